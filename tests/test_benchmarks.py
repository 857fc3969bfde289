"""The performance page is written by the benchmarks, one section each, and make bench runs them all."""

from __future__ import annotations

import datetime
import re
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = ROOT / "benchmarks"
DOC = '''Widgets per second, beside the target.

Usage: python benchmarks/x.py [--n N]

Target: at least 3 widgets.
'''


@pytest.fixture()
def page_module(monkeypatch):
    monkeypatch.syspath_prepend(str(BENCHMARKS))  # the scripts import their helpers as neighbours
    import _page

    return _page


def write(page_module, name, body, page, day=1):
    return page_module.write_section(f"benchmarks/{name}.py", DOC, body, page, argv=["--n", "5"],
                                     when=datetime.date(2026, 1, day))


def test_a_section_says_what_made_it(page_module, tmp_path):
    page = write(page_module, "grid_steps", "| a | b |", tmp_path / "docs" / "performance.md")
    text = page.read_text()
    assert text.startswith(page_module.HEADER)
    assert "## Widgets per second, beside the target" in text
    assert "Target: at least 3 widgets." in text and "Usage:" not in text
    assert "python benchmarks/grid_steps.py --n 5" in text
    assert "Measured 2026-01-01 at commit" in text and "cores" in text
    assert "| a | b |" in text


def test_a_run_replaces_only_its_own_section_and_the_page_keeps_its_order(page_module, tmp_path):
    page = tmp_path / "performance.md"
    write(page_module, "teachers", "teachers, first run", page)
    write(page_module, "automata", "automata figures", page)
    write(page_module, "teachers", "teachers, second run", page, day=2)
    text = page.read_text()
    assert "teachers, first run" not in text and "teachers, second run" in text
    assert "automata figures" in text
    assert text.index("automata figures") < text.index("teachers, second run")  # SECTIONS' order, not the runs'
    assert text.count("<!-- begin section: teachers -->") == 1


def test_a_damaged_page_is_named_and_left_as_it_was(page_module, tmp_path):
    page = tmp_path / "performance.md"
    damaged = "# Performance\n\n<!-- begin section: automata -->\nhalf a section\n"
    page.write_text(damaged)
    with pytest.raises(ValueError, match="automata.*no end marker"):
        write(page_module, "grid_steps", "figures", page)
    assert page.read_text() == damaged


def test_a_script_without_a_section_is_refused(page_module, tmp_path):
    with pytest.raises(ValueError, match="no section"):
        write(page_module, "td3_reach", "figures", tmp_path / "performance.md")
    assert not (tmp_path / "performance.md").exists()


def test_every_benchmark_has_a_section_and_a_line_in_make_bench(page_module):
    scripts = {p.stem for p in BENCHMARKS.glob("*.py") if not p.name.startswith("_")}
    assert scripts == set(page_module.SECTIONS)
    make = (ROOT / "Makefile").read_text()
    bench = make[make.index("\nbench:"):]
    bench = bench[:bench.index("\n\n")]
    assert set(re.findall(r"benchmarks/(\w+)\.py", bench)) == scripts


# each benchmark's smallest run (minutes at full size), for a test that it writes its section
TINY = {"automata": ["--tasks", "Reach", "--flloat-timeout", "5"], "code_size": ["--reference", "HEAD"],
        "cont_steps": ["--steps", "100", "--no-render"],
        "checkpoint_memory": ["--rows", "400", "--members", "2"],
        "crm_memory": ["--steps", "300"], "engine_equivalence": [], "grid_steps": ["--steps", "200"],
        "interval_coverage": ["--trials", "20"], "verdict_error": ["--trials", "4"],
        "results_page": ["results/shaping-in-mujoco/standard", "--reference", "HEAD"],
        "student_throughput": ["--seconds", "0.2", "--members", "2"],
        "teachers": ["--tasks", "Reach", "--max-steps", "300"],
        "vector_envs": ["--envs", "2", "--steps", "20"]}


@pytest.mark.slow  # runs every benchmark, if briefly
@pytest.mark.parametrize("name", sorted(p.stem for p in BENCHMARKS.glob("*.py") if not p.name.startswith("_")))
def test_every_benchmark_writes_its_section(page_module, name, tmp_path, monkeypatch):
    assert name in TINY, f"give benchmarks/{name}.py a small run in TINY"
    page = tmp_path / "performance.md"
    monkeypatch.setattr(sys, "argv", [f"{name}.py", *TINY[name], "--page", str(page)])
    import importlib

    try:
        importlib.import_module(name).main()
    finally:
        sys.modules.pop(name, None)
    assert f"<!-- begin section: {name} -->" in page.read_text()


def test_a_benchmark_run_writes_its_figures_beside_the_target(page_module, tmp_path, monkeypatch):
    page = tmp_path / "performance.md"
    monkeypatch.setattr(sys, "argv", ["grid_steps.py", "--steps", "200", "--page", str(page)])
    import grid_steps

    grid_steps.main()
    text = page.read_text()
    section = text[text.index("<!-- begin section: grid_steps -->"):]
    assert f"target >= {grid_steps.TARGET:,}" in section
    rows = [line for line in section.splitlines() if line.startswith("| CraftSuite/")]
    assert rows and all(row.split("|")[4].strip() in ("yes", "**no**") for row in rows)
    sys.modules.pop("grid_steps", None)


def test_a_description_keeps_its_list_items(page_module):
    title, about = page_module.describe("Title.\n\nUsage: x\n\nFirst, two:\n* one,\n  wrapped;\n* two.\n")
    assert title == "Title"
    assert about == "First, two:\n* one, wrapped;\n* two."


def refusal(name: str, argv: list, work: str, tmp_path, monkeypatch, capsys) -> str:
    """The one line benchmark ``name`` prints refusing ``argv``, after checking that it exits with
    argparse's code, before calling its ``work`` (replaced by a function that fails the test) and
    before writing its page."""
    page = tmp_path / "performance.md"
    monkeypatch.setattr(sys, "argv", [f"{name}.py", *argv, "--page", str(page)])
    import importlib

    module = importlib.import_module(name)

    def no_work(*args, **kwargs):
        raise AssertionError(f"{work} started before the input was checked")

    monkeypatch.setattr(module, work, no_work)
    try:
        with pytest.raises(SystemExit) as stop:
            module.main()
    finally:
        sys.modules.pop(name, None)
    assert stop.value.code == 2 and not page.exists()
    return capsys.readouterr().err.strip().splitlines()[-1]


@pytest.mark.parametrize("argv, problem", [
    (["results/shaping-in-mujoco/standard", "--reference", "no-such-commit"],
     "--reference no-such-commit: not readable from this checkout's git history"),
    (["results/no-such-archive"], "results/no-such-archive: not an archive"),
    (["results/shaping-in-mujoco/standard", "--repeat", "0"], "--repeat 0: give at least 1"),
])
def test_the_page_build_benchmark_refuses_bad_input_in_one_line_before_building(page_module, argv, problem,
                                                                                tmp_path, monkeypatch, capsys):
    last = refusal("results_page", argv, "build", tmp_path, monkeypatch, capsys)
    assert problem in last and "give" in last


def test_the_page_build_benchmark_counts_an_inserted_line_once(page_module):
    import results_page

    try:
        page = [f"line {i}" for i in range(5)]
        assert results_page.lines_differing(page, page) == 0
        assert results_page.lines_differing(page, page[:2] + ["new"] + page[2:]) == 1
        assert results_page.lines_differing(page, page[:2] + ["changed"] + page[3:]) == 1
    finally:
        sys.modules.pop("results_page", None)


@pytest.mark.parametrize("argv, problem", [
    (["--at-once", "0"], "--at-once 0: give a number of processes, 1 or more"),
    (["--at-once", "4096"], "--at-once 4096: this process may use"),
    (["--at-once", "2", "--device", "cuda"], "--at-once 2 with --device cuda: processes at once are measured on CPU"),
])
def test_the_throughput_benchmark_refuses_a_bad_process_count_before_measuring(page_module, argv, problem, tmp_path,
                                                                               monkeypatch, capsys):
    last = refusal("student_throughput", argv, "measure_population", tmp_path, monkeypatch, capsys)
    assert problem in last and "give" in last


def test_the_checkpoint_memory_benchmark_refuses_too_small_a_replay_before_measuring(page_module, tmp_path,
                                                                                    monkeypatch, capsys):
    last = refusal("checkpoint_memory", ["--rows", "2"], "measure", tmp_path, monkeypatch, capsys)
    assert "--rows 2" in last and "give at least 10 rows" in last


def test_the_suite_projection_runs_at_the_rates_of_processes_at_once(page_module):
    import student_throughput

    try:
        kinds = [("Cont", False), ("Grid", False), ("Grid", True)]
        alone = {10: {kind: 1000.0 for kind in kinds}}
        shared = {10: {kind: 500.0 for kind in kinds}}  # each of two processes at half the rate

        def hours(text):
            return float(text.split(" h (")[0].rsplit(": ", 1)[1])

        one, two = student_throughput.suite_projection("hard", alone, 1), student_throughput.suite_projection(
            "hard", shared, 2)
        assert "on 1 core:" in one and "one process alone" in one
        assert "on 2 cores:" in two and "with 2 at once" in two
        # two cores at half speed each take as long as one core at full speed
        assert hours(two) == pytest.approx(hours(one), rel=0.01)
    finally:
        sys.modules.pop("student_throughput", None)


def test_a_process_measured_at_once_that_dies_stops_the_others_and_says_so(page_module):
    import student_throughput

    try:
        row = ("dqn", "CraftSuite/NoSuchTask-Grid10-v0", 1, {}, {})  # its envs cannot be made
        started = time.perf_counter()
        with pytest.raises(RuntimeError, match="a process measuring dqn in CraftSuite/NoSuchTask-Grid10-v0 with 2 "
                                               "at once died"):
            student_throughput.measure_at_once(row, 1, 0.1, 2)
        assert time.perf_counter() - started < 120  # not the barrier's forever
    finally:
        sys.modules.pop("student_throughput", None)
