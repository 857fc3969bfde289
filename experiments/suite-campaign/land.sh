#!/usr/bin/env bash
# The watcher of a campaign part: for each NAME of a queue, in order, waits until part.sh's
# status file says it ended (`exit N`, or `skipped`), then archives its finished runs into this
# checkout's results/SUITE (`craftsuite archive OUT/NAME --suite SUITE`: a line stopped by the
# cut-off gives its finished populations), one landing at a time; after the last, rebuilds the
# pages once (`make docs`: minutes of a core, kept off the lines' time).
# Usage, from the project root, in the background beside part.sh (TREE's copy, as part.sh's:
# bash reads a script as it runs, and this checkout moves on):
#   bash TREE/experiments/suite-campaign/land.sh OUT SUITE NAME... >> OUT.land.out &
# Several queues at once: one call each, naming one lock (LAND_LOCK, default OUT/../.land.lock)
# so that their landings never overlap, and LAND_DOCS=0 for all but the last to end.
# A status part.sh resumes (`exit 3`: the cut-off; above 128: killed) counts only if written
# after this watcher started: one left by an earlier part is the resume's to replace.
set -u -o pipefail
if [ $# -lt 3 ]; then
  echo "usage: land.sh OUT SUITE NAME... (see the comment at the top of this script)" >&2; exit 2
fi
out=$(realpath -m "$1") suite=$2; shift 2
[ -d results ] && [ -f Makefile ] \
  || { echo "land.sh: run it from the project root (where results/ and the Makefile are)" >&2; exit 2; }
[ -d "$out" ] || { echo "land.sh: no OUT directory '$out': give part.sh's OUT" >&2; exit 2; }
py=${PYTHON:-$PWD/.venv/bin/python}
lock=${LAND_LOCK:-$(dirname "$out")/.land.lock}
since=$(mktemp)  # this watcher's start, to tell a resumable status written before it
trap 'rm -f "$since"' EXIT
poll=${LAND_POLL:-30}

ended() {  # NAME: whether its status says it ended (and is not an earlier part's, awaiting its resume)
  local file=$out/$1.status status code
  status=$(head -1 "$file" 2>/dev/null) || return 1
  [[ $status == skipped ]] && return 0
  [[ $status == exit* ]] || return 1
  code=${status#exit }
  if [[ $code == 3 || $code -gt 128 ]]; then [ "$file" -nt "$since" ]; else return 0; fi
}

for name in "$@"; do
  until ended "$name"; do sleep "$poll"; done
  status=$(head -1 "$out/$name.status")
  echo "$(date -u +%H:%M:%S) $name: $status"
  [[ $status == skipped ]] && continue
  (
    flock 8
    if "$py" -m craftsuite archive "$out/$name" --suite "$suite" 2>&1 | tail -3; then
      echo "$(date -u +%H:%M:%S) $name: archived"
    else
      echo "$(date -u +%H:%M:%S) $name: NOT archived (craftsuite archive failed: its lines above)"
    fi
  ) 8> "$lock"
done
if [ "${LAND_DOCS:-1}" != 0 ]; then
  make docs > "$out.docs.out" 2>&1
  rc=$?
  echo "$(date -u +%H:%M:%S) pages rebuilt (make docs exit $rc, its output in $out.docs.out)"
fi
