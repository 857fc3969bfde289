"""Student run directories written by hand, with known answers."""

import hashlib
import json

from craftsuite.runs import EPISODE_FIELDS, EVAL_FIELDS, write_csv


def fake_run(root, method, seed, evals, episodes, budget=1_000, task="BlindCraftsman", world="Cont", **config):
    run = root / f"student-{task}-{world}-{method}-s{seed}"
    if config or budget != 1_000:  # another setting: another directory, as config_key gives
        run = run.with_name(f"{run.name}-{hashlib.sha256(json.dumps([budget, config]).encode()).hexdigest()[:8]}")
    run.mkdir(parents=True)
    (run / "config.json").write_text(json.dumps({"task": task, "world": world, "method": method, "seed": seed,
                                                 "steps": budget, **config}))
    (run / "result.json").write_text(json.dumps({"kind": "student", "steps": budget}))
    write_csv(run / "evals.csv", EVAL_FIELDS,
              [{"step": s, "success": v, "return": 0.0, "episodes": 10} for s, v in evals])
    write_csv(run / "episodes.csv", EPISODE_FIELDS,
              [{"step": s, "return": r, "length": 10, "success": won}  # (step, return[, won]): lost by default
               for s, r, won in (tuple(e) + (0,) * (3 - len(e)) for e in episodes)])
    return run
