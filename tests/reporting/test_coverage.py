"""A results page says how much of a suite, as defined now, its archive holds."""

import json

from craftsuite.reporting.coverage import coverage_markdown
from craftsuite.suites import SUITES


def _finish(root, config):
    run = root / "students" / config.run_name()
    run.mkdir(parents=True)
    (run / "result.json").write_text(json.dumps({"steps": config.steps}))


def test_archived_runs_are_counted_per_cell_and_the_rest_named(tmp_path):
    suite = SUITES["quick"]
    configs = suite.student_configs(tmp_path / "teachers")
    first = [c for c in configs if c.task == "Reach" and c.method == "td3"]
    for config in first:
        _finish(tmp_path, config)
    (tmp_path / "students" / "student-Reach-Cont-td3-s9-0000000000").mkdir()  # unfinished: no result.json
    lines = coverage_markdown(tmp_path, "quick")
    left = sum(c.steps for c in configs) - sum(c.steps for c in first)
    assert lines[0].startswith(f"The suite as defined now (one-step learner regime, {suite.seeds} seeds a cell) "
                               f"asks for {len(configs)} student runs; {len(first)} of them are archived here, "
                               f"and {left / 1e6:,.1f}M transitions are still to train.")
    reach = next(line for line in lines if "| Reach |" in line)
    assert f"| {len(first)} / {2 * suite.seeds} |" in reach and "`td3-dynamic-edges`" in reach
    assert "`td3`," not in reach
    tool = next(line for line in lines if "| FirstTool |" in line)
    assert f"| 0 / {2 * suite.seeds} |" in tool and "`td3`, `td3-dynamic-edges`" in tool


def test_a_whole_suite_has_no_table_and_an_unknown_one_no_lines(tmp_path):
    for config in SUITES["quick"].student_configs(tmp_path / "teachers"):
        _finish(tmp_path, config)
    lines = coverage_markdown(tmp_path, "quick")
    assert lines[0].endswith("all of them.") and not any(line.startswith("|") for line in lines)
    assert coverage_markdown(tmp_path, "no-such-suite") == []
