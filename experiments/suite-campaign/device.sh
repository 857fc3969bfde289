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

# each part's finished runs, their records only (the archive's own list: no model, checkpoint
# or learner's log), with the part's provenance, one archive per part (a file that comes back
# holds at most 16 MiB): here, `tar -xzf partN.tgz -C DIR && craftsuite archive DIR/partN
# --suite SUITE` keeps them. Beside it in the log, each finished run's transitions, population
# and seconds, for the part's measured time.
"$py" - "$runs" >> "$log" <<'PY'
import json, pathlib, sys
from craftsuite.archive import COMPRESSED, RECORDS
runs = pathlib.Path(sys.argv[1])
for part in sorted(p for p in runs.iterdir() if p.is_dir()):
    finished = sorted(r.parent for r in part.glob("students/*/result.json"))
    names = [*RECORDS, *COMPRESSED, *(f"{c}.gz" for c in COMPRESSED)]
    files = [part / "provenance.json", part / "suite.json"] + [d / n for d in finished for n in names if (d / n).is_file()]
    (runs / f"{part.name}.files").write_text("".join(f"{f.relative_to(runs)}\n" for f in files if f.is_file()))
    print(f"{part.name}: {len(finished)} finished runs packed")
    for d in finished:
        r = json.loads((d / "result.json").read_text())
        print(d.name, r.get("steps"), r.get("members"), r.get("device"), r.get("seconds_this_session"))
PY
for files in "$runs"/part*.files; do
  tar -czf "$out/$(basename "$files" .files).tgz" -C "$runs" -T "$files"
done
tail -3 "$log"
