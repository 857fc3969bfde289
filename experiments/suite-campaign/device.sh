#!/usr/bin/env bash
# One part of the campaign on a machine with a GPU and 16 cores, within a fixed wall time:
# a suite's MuJoCo cells as populations on the GPU (SUITE, default standard: the middle rungs
# first, then the easy rungs if the time left can finish them; SUITE=hard: the paper's tasks,
# RUNGS picking which). Cells that finish are archived into results/$SUITE there and packed,
# one archive per rung, with the log (the machine, the GPU's load, each run's time) and the
# archive's provenance, into $OUT.
# Usage, from the project root: [SUITE=hard RUNGS="--tasks BlindCraftsman" EXTRA="--members 2"]
#   bash experiments/suite-campaign/device.sh COMMIT SECONDS
set -u
commit=$1
seconds=$2
suite=${SUITE:-standard}
case $suite in standard|hard) ;; *) echo "SUITE must be standard or hard, got $suite" >&2; exit 2 ;; esac
if [ "$suite" != standard ] && [ -z "${RUNGS:-}" ]; then
  # every hard cell at once would be 350M transitions: a part names the rungs (and methods) it can finish
  echo "SUITE=$suite needs RUNGS, e.g. RUNGS=\"--tasks BlindCraftsman --methods td3 td3-dynamic\"" >&2; exit 2
fi
out=${OUT:-/tmp/out}
mkdir -p "$out"
export PYTHONPATH=${PYTHONPATH:-}:$PWD MUJOCO_GL=disable PYTHONUNBUFFERED=1 CRAFTSUITE_COMMIT=$commit \
  OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
py=${PYTHON:-python3}
device=${DEVICE:-cuda}
end=$(( $(date +%s) + seconds ))
{ echo "cores: $(nproc --all)"; free -g | head -2; nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv 2>&1; } \
  >> "$out/campaign.log"
# the GPU's load while the cells train, every 30 s
( while sleep 30; do echo "gpu $(date -u +%H:%M:%S) $(nvidia-smi --query-gpu=utilization.gpu,memory.used \
  --format=csv,noheader 2>&1)"; done >> "$out/campaign.log" ) &
sampler=$!
mkdir -p "results/$suite/students"
ls "results/$suite/students" > /tmp/before.txt

run_part() {  # run_part NAME WORKERS ARGS...: one transfer, stopped at the deadline
  local name=$1 workers=$2; shift 2
  local left=$(( end - $(date +%s) ))
  echo "== $name: $left s left, $(date -u +%H:%M:%S)" | tee -a "$out/campaign.log"
  local start=$(date +%s)
  timeout "$left" "$py" -m craftsuite transfer --suite "$suite" --worlds Cont "$@" --workers "$workers" \
    --device "$device" --no-video --archive results --out "/tmp/runs/$name" ${EXTRA:-} >> "$out/campaign.log" 2>&1
  echo "== $name: rc $?, $(( $(date +%s) - start )) s" | tee -a "$out/campaign.log"
}

# RUNGS and WORKERS pick another first part (e.g. RUNGS="--tasks KeySwordDragon" WORKERS=6); about
# 15 population processes fill an H100 (parts 1-2), more only queue for it
if [ "$suite" = standard ]; then
  run_part middle "${WORKERS:-15}" ${RUNGS:---tags middle}
  # the easy rungs' cells take 2.5M transitions each: only where the time left can hold them
  if [ $(( end - $(date +%s) )) -gt 300 ]; then run_part easy 14 --tags easy; fi
else
  run_part "$suite" "${WORKERS:-15}" $RUNGS
fi

# what finished goes into the archive there (unfinished runs are named and skipped)
for d in /tmp/runs/*/; do "$py" -m craftsuite archive "$d" --suite "$suite" >> "$out/campaign.log" 2>&1; done
ls "results/$suite/students" | sort > /tmp/after.txt
comm -13 <(sort /tmp/before.txt) /tmp/after.txt | sed "s|^|results/$suite/students/|" > /tmp/new.txt
echo "$(wc -l < /tmp/new.txt) new runs archived" | tee -a "$out/campaign.log"
kill $sampler
# one archive per rung (a file that comes back holds at most 16 MiB)
cp "results/$suite/provenance.json" "$out/provenance.json"
for task in $(sed 's|.*/student-\([A-Za-z]*\)-.*|\1|' /tmp/new.txt | sort -u); do
  grep "/student-$task-" /tmp/new.txt | tar -czf "$out/$suite-$task.tgz" -T -
done
# each run's transitions and seconds, for the part's measured time
"$py" - >> "$out/campaign.log" <<'PY'
import json, pathlib
for line in open("/tmp/new.txt"):
    r = json.loads((pathlib.Path(line.strip()) / "result.json").read_text())
    print(line.strip().split("/")[-1], r.get("steps"), r.get("seconds_this_session"), r.get("seconds_share"))
PY
