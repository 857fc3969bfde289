"""A results page says which of a suite's rungs some method has learned, per world."""

from craftsuite.regimes import check_regime
from craftsuite.reporting.board import build
from craftsuite.reporting.learned import learned, learned_markdown
from craftsuite.suites import SUITES

from .fakes import fake_run


def _cell(root, task, method, values, budget, **config):
    for seed, value in enumerate(values):
        fake_run(root, method, seed, [(budget, value)], [(budget, 1.0)], budget=budget, task=task, **config)


def test_learned_rungs_are_counted_per_world_and_the_rest_named(tmp_path):
    suite = SUITES["hard"]
    wide = {"hyperparameters": check_regime(suite.regime).settings("td3")}
    budget = suite.budget(next(s for s in suite.rungs() if s.name == "DungeonQuest"), "Cont")
    _cell(tmp_path, "DungeonQuest", "td3-dynamic", [1.0, 0.9, 1.0], budget, **wide)  # learned
    _cell(tmp_path, "DungeonQuest", "td3", [0.9, 0.8, 0.9], budget, **wide)  # learned as well
    _cell(tmp_path, "DungeonQuest", "td3-static", [0.0, 0.5, 0.0], budget, **wide)  # not
    _cell(tmp_path, "BlindCraftsman", "td3", [0.1, 0.0, 0.2], budget)  # one-step: named so
    _cell(tmp_path, "BlindCraftsman", "td3-dynamic", [0.9, 0.9, 0.9], 2 * budget, **wide)  # another budget: named
    lines = learned_markdown(learned(build(tmp_path), "hard"))
    cont = next(line for line in lines if line.startswith("| Cont |"))
    said, short, absent = cont.split(" | ")[1:4]
    assert said == (f"2 of {len(suite.rungs())}: BlindCraftsman (`td3-dynamic` 0.90 ({2 * budget:,} transitions)); "
                       "DungeonQuest (`td3-dynamic` 0.97 and 1 other method)")
    assert short == "none"
    assert absent.rstrip(" |") == ", ".join(s.name for s in suite.rungs()
                                           if s.name not in ("BlindCraftsman", "DungeonQuest"))
    grid = next(line for line in lines if line.startswith("| Grid10 |"))
    assert grid.startswith(f"| Grid10 | 0 of {len(suite.rungs())} | none |")


def test_a_rung_nobody_learned_names_its_best_and_an_unknown_suite_has_no_lines(tmp_path):
    _cell(tmp_path, "BlindCraftsman", "td3", [0.1, 0.0, 0.2], 1_000_000)
    _cell(tmp_path, "BlindCraftsman", "td3-dynamic", [0.3, 0.2, 0.4], 1_000_000)
    cont = next(line for line in learned_markdown(learned(build(tmp_path), "hard")) if line.startswith("| Cont |"))
    assert "| BlindCraftsman (best `td3-dynamic` 0.30 (one-step)) |" in cont
    assert learned(build(tmp_path), "no-such-suite") == [] and learned_markdown([]) == []


def test_a_rung_names_its_best_at_the_suite_s_own_setting_before_a_better_run_elsewhere(tmp_path):
    suite = SUITES["hard"]
    wide = {"hyperparameters": check_regime(suite.regime).settings("td3")}
    _cell(tmp_path, "DungeonQuest", "td3", [0.9, 0.8, 0.9], 1_000_000, **wide)  # the suite's setting
    _cell(tmp_path, "DungeonQuest", "td3-dynamic", [1.0, 1.0, 1.0], 1_000_000)  # higher, but one-step
    _cell(tmp_path, "DungeonQuest", "td3-dynamic", [1.0, 1.0, 1.0], 1_000_000, world_kwargs={"frame_skip": 2},
          **wide)  # higher, but in another world's settings
    _cell(tmp_path, "GoldMine", "td3", [0.0, 0.1, 0.2], 1_000_000, world_kwargs={"frame_skip": 2}, **wide)
    cont = next(line for line in learned_markdown(learned(build(tmp_path), "hard")) if line.startswith("| Cont |"))
    assert "DungeonQuest (`td3` 0.87 and 1 other method)" in cont
    assert "GoldMine (best `td3` 0.10 (Cont: frame_skip=2))" in cont
