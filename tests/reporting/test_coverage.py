"""A results page says how much of a suite, as defined now, its archive holds."""

import json

from craftsuite.reporting.coverage import coverage, coverage_markdown
from craftsuite.suites import SUITES


def _finish(root, config):
    run = root / "students" / config.run_name()
    run.mkdir(parents=True)
    (run / "result.json").write_text(json.dumps({"steps": config.steps}))


def test_archived_runs_are_counted_per_cell_and_the_rest_named(tmp_path):
    suite = SUITES["quick"]
    configs = suite.student_configs(tmp_path / "teachers")
    first = [c for c in configs if c.task == "Reach" and c.method == "td3"]
    some = [c for c in configs if c.task == "FirstTool" and c.method == "td3"][:1]  # a method part-way
    for config in first + some:
        _finish(tmp_path, config)
    (tmp_path / "students" / "student-Reach-Cont-td3-s9-0000000000").mkdir()  # unfinished: no result.json
    lines = coverage_markdown(coverage(tmp_path, "quick"))
    assert "in all" not in lines[0]  # every finished run is one of the suite's
    extra = tmp_path / "students" / "student-Reach-Cont-td3-s99-0000000000"  # a seed beyond the suite's
    extra.mkdir()
    (extra / "result.json").write_text("{}")
    lines = coverage_markdown(coverage(tmp_path, "quick"))
    assert (f"The directory holds {len(first) + 2} finished student runs in all: the others are runs the suite does "
            "not ask for now") in lines[0]
    left = sum(c.steps for c in configs) - sum(c.steps for c in first + some)
    assert lines[0].startswith(f"The suite as defined now (one-step learner regime; {suite.seeds} seeds a cell) "
                               f"asks for {len(configs)} student runs; {len(first) + 1} of them are archived here, "
                               f"and {left / 1e6:,.1f}M transitions are still to train.")
    reach = next(line for line in lines if "| Reach |" in line)
    assert f"| {len(first)} / {2 * suite.seeds} |" in reach and "`td3-dynamic-edges`" in reach
    assert reach.endswith("| `td3-dynamic-edges` |")  # td3's seeds all archived: not listed
    tool = next(line for line in lines if "| FirstTool |" in line)
    assert f"| 1 / {2 * suite.seeds} |" in tool and f"`td3` (1 of {suite.seeds}), `td3-dynamic-edges` |" in tool


def test_a_whole_suite_has_no_table_and_an_unknown_one_no_lines(tmp_path):
    for config in SUITES["quick"].student_configs(tmp_path / "teachers"):
        _finish(tmp_path, config)
    lines = coverage_markdown(coverage(tmp_path, "quick"))
    assert lines[0].endswith("all of them.") and not any(line.startswith("|") for line in lines)
    assert coverage(tmp_path, "no-such-suite") is None and coverage_markdown(None) == []


def test_the_time_still_to_train_is_projected_from_the_rates_the_runs_recorded(tmp_path):
    configs = SUITES["quick"].student_configs(tmp_path / "teachers")
    left = sum(c.steps for c in configs)  # nothing archived; the quick suite is MuJoCo only
    line = coverage_markdown(coverage(tmp_path, "quick", {"Cont": 1_000.0}))[0]
    hours = left / 1_000 / 3600
    assert line.endswith("At the rates this page's runs of its learner regime recorded on CPUs (one population "
                         "process each, averaged over the tasks, methods and population sizes that ran: Cont 1,000 "
                         "transitions/s), that is about "
                         f"{hours:,.1f} h of one process, {hours / 2:,.1f} h on 2 cores with a population on each.")
    # no rate for the suite's world: no projection
    assert "At the rates" not in coverage_markdown(coverage(tmp_path, "quick", {"Grid10": 1_000.0}))[0]


def test_rates_are_transitions_over_each_population_s_time_on_cpus(tmp_path):
    from craftsuite.reporting.board import build
    from craftsuite.reporting.timing import rates

    from .fakes import fake_run

    for seed in range(2):  # a population of 2: 2 x 1,000 transitions in 4 s of one process
        run = fake_run(tmp_path, "td3", seed, [(1000, 0.5)], [(995, 1.0)])
        (run / "result.json").write_text(json.dumps({"kind": "student", "steps": 1000, "seconds_share": 2.0,
                                                     "members": 2, "device": "cpu"}))
    run = fake_run(tmp_path, "td3-dynamic", 0, [(1000, 0.5)], [(995, 1.0)])  # on a GPU: not a CPU's rate
    (run / "result.json").write_text(json.dumps({"kind": "student", "steps": 1000, "seconds_share": 0.1,
                                                 "device": "cuda"}))
    # older records: their last session's time, whole only where they trained in one session
    for seed, sessions, seconds in ((0, 1, 4.0), (1, 2, 1.0)):
        run = fake_run(tmp_path, "td3-static", seed, [(1000, 0.5)], [(995, 1.0)])
        config = json.loads((run / "config.json").read_text())
        (run / "config.json").write_text(json.dumps({**config, "provenance": [{"commit": "x"}] * sessions}))
        (run / "result.json").write_text(json.dumps({"kind": "student", "steps": 1000,
                                                     "seconds_this_session": seconds, "members": 2, "device": "cpu"}))
    # 3,000 transitions in 2 + 2 + 2 s: the resumed run's last session alone would read faster than it ran
    assert rates(build(tmp_path)) == {"one-step": {"Cont": 500.0}}  # no run of another regime: no rate of it


def test_a_rung_with_more_seeds_asks_for_them(tmp_path):
    line, *rows = coverage_markdown(coverage(tmp_path, "standard"))
    assert line.startswith("The suite as defined now (n-step-wide learner regime; 10 seeds a cell, 20 on "
                           "KeySwordDragon, ToolHome, TwoToolsHome in the grid worlds) asks for ")
    assert "| Grid10 | ToolHome | 0 / 140 |" in "\n".join(rows) and "| Cont | ToolHome | 0 / 70 |" in "\n".join(rows)
