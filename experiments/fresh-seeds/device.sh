#!/usr/bin/env bash
# The fresh-seeds replication in one command of a GPU machine (16 cores): train seeds 20-99 of
# dqn, static and dynamic on Grid10's middle rungs as populations on the GPU, keep them in the
# results archive, then measure the GPU population's throughput. Everything it learns goes to
# $OUT: the machine (device.txt), the training log, the archive's changed files
# (standard-changes.tgz, to unpack over results/standard here) and the throughput table.
# Settings by environment: LIMIT (seconds of training, default 420), SEEDS (100), MEMBERS (20),
# WORKERS (18), DEVICE (cuda), BENCH (seconds per throughput row, 5; 0 skips it). The whole
# script takes LIMIT plus about 3 minutes (archive, packing, the throughput rows): the device
# command's own limit must leave that, or nothing comes back. Unfinished runs' checkpoints stay
# on the machine (a second command on the same machine resumes them; a fresh machine does not).
set -u
OUT=${OUT:?set OUT to the folder the records go to}
PY=${PY:-python3}
LIMIT=${LIMIT:-420} SEEDS=${SEEDS:-100} MEMBERS=${MEMBERS:-20} WORKERS=${WORKERS:-18}
DEVICE=${DEVICE:-cuda} BENCH=${BENCH:-5}
RUNS=${RUNS:-/tmp/runs/fresh-seeds}
export PYTHONUNBUFFERED=1
stamp=$(mktemp) && sleep 1  # the archive's files written after this are the ones to bring back
{ date -u; nproc; free -g | head -2; nvidia-smi -L 2>&1; $PY -c 'import sys, torch; print(sys.version.split()[0], torch.__version__, torch.cuda.is_available())'; } > "$OUT/device.txt" 2>&1
start=$(date +%s) log="$OUT/transfer.log"
: > "$log"  # appended to by all (a worker outliving the limit must not write over later lines)
timeout -k 15 "$LIMIT" $PY -m craftsuite transfer --suite standard --worlds Grid10 \
  --tasks KeySwordDragon ToolHome TwoToolsHome --methods dqn static dynamic --seeds "$SEEDS" \
  --members "$MEMBERS" --workers "$WORKERS" --device "$DEVICE" --no-video --out "$RUNS" >> "$log" 2>&1 &
tpid=$!
wait "$tpid"; rc=$?
# timeout leads a process group of its own: the transfer and its workers, and nothing else
kill -9 -- "-$tpid" 2>/dev/null; sleep 1
echo "transfer: exit $rc after $(( $(date +%s) - start )) s" >> "$log"
# a transfer stopped by the limit never reached its own archiving: keep what finished
$PY -m craftsuite archive "$RUNS" --suite standard >> "$log" 2>&1
find results/standard -type f -newer "$stamp" -print0 | tar -czf "$OUT/standard-changes.tgz" --null -T -
echo "archive: $(tar -tzf "$OUT/standard-changes.tgz" | grep -c 'result.json$') finished runs changed or added" >> "$log"
if [ "$BENCH" != 0 ]; then
  timeout 120 $PY benchmarks/student_throughput.py --device "$DEVICE" --members 20 80 --seconds "$BENCH" \
    --only n-step-wide --no-page > "$OUT/throughput.txt" 2>&1
  echo "throughput: exit $?" >> "$OUT/throughput.txt"
fi
tail -5 "$OUT/transfer.log"; cat "$OUT/throughput.txt" 2>/dev/null
