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
# split at spaces (no quoting: a JSON argument does not fit on a queue line). A transfer
# takes one core (`--workers 1`, one process a core) unless its ARGS say `--workers N`: a
# cell split into N populations over N cores finishes within a session, where checkpoints
# would not outlive a change of machine.
# Lines starting with # are comments. The queue is read again before each transfer, so an
# amendment edits the lines not yet started (and the resume of a stopped one: keep its ARGS,
# or it trains something else into the same OUT/NAME). A started or skipped NAME leaves
# OUT/NAME.status and is not run again, except one the cut-off stopped (`exit 3`, the status
# of a transfer its --time-limit stopped), one killed by a signal, or whose worker was
# (`exit 137`, say: memory), or one interrupted (`started PID START BOOT` whose part.sh is
# gone: killed, or the machine restarted): the next part.sh over the same OUT and queue
# resumes it first, from its runs' checkpoints (a later session's part, from the same TREE
# so that its runs keep one commit; each start's line in the log names the commit it ran).
# One whose part.sh, or its transfer, still runs is left to it. (Telling which runs takes
# Linux's /proc: elsewhere the status is a bare `started`, run again only once it is deleted.)
# To run another NAME again, delete its status file. One part.sh runs over an OUT at a time:
# a second call over it is refused while the first runs (with flock, which Linux has).
# Runs land in OUT/NAME (log OUT/NAME.log, each start appended) and in ./results, recording
# TREE's commit; PYTHON (default ./.venv/bin/python) runs them.
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

stopped=3  # the exit status of a transfer its --time-limit stopped (craftsuite.cli.TIME_LIMIT_STATUS)
ran=" "    # the NAMEs this call has taken up (run, skipped or not resumed): each at most once a call
boot=$(cat /proc/sys/kernel/random/boot_id 2>/dev/null || echo unknown)

identity() {  # PID -> "PID START BOOT": a PID is reused (by a later process, or after a restart),
  # the three together are not; nothing where /proc cannot tell
  local stat fields
  stat=$(cat "/proc/$1/stat" 2>/dev/null) || return 1
  read -ra fields <<< "${stat##*) }"  # the fields after the command's name, which may hold spaces
  echo "$1 ${fields[19]} $boot"       # field 22: the start time, in clock ticks after boot
}

writing() {  # whether a process's command line holds `--out OUT/NAME`: a transfer still running
  local cmdline args i
  for cmdline in /proc/[0-9]*/cmdline; do
    mapfile -d '' args 2>/dev/null < "$cmdline" || continue
    for ((i = 0; i + 1 < ${#args[@]}; i++)); do
      [[ ${args[i]} == --out && ${args[i + 1]} == "$out/$1" ]] && return 0
    done
  done
  return 1
}

due() {  # whether NAME is still to run: no status yet, stopped at a cut-off, killed by a
  # signal, or interrupted, and not taken up by this call
  local status="" pid=""
  [[ $ran == *" $1 "* ]] && return 1
  [ -e "$out/$1.status" ] || return 0
  read -r status < "$out/$1.status"
  # stopped at its cut-off, or killed by a signal (128 + its number: 137 for the kernel's
  # out-of-memory kill, 143 for a kill's TERM): its runs keep their checkpoints either way; a
  # transfer's own failure (1, or 2 for a refused command) is not taken up again
  [[ $status =~ ^exit\ ([0-9]+)$ ]] && (( BASH_REMATCH[1] == stopped || BASH_REMATCH[1] > 128 )) && return 0
  [[ $status == "started "* ]] || return 1  # finished or skipped (or an older part.sh's bare `started`)
  # interrupted: the part.sh that started it is gone (killed, or the machine restarted), and no
  # transfer it left (a part.sh killed alone) still writes to OUT/NAME
  read -r _ pid _ <<< "$status"
  [[ $(identity "$pid") == "${status#started }" ]] && return 1
  ! writing "$1"
}

next() {  # the queue's first line still due (resumable ones first); every line checked first
  local name minutes args first="" resume=""
  while read -r name minutes args; do
    [[ -z $name || $name == \#* ]] && continue
    [[ $minutes =~ ^[0-9]+$ ]] \
      || { echo "part.sh: $queue, line $name: MINUTES '$minutes' is not a whole number" >&2; return 2; }
    due "$name" || continue
    if [ -e "$out/$name.status" ]; then
      [[ -z $resume ]] && resume="$name $minutes $args"
    else
      [[ -z $first ]] && first="$name $minutes $args"
    fi
  done < "$queue"
  echo "${resume:-$first}"
}

next > /dev/null || exit 2  # a bad queue is refused before anything is made
me=$(identity $$)
mkdir -p "$out"
# one part.sh over an OUT at a time: two would both take up its first due line and train it
# twice into one OUT/NAME. The lock is this process's own (its transfers do not hold it), so a
# transfer left running by a killed part.sh is not mistaken for it: `due` finds that one.
if command -v flock > /dev/null; then
  exec 9> "$out/.part.lock"
  flock -n 9 || {
    echo "part.sh: another part.sh runs over OUT '$out': wait for it to end, or give this one another OUT" >&2
    exit 2
  }
fi

while :; do
  line=$(next) || exit 2
  [ -z "$line" ] && break
  read -r name minutes args <<< "$line"
  ran+="$name "
  [ -e "$out/$name.status" ] && verb=resume || verb=start
  left=$(( (end - $(date +%s)) / 60 ))
  if [ "$left" -lt "$minutes" ]; then
    if [ $verb = resume ]; then  # what it trained is kept: it stays for the next call to resume
      echo "$(date -u +%H:%M) $name: not resumed, $left min left, needs $minutes"
    else
      echo "$(date -u +%H:%M) $name: skipped, $left min left, needs $minutes"
      echo skipped > "$out/$name.status"
    fi
    continue
  fi
  echo "$(date -u +%H:%M) $name: $verb, $left min left"
  echo "started${me:+ $me}" > "$out/$name.status"  # bare where /proc cannot name this process
  echo "== part.sh: $verb $(date -u '+%Y-%m-%d %H:%M') UTC, commit $commit, $left min left" >> "$out/$name.log"
  # shellcheck disable=SC2086  # ARGS are words of the command, split as written in the queue
  (cd "$tree" && CRAFTSUITE_COMMIT=$commit "$py" -m craftsuite transfer --workers 1 $args --no-video \
    --time-limit "$left" --archive "$archive" --out "$out/$name") >> "$out/$name.log" 2>&1 9>&-
  status=$?
  echo "exit $status" > "$out/$name.status"
  echo "$(date -u +%H:%M) $name: exit $status"
done
echo "$(date -u +%H:%M) queue done"
