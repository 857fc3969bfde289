#!/usr/bin/env bash
# One part of the campaign on a machine with a GPU and 16 cores, within a fixed wall time.
# Each PART is one `craftsuite transfer` of a suite's cells, written SUITE:WORKERS:DEVICE:ARGS
# (DEVICE cuda for populations on the GPU, cpu for populations on cores); the parts run at
# once, each stopped at the deadline. Each part's finished runs are packed (records and
# provenance, partN.tgz) with the logs (the machine, the GPU's load, each run's time) into $OUT.
# Usage, from the project root:
#   bash experiments/suite-campaign/device.sh COMMIT SECONDS \
#     'hard:14:cpu:--worlds Grid10 --tasks BlindCraftsman --methods dqn static --members 5' \
#     'standard:2:cuda:--worlds Grid10 --tasks Reach --members 10'
# Sizing: a GPU process drives about 2.9k TD3 transitions/s with a population of 10, and about
# 15 of them fill the GPU (parts 1-2); a DQN population of 10 on the GPU about 1.7k/s, and a
# CPU process with a DQN population of 5 about 600/s when every core is busy (part 12). A
# population that cannot finish by the deadline is lost with the machine (its checkpoints, a
# replay buffer each, are far over what a file that comes back may hold).
set -u
if [ $# -lt 3 ]; then
  echo "usage: device.sh COMMIT SECONDS SUITE:WORKERS:DEVICE:ARGS..." >&2; exit 2
fi
commit=$1 seconds=$2
shift 2
for part in "$@"; do  # refused before anything starts, so a typo costs no device time
  IFS=: read -r suite workers device args <<< "$part"
  case $suite in standard|hard) ;; *) echo "part '$part': SUITE must be standard or hard" >&2; exit 2 ;; esac
  case $device in cpu|cuda) ;; *) echo "part '$part': DEVICE must be cpu or cuda" >&2; exit 2 ;; esac
  [[ $workers =~ ^[0-9]+$ ]] || { echo "part '$part': WORKERS must be a whole number" >&2; exit 2; }
  [[ $args == *--worlds* ]] || { echo "part '$part': ARGS must name --worlds (every cell at once would not finish)" >&2; exit 2; }
done
out=${OUT:-/tmp/out}
mkdir -p "$out"
export PYTHONPATH=${PYTHONPATH:-}:$PWD MUJOCO_GL=disable PYTHONUNBUFFERED=1 CRAFTSUITE_COMMIT=$commit \
  OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
py=${PYTHON:-python3}
end=$(( $(date +%s) + seconds ))
log="$out/campaign.log"
{ echo "cores: $(nproc --all)"; free -g | head -2; nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv 2>&1; } >> "$log"
# the GPU's load while the cells train, every 30 s
( while sleep 30; do echo "gpu $(date -u +%H:%M:%S) $(nvidia-smi --query-gpu=utilization.gpu,memory.used \
  --format=csv,noheader 2>&1)"; done >> "$log" ) &
sampler=$!
# a directory of this call's own: a second call on the same machine must not resume or re-archive the first's
runs=$(mktemp -d /tmp/runs.XXXX)

n=0
for part in "$@"; do
  IFS=: read -r suite workers device args <<< "$part"
  n=$(( n + 1 ))
  mkdir -p "results/$suite/students"
  (
    start=$(date +%s)
    echo "== part $n ($part): $(( end - start )) s left, $(date -u +%H:%M:%S)" >> "$log"
    visible=$([ "$device" = cpu ] && echo "" || echo "${CUDA_VISIBLE_DEVICES-0}")
    # timeout leads a process group of its own: the transfer and its workers, and nothing else
    CUDA_VISIBLE_DEVICES=$visible timeout -k 15 $(( end - start )) "$py" -m craftsuite transfer --suite "$suite" \
      $args --workers "$workers" --device "$device" --no-video --archive results --out "$runs/part$n" \
      >> "$out/part$n.log" 2>&1
    echo "== part $n: rc $?, $(( $(date +%s) - start )) s" >> "$log"
  ) &
done
wait $(jobs -p | grep -v "^$sampler$")
kill "$sampler" 2>/dev/null

# each part's finished runs, their records only (no model, checkpoint or log of the learner),
# with the part's provenance, one archive per part (a file that comes back holds at most 16 MiB):
# here, `tar -xzf partN.tgz -C DIR && craftsuite archive DIR/partN --suite SUITE` keeps them
n=0
for part in "$@"; do
  n=$(( n + 1 ))
  ( cd "$runs" && find "part$n/students" -name result.json | xargs -r -n1 dirname > "part$n.finished"
    tar -czf "$out/part$n.tgz" "part$n/provenance.json" "part$n/suite.json" \
      $(sed 's|$|/config.json|; p; s|config.json$|result.json|; p; s|result.json$|evals.csv|' "part$n.finished") \
      $(for d in $(cat "part$n.finished"); do ls "$d"/episodes.csv* 2>/dev/null; done) )
  echo "part $n: $(wc -l < "$runs/part$n.finished") finished runs packed" | tee -a "$log"
done
# each finished run's transitions, population and seconds, for the part's measured time
"$py" - "$runs" >> "$log" <<'PY'
import json, pathlib, sys
for result in sorted(pathlib.Path(sys.argv[1]).glob("part*/students/*/result.json")):
    r = json.loads(result.read_text())
    print(result.parent.name, r.get("steps"), r.get("members"), r.get("device"), r.get("seconds_this_session"))
PY
tail -3 "$log"
