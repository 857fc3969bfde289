"""The learner-regime experiment's runs: TD3 (MuJoCo) and DQN (Grid10) from scratch on the
middle rungs and Dungeon Quest, one factor at a time (the plan: this folder's README).

    python experiments/learner-regime/run.py --wave 1 --out experiments/learner-regime/results
    python experiments/learner-regime/run.py --wave 2 --n 3 3 --out experiments/learner-regime/results
    python experiments/learner-regime/run.py --wave 3 --n 3 3 --winners layernorm none --out ...

Each run is its suite's config (standard: the middle rungs; hard: Dungeon Quest) with the
setting's overrides added to its algorithm's settings. The runs the results archive holds
are not trained again (nor copied: ``table.py`` reads them there); the rest train as the
suites train them (each cell's seeds as one population). Runs land in ``<out>/<suite>/students``, ready for
``craftsuite archive <out>/<suite> --suite <suite> --archive results/learner-regime``.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.suites import SUITES

RUNGS = {"standard": ("KeySwordDragon", "ToolHome", "TwoToolsHome"), "hard": ("DungeonQuest",)}
# the suites whose rungs each wave runs: wave 2 the middle rungs only (the README's amendment:
# Dungeon Quest's 1M-transition runs were 70% of its cost)
WAVES = {1: ("standard", "hard"), 2: ("standard",), 3: ("standard", "hard")}
SCRATCH = {"Cont": "td3", "Grid10": "dqn"}
ARCHIVES = ("results/{suite}", "results/n-step-returns/{suite}", "results/learner-regime/{suite}")
# {} is the suites' own regime: its runs are the suites' records.
N_STEPS = {"n1": {}, "n3": {"n_steps": 3}, "n5": {"n_steps": 5}}


def factor_settings(world: str) -> dict[str, dict]:
    """Wave 2's settings, each one factor's change from wave 1's winner, by name."""
    td3 = SUITES["standard"].td3_hyperparameters
    if world == "Cont":
        return {"layernorm": {"layer_norm": True},
                "w256": {"policy_kwargs": {**td3["policy_kwargs"], "net_arch": [256, 256]}},
                "gaussian": {"action_noise": {"type": "normal", "sigma": 0.3}}}
    return {"layernorm": {"layer_norm": True}, "w256": {"policy_kwargs": {"net_arch": [256, 256]}},
            "updates0.25": {"gradient_steps": 1}}


def wave_2(world: str, n: int) -> dict[str, dict]:
    """Wave 2's settings in ``world`` at wave 1's ``n``: each factor varied alone."""
    base = {} if n == 1 else {"n_steps": n}
    return {f"n{n}": base, **{f"n{n}-{name}": {**base, **change} for name, change in factor_settings(world).items()}}


def wave_3(world: str, n: int, winners: list[str]) -> dict[str, dict]:
    """Wave 3's settings in ``world``: wave 2's winning changes together, beside wave 1's
    winner (none won: the two are one setting, and wave 3 has nothing to run there)."""
    base = {} if n == 1 else {"n_steps": n}
    changes = factor_settings(world)
    unknown = sorted(set(winners) - set(changes))
    if unknown:
        raise SystemExit(f"--winners: {world} has no wave-2 setting {unknown}; its settings: {list(changes)}")
    if not winners:
        return {f"n{n}": base}
    combined = dict(base)
    for name in winners:
        combined.update(changes[name])
    return {f"n{n}-" + "-".join(winners): combined, f"n{n}": base}


def factors(wave: int, world: str, n: int | None, winners: list[str] | None = None) -> list[list[str]]:
    """Each factor's settings in the rule's order: the cheaper first (the incumbent), the
    suites' current one first where two cost the same (the README's table). In wave 3 the
    combination is the incumbent, which wave 1's winner must beat by the rule."""
    if wave == 1:
        return [list(N_STEPS)]
    base = f"n{n}"
    if wave == 3:
        return [list(wave_3(world, n, winners or []))] if winners else []
    last = [base, f"{base}-gaussian"] if world == "Cont" else [f"{base}-updates0.25", base]  # 0.25 is the cheaper
    return [[base, f"{base}-layernorm"], [base, f"{base}-w256"], last]


def settings_for(wave: int, world: str, n: int | None, winners: list[str] | None = None) -> dict[str, dict]:
    if wave == 1:
        return dict(N_STEPS)
    if n is None:
        raise SystemExit(f"--wave {wave} needs --n: wave 1's winners, TD3's then DQN's (table.py says them)")
    return wave_2(world, n) if wave == 2 else wave_3(world, n, winners or [])


def configs(suite: str, wave: int, ns: dict[str, int | None],
            winners: dict[str, list[str]] | None = None) -> list[tuple[str, object]]:
    """The wave's runs of ``suite``'s rungs as (setting, config), MuJoCo first (the
    question the suites most need answered), then the shorter budgets."""
    out = []
    if suite not in WAVES[wave]:
        return out
    # the suite's seeds a cell as this experiment read them (not the Grid10 middle rungs' 20 of twenty-seeds)
    plain = dataclasses.replace(SUITES[suite], rung_seeds={})
    for c in plain.student_configs(Path("unused-teachers")):  # scratch methods read no table
        if c.task in RUNGS[suite] and SCRATCH.get(c.world) == c.method:
            for name, overrides in settings_for(wave, c.world, ns[c.world], (winners or {}).get(c.world)).items():
                out.append((name, dataclasses.replace(c, hyperparameters={**c.hyperparameters, **overrides})))
    return sorted(out, key=lambda pair: (pair[1].world != "Cont", pair[1].steps))


def parse_winners(text: str) -> list[str]:
    """``layernorm,w256`` -> the two names; ``none`` -> none."""
    return [] if text == "none" else [name for name in text.split(",") if name]


# where the readers (table.py, budgets.py) find the runs: the archive's and this folder's
READ_FROM = (Path("results/learner-regime"), Path(__file__).parent / "results", Path("results/n-step-returns"),
             Path("results"))


def reader_arguments(parser: argparse.ArgumentParser, wave_default: int = 1) -> None:
    """The readers' arguments naming a wave's settings and where its runs lie."""
    parser.add_argument("--wave", type=int, choices=tuple(WAVES), default=wave_default)
    parser.add_argument("--n", type=int, nargs=2, metavar=("TD3_N", "DQN_N"), help="wave 1's winners (waves 2, 3)")
    parser.add_argument("--winners", nargs=2, metavar=("TD3", "DQN"), help="wave 3: wave 2's winners, as run.py's")
    parser.add_argument("--runs", type=Path, nargs="+", default=list(READ_FROM))


def read_settings(args) -> tuple[dict, dict]:
    """The worlds' n and wave-2 winners that the readers' arguments name."""
    ns = {"Cont": args.n[0], "Grid10": args.n[1]} if args.n else {"Cont": None, "Grid10": None}
    return ns, dict(zip(("Cont", "Grid10"), map(parse_winners, args.winners or ("none", "none")), strict=True))


def finished_runs(roots) -> dict[str, Path]:
    """The finished runs under ``roots`` (each a directory of suites' runs), by run name."""
    return {run.name: run for root in map(Path, roots) if root.is_dir() for run in root.glob("*/students/*")
            if (run / "result.json").exists()}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wave", type=int, choices=tuple(WAVES), required=True)
    parser.add_argument("--n", type=int, nargs=2, metavar=("TD3_N", "DQN_N"), help="wave 1's winners (waves 2, 3)")
    parser.add_argument("--winners", nargs=2, metavar=("TD3", "DQN"), type=parse_winners,
                        help="wave 3: wave 2's winning changes, comma-separated, or none (e.g. layernorm,w256 none)")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--dry-run", action="store_true", help="say what would train, and train nothing")
    args = parser.parse_args(argv)
    from craftsuite.suite_runner import cells, run_students

    ns = {"Cont": args.n[0], "Grid10": args.n[1]} if args.n else {"Cont": None, "Grid10": None}
    if args.wave == 3 and args.winners is None:
        raise SystemExit("--wave 3 needs --winners: wave 2's winning changes, TD3's then DQN's (table.py says them)")
    winners = dict(zip(("Cont", "Grid10"), args.winners or ([], []), strict=True))
    for suite in RUNGS:
        wanted = [c for _, c in configs(suite, args.wave, ns, winners)]
        out = args.out / suite
        held = [out] + [Path(archive.format(suite=suite)) for archive in ARCHIVES]
        todo = [c for c in wanted if not any((h / "students" / c.run_name() / "result.json").exists() for h in held)]
        print(f"{suite}: {len(wanted)} runs, {len(wanted) - len(todo)} held already (the archive's are read "
              f"there: table.py), {len(cells(todo))} cells to train ({sum(c.steps for c in todo):,} transitions)")
        if not args.dry_run and todo:
            run_students(todo, out / "students", workers=args.workers)


if __name__ == "__main__":
    main()
