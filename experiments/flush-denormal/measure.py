"""Time the population engine's gradient updates from a cell's checkpoints with subnormal
floats kept and flushed to zero (``torch.set_flush_denormal``), in CPU time, and compare the
networks the two leave after the same updates. Reads checkpoints only (copied first); trains
and writes nothing in the runs.

Usage: python experiments/flush-denormal/measure.py STUDENTS_DIR [--methods product-td3 td3-rs]
       [--rounds 4] [--updates 100] [--out results.json]
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import torch as th

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.configs import StudentConfig
from craftsuite.population.envs import make_envs
from craftsuite.population.td3 import delay_at
from craftsuite.population.train import CHECKPOINT, STEP, build_population
from craftsuite.runs import RunDir, load_config
from craftsuite.task_registry import resolve_task

TINY = np.finfo(np.float32).tiny  # the smallest normal float32: below it (and not 0), subnormal


def last_checkpoint(run: Path) -> Path | None:
    """The run's newest complete checkpoint folder (``RunDir``'s rule: both files written)."""
    return RunDir(run, load_config(StudentConfig, run)).last_checkpoint((CHECKPOINT, STEP))


def copy_checkpoints(runs: list[Path], into: Path) -> list[Path]:
    """Each run's newest complete checkpoint, copied; again until every copy is at one step
    (a population commits its members one after another)."""
    for _ in range(20):
        copies, steps = [], set()
        for run in runs:
            folder = into / run.name
            shutil.rmtree(folder, ignore_errors=True)
            try:
                shutil.copytree(last_checkpoint(run), folder)
                steps.add(json.loads((folder / STEP).read_text())["num_timesteps"])
            except (TypeError, OSError):  # none yet, or renamed by the run's commit while copied: again
                steps.add(-1)
            copies.append(folder / CHECKPOINT)
        if len(steps) == 1 and -1 not in steps:
            return copies
        time.sleep(10)
    sys.exit(f"the checkpoints of {runs[0].parent} stayed at different steps ({sorted(steps)}); try again")


def subnormal_share(tensors) -> tuple[int, int]:
    """(subnormal values, all values) over float tensors."""
    sub = total = 0
    for t in tensors:
        a = t.detach().abs()
        sub += int(((a > 0) & (a < TINY)).sum())
        total += a.numel()
    return sub, total


def weights(pop) -> dict[str, th.Tensor]:
    return {f"{m}.{k}": v.detach().clone() for m, mod in pop.learner.modules().items()
            for k, v in mod.state_dict().items() if v.is_floating_point()}


def measure(runs: list[Path], rounds: int, updates: int, scratch: Path) -> dict:
    configs = [load_config(StudentConfig, run) for run in runs]
    config = configs[0]
    states = [th.load(p, weights_only=False, map_location="cpu") for p in copy_checkpoints(runs, scratch)]
    spec = resolve_task(config.task)
    envs = make_envs(config.env_id, len(configs) * config.n_envs, config.env_kwargs, config.product)
    pop = build_population(config, [c.seed for c in configs], config.effective()["hyperparameters"], spec,
                           None, th.device("cpu"), envs)
    envs.close()
    pop.load_states(states)
    step = pop.num_timesteps
    moments = [v for opt in pop.learner.optimizers().values() for s in opt.state.values()
               for k, v in s.items() if k.startswith("exp_avg")]
    found = {"method": config.method, "members": len(configs), "step": step,
             "subnormal_moments": subnormal_share(moments), "subnormal_weights": subnormal_share(weights(pop).values())}
    pop.replay.rng = np.random.default_rng(0)
    batches = [pop.replay.sample(config.effective()["hyperparameters"]["batch_size"]) for _ in range(updates)]
    delay = delay_at(pop.delay_schedule, step)
    times, after = {False: [], True: []}, {}
    for r in range(rounds):
        for flush in (False, True):
            pop.load_states(states)  # the checkpoint again: every timing starts from the same moments
            th.manual_seed(0)        # the same target-policy noise
            th.set_flush_denormal(flush)
            start = time.process_time()
            for batch in batches:
                pop.learner.update(batch, delay)
            times[flush].append((time.process_time() - start) / updates * 1e3)
            th.set_flush_denormal(False)
            if r == 0:
                after[flush] = weights(pop)
    scale = max(float(v.abs().max()) for v in after[False].values())
    diff = max(float((after[False][k] - after[True][k]).abs().max()) for k in after[False])
    found.update(ms_per_update_kept=[round(t, 3) for t in times[False]],
                 ms_per_update_flushed=[round(t, 3) for t in times[True]],
                 largest_weight=scale, largest_difference=diff, relative_difference=diff / scale)
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("students", type=Path, help="a transfer's students directory (the runs' checkpoints)")
    parser.add_argument("--task", default="FirstTool")
    parser.add_argument("--world", default="Cont")
    parser.add_argument("--methods", nargs="+", default=["product-td3", "td3-rs"])
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--updates", type=int, default=100)
    parser.add_argument("--out", type=Path)
    args = parser.parse_args()
    if not th.set_flush_denormal(True):
        sys.exit("this CPU cannot flush subnormals to zero (torch.set_flush_denormal returned False)")
    th.set_flush_denormal(False)
    th.set_num_threads(1)  # as the engine trains on CPU
    found = []
    with tempfile.TemporaryDirectory() as scratch:
        for method in args.methods:
            runs = sorted(args.students.glob(f"student-{args.task}-{args.world}-{method}-s*"))
            if not runs:
                sys.exit(f"no {method} runs of {args.task} {args.world} in {args.students}")
            bare = [r.name for r in runs if last_checkpoint(r) is None]
            if bare:  # an archive keeps records only: the runs of a transfer's --out have checkpoints
                sys.exit(f"{len(bare)} {method} runs in {args.students} hold no checkpoint ({bare[0]}, ...: an "
                         "archive keeps none); "
                         "give the students directory of a transfer's --out whose runs still have theirs")
            found.append(measure(runs, args.rounds, args.updates, Path(scratch)))
            print(json.dumps(found[-1]), flush=True)
    if args.out:
        args.out.write_text(json.dumps(found, indent=1) + "\n")


if __name__ == "__main__":
    main()
