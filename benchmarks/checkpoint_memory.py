"""Checkpoint memory: how far a population's memory rises while it saves its checkpoints and loads them back.

Usage: python benchmarks/checkpoint_memory.py [--rows 1000000] [--members 1] [--page PATH | --no-page]

At each evaluation every member of a population saves its whole state, its replay included,
with ``torch.save``. A replay is sized to the run's budget (1M transitions of the hard suite),
so a member's rows reach a gigabyte. ``torch.save`` writes a tensor's storage straight to the
file, but pickles a NumPy array whole in memory first. The engine saves the replay's rows as
tensors sharing the arrays' memory (``PopulationReplay.member_state``) and reads a checkpoint
mapped from its file (``train.read_member_state``); the reference row saves the same states
with the rows as NumPy arrays (as older checkpoints hold them).

Each row builds a hard-suite population of Diamond Mine (DQN on Grid10, TD3 in MuJoCo) in a
fresh process, fills each member's replay with ``--rows`` transitions of random values (by
default one member's whole replay in the hard suite, 1M), and saves every member's state as a
checkpoint does: the rise is the process's peak resident set (Linux's ``VmHWM``, reset just
before) above its level before the saving. Then it loads the states back into the same
population as a resume does, every member's read before any is copied into the replay: what
they hold is the anonymous memory (``RssAnon``) they add while the replay's pages are resident
already. The target: both at most a tenth of one member's rows. The rows are random values: a
real replay's, mostly zeros and ones, pickle a little smaller as NumPy arrays. Members save one
after another, so a population pauses at each evaluation for about its members times the
seconds shown.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

from _page import Report, add_page_argument

TARGET_SHARE = 0.1
_CHILD = """
import contextlib, json, os, sys, tempfile, time
from pathlib import Path
import numpy as np, torch as th
import craftsuite
from craftsuite.population.envs import make_envs
from craftsuite.population.train import build_population, read_member_state
from craftsuite.suites import SUITES
from craftsuite.task_registry import resolve_task

world, method, members, rows, form = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
spec = resolve_task("DiamondMine")
config = SUITES["hard"].student_config(spec, world, method)
with contextlib.closing(make_envs(config.env_id, 1, config.env_kwargs, config.product)) as envs:
    pop = build_population(config, list(range(members)), config.effective()["hyperparameters"], spec, None,
                           "cpu", envs)
replay, rng = pop.replay, np.random.default_rng(0)
rows = min(rows, replay.capacity) // replay.n_envs * replay.n_envs  # whole steps of the envs
for name in replay._arrays:  # every page written, as a run's transitions write them
    array = getattr(replay, name)[:, :rows]
    array[...] = rng.integers(0, 2, size=array.shape) if array.dtype.kind in "biu" else rng.random(array.shape)
if replay.trees is not None:
    leaves = replay.trees.tree[:, replay.trees.leaves:replay.trees.leaves + rows * replay.per_step]
    leaves[...] = rng.random(leaves.shape)
replay.pos = rows
row_bytes = sum(v.numel() * v.element_size() for v in pop.member_state(0)["replay"].values() if th.is_tensor(v))


def vm(field):
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1]) * 1024


def state(k):
    s = pop.member_state(k)
    if form == "numpy":
        s["replay"] = {name: v.numpy() if isinstance(v, th.Tensor) else v for name, v in s["replay"].items()}
    return s


with tempfile.TemporaryDirectory() as out:
    Path("/proc/self/clear_refs").write_text("5")  # VmHWM from here
    level, start = vm("VmRSS"), time.perf_counter()
    for k in range(members):
        th.save(state(k), Path(out) / f"member{k}.pt")
    seconds, rise = time.perf_counter() - start, vm("VmHWM") - level
    size = os.path.getsize(Path(out) / "member0.pt")
    # back into the same population, as a resume loads them: every member's state read before
    # any is copied into the replay, whose pages are resident already
    before = vm("RssAnon")
    states = [read_member_state(Path(out) / f"member{k}.pt") for k in range(members)]
    pop.load_states(states)
    held = vm("RssAnon") - before
    del states
print(json.dumps({"rows": rows, "level": level, "rise": rise, "row_bytes": row_bytes, "file": size,
                  "seconds": seconds, "held": held}))
"""
CELLS = (("Grid10", "dqn"), ("Cont", "td3"))
FORMS = {"tensor": "tensors (the engine's)", "numpy": "NumPy arrays (reference)"}


def measure(world: str, method: str, members: int, rows: int, form: str) -> dict:
    done = subprocess.run([sys.executable, "-c", _CHILD, world, method, str(members), str(rows), form],
                          check=True, capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=1_000_000, help="transitions in each member's replay")
    parser.add_argument("--members", type=int, default=1, help="the population's members")
    add_page_argument(parser)
    args = parser.parse_args()
    if args.rows < 10 or args.members < 1:
        parser.error(f"--rows {args.rows} --members {args.members}: give at least 10 rows (a step of MuJoCo's "
                     "10 envs) and 1 member")
    if not Path("/proc/self/clear_refs").exists():
        parser.error("this benchmark reads a process's peak memory from Linux's /proc: run it on Linux")
    mib = 2 ** 20
    report = Report()
    report(f"| Diamond Mine | replay's rows saved as | members x rows | resident before saving (MiB) | "
           "one member's rows (MiB) | rise while saving (MiB) | held while loading back (MiB) | "
           f"target: both <= {TARGET_SHARE:.0%} of a member's | file a member (MiB) | seconds to save |")
    report("|---|---|---|---|---|---|---|---|---|---|")
    for world, method in CELLS:
        for form, label in FORMS.items():
            got = measure(world, method, args.members, args.rows, form)
            met = max(got["rise"], got["held"]) <= TARGET_SHARE * got["row_bytes"]
            report(f"| {world} `{method}` | {label} | {args.members} x {got['rows']:,} | {got['level'] / mib:,.0f} | "
                   f"{got['row_bytes'] / mib:,.0f} | {got['rise'] / mib:,.0f} | {got['held'] / mib:,.0f} | "
                   f"{'met' if met else 'NOT met'} | "
                   f"{got['file'] / mib:,.0f} | {got['seconds']:.1f} |")
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
