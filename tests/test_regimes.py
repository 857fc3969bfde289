"""Learner regimes: a suite's regime reaches every method's settings, a record's regime is
read back from its settings, and the leaderboard never pools two regimes' runs."""

import dataclasses

import pytest

from craftsuite.methods import METHODS
from craftsuite.regimes import REGIMES, regime_of
from craftsuite.reporting.board import build
from craftsuite.reporting.pages import comparisons, comparisons_markdown, leaderboard_markdown
from craftsuite.suites import SUITES

from .reporting.fakes import fake_run


@pytest.mark.parametrize("settings, name", [
    ({}, "one-step"), ({"n_steps": 1}, "one-step"), ({"n_steps": 3}, "n-step"),
    ({"n_steps": 3, "learning_rate": 1e-3}, "n-step"),  # a setting no regime sets tells none apart
    ({"n_steps": 5}, "n_steps=5"),  # a run's own settings, named by them
])
def test_a_records_regime_is_read_from_its_settings(settings, name):
    assert regime_of("td3", settings) == name
    assert regime_of("dqn", settings) == name


def test_a_suites_regime_reaches_every_method_and_the_command_lines_settings_win():
    suite = dataclasses.replace(SUITES["standard"], regime="n-step", tags=("middle",))
    configs = suite.student_configs("/tmp/teachers")
    assert {c.method for c in configs} >= {"td3", "td3-dynamic", "crm", "dqn", "dynamic", "rs", "td3-rs"}
    assert all(c.hyperparameters["n_steps"] == REGIMES["n-step"].settings("td3")["n_steps"] for c in configs)
    # the regime over the suite's collection settings, the command line's over both
    theirs = dataclasses.replace(suite, td3_hyperparameters={**suite.td3_hyperparameters, "n_steps": 5})
    assert {c.hyperparameters["n_steps"] for c in theirs.student_configs("/tmp/teachers") if c.world == "Cont"} == {3}
    mine = dataclasses.replace(theirs, td3_overrides={"n_steps": 5})
    assert {c.hyperparameters["n_steps"] for c in mine.student_configs("/tmp/teachers") if c.world == "Cont"} == {5}


def test_the_one_step_regime_records_nothing_new():
    """The suites' regime before regimes were named adds no setting: its runs keep their keys."""
    suite = dataclasses.replace(SUITES["standard"], regime="one-step")
    assert all("n_steps" not in c.hyperparameters for c in suite.student_configs("/tmp/teachers"))


@pytest.mark.parametrize("algorithm", ["td3", "dqn"])
def test_the_row_that_sets_most_names_a_run_that_fits_two(algorithm):
    """A run of the wide regime also fits ``n-step`` (3-step targets); the row that sets its
    networks too names it, and a 3-step run with the default networks stays ``n-step``."""
    wide = REGIMES["n-step-wide"].settings(algorithm)
    assert regime_of(algorithm, wide) == "n-step-wide"
    assert regime_of(algorithm, {"n_steps": 3, "policy_kwargs": {"net_arch": [64, 64]}}) == "n-step"


@pytest.mark.parametrize("suite", ["standard", "hard"])
def test_the_standard_and_hard_suites_train_in_the_wide_regime(suite):
    configs = SUITES[suite].student_configs("/tmp/teachers")
    names = {regime_of(METHODS[c.method].algorithm, c.hyperparameters) for c in configs}
    assert names == {"n-step-wide"}
    assert {c.hyperparameters["policy_kwargs"]["net_arch"][0] for c in configs} == {256}


def test_an_unknown_regime_is_refused_by_name():
    suite = dataclasses.replace(SUITES["standard"], regime="fast")
    with pytest.raises(ValueError,
                       match=r"^unknown learner regime 'fast'; learner regimes: one-step, n-step, "):
        suite.student_configs("/tmp/teachers")


def test_two_regimes_runs_are_two_leaderboards_never_variants(tmp_path):
    root = tmp_path / "students"
    for seed in range(3):
        for method, won in (("td3", 0.0), ("td3-dynamic", 1.0)):
            fake_run(root, method, seed, [(1000, won)], [(995, 1.0)], hyperparameters={})
            fake_run(root, method, seed, [(1000, 1.0 - won)], [(995, 1.0)], hyperparameters={"n_steps": 3})
    board = build(root)
    assert board.regimes == ["one-step", "n-step"]
    assert not any(e.variant for e in board)
    assert {(e.method, e.regime): e.values["success"] for e in board}[("td3", "n-step")] == [1.0, 1.0, 1.0]
    md = leaderboard_markdown(board)
    assert "## Learner regime `one-step`" in md and "## Learner regime `n-step`" in md
    assert "#### Cont, n-step regime" in md  # each regime's aggregate apart
    table = "\n".join(comparisons_markdown(comparisons([board])))
    assert "| BlindCraftsman | Cont | one-step | `td3-dynamic` − `td3` | 1,000 | +1.00" in table
    assert "| BlindCraftsman | Cont | n-step | `td3-dynamic` − `td3` | 1,000 | -1.00" in table
