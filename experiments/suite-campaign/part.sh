#!/usr/bin/env bash
# One process of a campaign part on this machine: the transfers of a queue, in order, each
# started only if the minutes left before the cut-off cover it, each stopped at the cut-off
# (`--time-limit`) and archived population by population as it goes.
# Usage, from the project root (one call per process, in the background):
#   git worktree add TREE PLAN_COMMIT      # the plan's code, while this checkout moves on
#   bash TREE/experiments/suite-campaign/part.sh TREE CUTOFF OUT QUEUE > OUT/A.out &
# (TREE's copy of this script: bash reads a script as it runs, so a running part must not
# read the copy this checkout edits; run it from the root all the same, where ./results is.)
# CUTOFF, in UTC: HH:MM for today, or 'YYYY-MM-DD HH:MM' (one argument) for a cut-off past
# midnight (a bare HH:MM is never read as tomorrow's: a cut-off already past is refused).
# QUEUE holds one transfer a line, `NAME MINUTES ARGS...`: MINUTES is the least time left
# at which it starts (its expected duration at the rate measured), ARGS the rest of its
# `craftsuite transfer` command (--suite, --worlds, --tasks, --methods, --seeds, --members),
# split at spaces (no quoting: a JSON argument does not fit on a queue line).
# Lines starting with # are comments. The queue is read again before each transfer, so an
# amendment edits the lines not yet started; a started or skipped NAME leaves OUT/NAME.status
# and is not run again (delete that file to run it again: a transfer resumes what it began).
# Runs land in OUT/NAME (log OUT/NAME.log) and in ./results, recording TREE's commit;
# PYTHON (default ./.venv/bin/python) runs them.
set -u
if [ $# -ne 4 ]; then
  echo "usage: part.sh TREE CUTOFF OUT QUEUE (see the comment at the top of this script)" >&2; exit 2
fi
tree=$1 cutoff=$2 out=$(realpath -m "$3") queue=$4
commit=$(git -C "$tree" rev-parse HEAD 2>/dev/null) \
  || { echo "part.sh: TREE '$tree' is not a checkout: make it with git worktree add TREE PLAN_COMMIT" >&2; exit 2; }
end=$(date -u -d "$cutoff" +%s 2>/dev/null) \
  || { echo "part.sh: cut-off '$cutoff' is not a time: give it as HH:MM (UTC, today) or 'YYYY-MM-DD HH:MM'" >&2; exit 2; }
[ "$end" -gt "$(date +%s)" ] \
  || { echo "part.sh: cut-off $cutoff UTC has passed: give a later one (HH:MM today, or 'YYYY-MM-DD HH:MM' past midnight)" >&2; exit 2; }
[ -f "$queue" ] || { echo "part.sh: no queue file '$queue': write one transfer a line, NAME MINUTES ARGS..." >&2; exit 2; }
py=${PYTHON:-$PWD/.venv/bin/python}
archive=$PWD/results

next() {  # the queue's first line whose NAME has no status yet; every line checked first
  local name minutes args first=""
  while read -r name minutes args; do
    [[ -z $name || $name == \#* ]] && continue
    [[ $minutes =~ ^[0-9]+$ ]] \
      || { echo "part.sh: $queue, line $name: MINUTES '$minutes' is not a whole number" >&2; return 2; }
    [[ -z $first && ! -e "$out/$name.status" ]] && first="$name $minutes $args"
  done < "$queue"
  echo "$first"
}

next > /dev/null || exit 2  # a bad queue is refused before anything is made
mkdir -p "$out"

while :; do
  line=$(next) || exit 2
  [ -z "$line" ] && break
  read -r name minutes args <<< "$line"
  left=$(( (end - $(date +%s)) / 60 ))
  if [ "$left" -lt "$minutes" ]; then
    echo "$(date -u +%H:%M) $name: skipped, $left min left, needs $minutes"
    echo skipped > "$out/$name.status"
    continue
  fi
  echo "$(date -u +%H:%M) $name: start, $left min left"
  echo started > "$out/$name.status"
  # shellcheck disable=SC2086  # ARGS are words of the command, split as written in the queue
  (cd "$tree" && CRAFTSUITE_COMMIT=$commit "$py" -m craftsuite transfer $args --workers 1 --no-video \
    --time-limit "$left" --archive "$archive" --out "$out/$name") > "$out/$name.log" 2>&1
  status=$?
  echo "exit $status" > "$out/$name.status"
  echo "$(date -u +%H:%M) $name: exit $status"
done
echo "$(date -u +%H:%M) queue done"
