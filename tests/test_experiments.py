"""Every research folder in experiments/ says what it asked and found, and its scripts import."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest


EXPERIMENTS = sorted(p for p in (Path(__file__).resolve().parents[1] / "experiments").iterdir() if p.is_dir())


def test_there_are_experiments():
    assert EXPERIMENTS


@pytest.mark.parametrize("folder", EXPERIMENTS, ids=lambda p: p.name)
def test_each_experiment_has_a_readme_with_question_date_commit_command_conclusion(folder):
    readme = (folder / "README.md").read_text()
    for part in ("**Question**", "**Date**", "**Commit**", "**Conclusion**", "```bash"):
        assert part in readme, f"{folder.name}/README.md lacks {part}"


@pytest.mark.parametrize("script", [s for f in EXPERIMENTS for s in sorted(f.glob("*.py"))],
                         ids=lambda p: f"{p.parent.name}/{p.name}")
def test_each_experiment_script_imports(script, monkeypatch):
    monkeypatch.syspath_prepend(str(script.parent))  # scripts import their neighbours, as when run there
    spec = importlib.util.spec_from_file_location(f"experiment_{script.parent.name}_{script.stem}", script)
    module = importlib.util.module_from_spec(spec)
    try:  # (a script's own method rows go with the test: conftest)
        spec.loader.exec_module(module)
        assert callable(getattr(module, "main", None)), f"{script} has no main()"
    finally:
        sys.modules.pop(spec.name, None)


def _load(script: Path):
    spec = importlib.util.spec_from_file_location(f"experiment_{script.parent.name}_{script.stem}", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_learner_regime_wave_3_combines_wave_2s_winners_beside_wave_1s():
    run = _load(Path(__file__).resolve().parents[1] / "experiments" / "learner-regime" / "run.py")
    settings = run.wave_3("Cont", 3, ["layernorm", "gaussian"])
    assert settings == {"n3-layernorm-gaussian": {"n_steps": 3, "layer_norm": True,
                                                  "action_noise": {"type": "normal", "sigma": 0.3}},
                        "n3": {"n_steps": 3}}
    # the combination is the incumbent: wave 1's winner must beat it by the rule
    assert run.factors(3, "Cont", 3, ["layernorm", "gaussian"]) == [["n3-layernorm-gaussian", "n3"]]
    assert run.factors(3, "Grid10", 3, []) == []  # no wave-2 winner: nothing to confirm
    with pytest.raises(SystemExit, match="Grid10 has no wave-2 setting \\['gaussian'\\]"):
        run.wave_3("Grid10", 3, ["gaussian"])


def test_the_learner_regime_budget_rule_reads_the_curve_as_fixed():
    budgets = _load(Path(__file__).resolve().parents[1] / "experiments" / "learner-regime" / "budgets.py")
    curve = [(100_000, 0.0), (200_000, 0.35), (300_000, 0.55), (400_000, 0.9)]
    assert budgets.choose(curve, 400_000) == (300_000, "mean 0.55 at 300,000")
    assert budgets.choose(curve, 250_000)[0] == 200_000  # never beyond today's budget
    assert budgets.choose([(100_000, 0.1), (200_000, 0.2)], 200_000)[0] == 200_000  # below the band: kept
    assert budgets.choose([(100_000, 0.1), (200_000, 0.9)], 200_000)[0] == 100_000  # jumps past it


def test_the_hard_grid_budget_rule_takes_the_first_candidate_that_learns():
    rule = _load(Path(__file__).resolve().parents[1] / "experiments" / "suite-campaign" / "grid_budgets.py")
    assert rule.choose({50_000: 1.0}) == 50_000
    assert rule.choose({50_000: 0.4, 100_000: 0.8, 200_000: 1.0}) == 100_000  # 0.8 counts as learned
    assert rule.choose({50_000: 0.4, 100_000: 0.79}) == rule.FALLBACK == 1_000_000  # none learns: 1M


def test_the_learner_regime_grid_rule_takes_the_largest_in_the_zone_else_the_nearest():
    budgets = _load(Path(__file__).resolve().parents[1] / "experiments" / "learner-regime" / "budgets.py")
    assert budgets.grid_choice({10_000: 0.31, 15_000: 0.74, 20_000: 0.78, 30_000: 1.0})[0] == 20_000
    assert budgets.grid_choice({10_000: 0.9, 15_000: 1.0})[0] == 10_000  # none inside: the nearest
    assert budgets.grid_choice({10_000: 0.85, 15_000: 0.85})[0] == 10_000  # a tie: the smaller budget
