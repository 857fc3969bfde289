"""Leaderboard numbers on synthetic run directories with known answers."""

import csv
import hashlib
import json

import numpy as np
import pytest

from craftsuite import leaderboard
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


@pytest.fixture
def runs(tmp_path):
    root = tmp_path / "students"
    # fast: 80% at step 500 on both seeds; returns in the last 10% (step > 900): 10 and 20
    fake_run(root, "td3-dynamic", 0, [(250, 0.2), (500, 0.8), (750, 1.0), (1000, 1.0)],
             [(100, -50.0, 1), (920, 10.0, 1), (950, 10.0, 0), (980, 10.0, 1), (1000, 10.0, 1)])
    fake_run(root, "td3-dynamic", 1, [(250, 0.4), (500, 0.8), (750, 0.8), (1000, 0.6)],
             [(900, -99.0), (990, 20.0)])
    # slow: one seed reaches 80% at 1000, the other never does
    fake_run(root, "td3", 0, [(250, 0.0), (500, 0.0), (750, 0.4), (1000, 0.8)], [(995, 0.0)])
    fake_run(root, "td3", 1, [(250, 0.0), (500, 0.0), (750, 0.0), (1000, 0.0)], [(995, -100.0)])
    (root / "student-unfinished").mkdir()  # no record at all: not a run
    teacher = root / "teacher-BlindCraftsman-Grid7"  # a teacher run: not on the board
    teacher.mkdir()
    (teacher / "config.json").write_text(json.dumps({"task": "BlindCraftsman", "max_steps": 10}))
    (teacher / "result.json").write_text(json.dumps({"kind": "teacher", "steps": 10}))
    return root


def test_run_metrics_known_answers(runs):
    m = leaderboard.run_metrics(runs / "student-BlindCraftsman-Cont-td3-dynamic-s0")
    assert m["success"] == 1.0
    assert m["auc"] == pytest.approx((0.2 + 0.8 + 1.0 + 1.0) / 4)
    assert m["steps_to_80"] == 500
    assert m["return"] == 10.0  # only the episodes after step 900
    assert m["train_success"] == 0.75  # three of the four training episodes after step 900 won
    m = leaderboard.run_metrics(runs / "student-BlindCraftsman-Cont-td3-s1")
    assert m["steps_to_80"] is None and m["success"] == 0.0 and m["return"] == -100.0


def test_entries_keep_every_seed_and_give_no_interval_below_three(runs):
    entries = {e.method: e for e in leaderboard.build(runs)}
    assert set(entries) == {"td3-dynamic", "td3"}
    dyn, td3 = entries["td3-dynamic"], entries["td3"]
    assert dyn.seeds == [0, 1] and dyn.values["success"] == [1.0, 0.6]
    success = dyn.stats["success"]
    assert success.value == pytest.approx(0.8) and not success.has_interval  # 2 seeds: the seeds alone
    assert dyn.stats["return"].value == pytest.approx(15.0)
    assert dyn.stats["train_success"].value == pytest.approx((0.75 + 0.0) / 2)
    assert (dyn.reached.k, dyn.reached.n, dyn.reached.median) == (2, 2, 500.0)
    assert (td3.reached.k, td3.reached.n, td3.reached.median) == (1, 2, 1000.0)  # the censored seed is not averaged in
    assert str(td3.reached) == "1 of 2; median 1,000"


def test_from_three_seeds_a_t_interval_clipped_to_the_rate_range(runs):
    fake_run(runs, "td3", 2, [(500, 0.9), (1000, 1.0)], [(995, 1.0)])
    td3 = {e.method: e for e in leaderboard.build(runs)}["td3"]
    values = [0.8, 0.0, 1.0]
    half = 4.302652729749464 * np.std(values, ddof=1) / np.sqrt(3)  # t(0.975, 2 degrees of freedom)
    success = td3.stats["success"]
    assert success.value == pytest.approx(0.6) and success.low == pytest.approx(max(0.0, 0.6 - half))
    assert success.high == 1.0  # the mean of a rate is at most 1
    assert str(td3.reached) == "2 of 3; median 750"


def test_a_single_seed_reads_as_its_value_and_never_as_an_interval(tmp_path):
    root = tmp_path / "students"
    fake_run(root, "td3", 0, [(500, 0.3), (1000, 0.5)], [(995, 22.2)])
    board = leaderboard.build(root)
    md = leaderboard.to_markdown(board)
    assert "| td3 | 1 | 0.50 | 0.50 | 0.40 | 22.2 |" in md and "[22.2, 22.2]" not in md
    assert "| 0 of 1 |" in md


def test_a_task_only_one_method_ran_stays_out_of_the_aggregate_and_says_so(runs):
    for seed in (0, 1, 2):
        fake_run(runs, "td3", seed, [(1000, 1.0)], [(995, 1.0)], task="Reach")
    board = leaderboard.build(runs)
    [agg] = leaderboard.aggregates(list(board))
    assert agg.tasks == ["BlindCraftsman"] and agg.baseline == "td3"
    assert "task Reach: run by td3 only" in agg.left_out
    md = leaderboard.to_markdown(board)
    assert "## Reach (Cont)" in md and "task Reach: run by td3 only" in md
    assert "| td3-dynamic | 2 |" in md.split("## Across tasks")[1]


def test_aggregates_pool_tasks_with_stratified_intervals_and_a_probability_of_improvement(tmp_path):
    root = tmp_path / "students"
    for task in ("Reach", "BlindCraftsman"):
        for seed in range(4):
            fake_run(root, "td3", seed, [(1000, (0.0, 0.5, 1.0, 0.5)[seed])], [(995, 0.0)], task=task)
            fake_run(root, "td3-dynamic", seed, [(1000, 1.0)], [(995, 0.0)], task=task)
    [agg] = leaderboard.aggregates(list(leaderboard.build(root)))
    assert agg.iqm["td3"]["success"].value == 0.5  # the middle half of 0, 0, .5, .5, .5, .5, 1, 1
    assert agg.iqm["td3-dynamic"]["success"].value == 1.0
    imp = agg.improvement["td3-dynamic"]["success"]
    assert imp.value == pytest.approx((3 + 0.5) / 4)  # beats 3 of td3's 4 seeds, ties the fourth
    assert imp.low < imp.value <= imp.high <= 1.0
    assert "td3" not in agg.improvement  # the baseline is not compared with itself
    [profile] = leaderboard.plot_profiles(leaderboard.build(root), tmp_path)
    assert profile.path.name == "profile-Cont.png" and profile.path.read_bytes()[:4] == b"\x89PNG"


def test_unfinished_and_damaged_runs_are_listed_not_averaged(runs):
    unfinished = runs / "student-BlindCraftsman-Cont-td3-s7"
    unfinished.mkdir()
    (unfinished / "config.json").write_text(json.dumps({"task": "BlindCraftsman", "world": "Cont", "method": "td3",
                                                        "seed": 7, "steps": 1000}))
    damaged = fake_run(runs, "td3", 8, [(1000, 1.0)], [(995, 1.0)])
    (damaged / "config.json").write_text("{torn")
    board = leaderboard.build(runs)
    assert {e.method: e.seeds for e in board} == {"td3": [0, 1], "td3-dynamic": [0, 1]}
    assert [u["seed"] for u in board.unfinished] == [7]
    [reason] = board.unreadable
    assert "student-BlindCraftsman-Cont-td3-s8" in reason and "not valid JSON" in reason
    md = leaderboard.to_markdown(board)
    assert "Unfinished, not counted: td3 seed 7" in md and "Not read: " in md
    assert damaged.joinpath("config.json").read_text() == "{torn"  # nothing on disk is touched


def test_a_run_recorded_by_an_older_version_loads_beside_new_ones_but_is_not_pooled_with_them(runs):
    # the fixture's runs are records without effective settings (format 1); these two are format 2
    for seed in (0, 1):
        fake_run(runs, "td3", seed, [(1000, 1.0)], [(995, 1.0)], effective={"hyperparameters": {"lr": 1}},
                 format=2, provenance=[{"commit": "abc"}])
    rows = {e.label: e for e in leaderboard.build(runs) if e.method == "td3"}
    assert set(rows) == {"td3 (a)", "td3 (b)"}
    assert sorted(json.dumps(e.differs) for e in rows.values()) == sorted(
        json.dumps(d) for d in ({"effective.hyperparameters.lr": 1}, {"effective.hyperparameters.lr": "(not recorded)"}))


def test_markdown_csv_and_plot(runs, tmp_path):
    board = leaderboard.build(runs)
    md = leaderboard.write(board, tmp_path).read_text()
    assert "## BlindCraftsman (Cont)" in md
    assert md.index("| td3-dynamic |") < md.index("| td3 |")  # ranked by AUC
    assert "| 1.00 0.60 |" in md  # every seed's final success
    assert "| 2 of 2; median 500 |" in md and "| 1 of 2; median 1,000 |" in md
    assert "reference: authors' td3-dynamic" in md and "19.95" in md
    with open(tmp_path / "leaderboard.csv") as f:
        rows = {r["method"]: r for r in csv.DictReader(f)}
    assert float(rows["td3-dynamic"]["success"]) == pytest.approx(0.8) and rows["td3-dynamic"]["success_lo"] == ""
    assert float(rows["td3-dynamic"]["train_success"]) == pytest.approx(0.375)
    assert rows["td3"]["reached_80"] == "1" and float(rows["td3"]["reached_80_median"]) == 1000
    assert rows["td3-dynamic"]["success_per_seed"] == "1.0 0.6"
    [png] = leaderboard.plot_curves(runs, tmp_path)
    assert png.name == "curves-BlindCraftsman-Cont.png" and png.read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "profile-Cont.png").exists() and "profile-Cont.png" in md


def test_runs_in_another_world_setting_get_their_own_row_and_plot(runs, tmp_path):
    fake_run(runs, "td3", 0, [(1000, 1.0)], [(995, 50.0)], world_kwargs={"frame_skip": 10, "max_episode_steps": 200})
    fake_run(runs, "dqn", 0, [(1000, 0.5)], [(995, 5.0)], world="Grid10", layout_seed=1)
    fake_run(runs, "td3", 0, [(1000, 0.2)], [(995, 9.0)], world="Kinematic")
    entries = {(e.world, e.method): e for e in leaderboard.build(runs)}
    assert entries[("Cont", "td3")].seeds == [0, 1]  # the registered world's runs are not mixed with the others
    other = entries[("Cont: frame_skip=10, max_episode_steps=200", "td3")]
    assert other.seeds == [0] and other.stats["success"].value == 1.0
    assert entries[("Grid10: layout_seed=1", "dqn")].stats["return"].value == 5.0
    md = leaderboard.to_markdown(list(entries.values()))
    sections = {part.split(")")[0]: part for part in md.split("## BlindCraftsman (")[1:]}
    assert "reference" in sections["Cont: frame_skip=10, max_episode_steps=200"]  # theirs was a 2-D toy
    assert "reference" not in sections["Grid10: layout_seed=1"]  # their numbers are continuous ones
    assert "reference" in sections["Kinematic"]  # the world their figures come from
    names = {p.name for p in leaderboard.plot_curves(runs, tmp_path)}
    assert names == {"curves-BlindCraftsman-Cont.png", "curves-BlindCraftsman-Grid10-layout_seed-1.png",
                     "curves-BlindCraftsman-Cont-frame_skip-10-max_episode_steps-200.png",
                     "curves-BlindCraftsman-Kinematic.png"}
    # settings that read alike in a file name do not overwrite each other's plot
    fake_run(runs, "td3", 0, [(1000, 0.0)], [(995, 0.0)], world_kwargs={"x": -1})
    fake_run(runs, "td3", 0, [(1000, 0.0)], [(995, 0.0)], world_kwargs={"x": 1})
    assert len({p.name for p in leaderboard.plot_curves(runs, tmp_path)}) == 6


def test_runs_of_one_method_that_differ_beyond_the_seed_are_flagged_and_not_pooled(runs, tmp_path):
    fake_run(runs, "td3", 2, [(2000, 0.0)], [(1995, 0.0)], budget=2_000)  # another budget, same world
    entries = {e.label: e for e in leaderboard.build(runs)}
    assert set(entries) == {"td3 (a)", "td3 (b)", "td3-dynamic"}
    assert entries["td3 (a)"].seeds == [0, 1] and entries["td3 (b)"].seeds == [2]
    assert entries["td3 (a)"].differs == {"steps": 1000} and entries["td3 (b)"].differs == {"steps": 2000}
    md = leaderboard.to_markdown(list(entries.values()))
    assert "are not pooled" in md and "- *td3 (b): steps = 2000*" in md
    assert "td3: runs of more than one setting" in md  # nor aggregated
    with open(leaderboard.write(list(entries.values()), tmp_path).with_suffix(".csv")) as f:
        assert {(r["method"], r["variant"]): r["differs_in"] for r in csv.DictReader(f)} == {
            ("td3", "a"): "steps", ("td3", "b"): "steps", ("td3-dynamic", ""): ""}


def test_budget_reads_in_transitions_and_gradient_updates_and_methods_are_explained(runs):
    for seed, updates in ((5, 240), (6, 260)):
        run = fake_run(runs, "td3-dynamic-edges", seed, [(1000, 0.5)], [(995, 1.0)])
        (run / "result.json").write_text(json.dumps({"kind": "student", "steps": 1000, "updates": updates}))
    entries = {e.method: e for e in leaderboard.build(runs)}
    assert entries["td3-dynamic-edges"].budget_text == "1,000 / 250"
    assert entries["td3"].budget_text == "1,000 / ?"  # runs from before updates were recorded
    md = leaderboard.to_markdown(list(entries.values()))
    assert "| 1,000 / 250 |" in md
    assert "- `td3-dynamic-edges`: td3-dynamic with the teacher's values on the automaton's edges only" in md
    assert md.index("- `td3`:") < md.index("- `td3-dynamic`:")  # the legend follows the methods table


def test_results_page_names_the_missing_and_the_empty(tmp_path):
    with pytest.raises(FileNotFoundError, match="no run directory"):
        leaderboard.write_page([tmp_path / "nope"], tmp_path / "results.md")
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="no finished student runs"):
        leaderboard.write_page([tmp_path / "empty"], tmp_path / "results.md")
    assert not (tmp_path / "results.md").exists()


def test_a_directory_of_unfinished_runs_only_is_named_as_such(tmp_path):
    run = tmp_path / "students" / "student-Reach-Cont-td3-s0"
    run.mkdir(parents=True)
    (run / "config.json").write_text(json.dumps({"task": "Reach", "world": "Cont", "method": "td3", "seed": 0,
                                                 "steps": 1000}))
    with pytest.raises(ValueError, match=r"no finished student runs under .*students \(1 unfinished\)"):
        leaderboard.write_page([tmp_path], tmp_path / "results.md")
    assert not (tmp_path / "results.md").exists() and (run / "config.json").exists()


def test_a_task_only_the_baseline_ran_with_one_seed_does_not_drop_the_baseline(runs):
    fake_run(runs, "td3", 0, [(1000, 1.0)], [(995, 1.0)], task="Reach")  # one seed, and only td3 ran Reach
    [agg] = leaderboard.aggregates(list(leaderboard.build(runs)))
    assert agg.baseline == "td3" and set(agg.improvement) == {"td3-dynamic"}
    assert agg.tasks == ["BlindCraftsman"] and "task Reach: run by td3 only" in agg.left_out


def test_a_run_without_evaluations_is_no_estimate_and_is_left_out_of_the_aggregate_by_name(runs):
    fake_run(runs, "td3", 2, [], [(995, 1.0)])  # finished, but never evaluated
    board = leaderboard.build(runs)
    td3 = {e.method: e for e in board}["td3"]
    assert np.isnan(td3.stats["success"].value) and not td3.stats["success"].has_interval
    [agg] = leaderboard.aggregates(list(board))
    assert "1 run without an evaluation" in agg.left_out and agg.runs["td3"] == 2
    assert agg.iqm["td3"]["success"].value == pytest.approx(0.4)  # the two evaluated runs: 0.8 and 0.0
    with open(leaderboard.write(board, runs.parent).with_suffix(".csv")) as f:
        row = next(r for r in csv.DictReader(f) if r["method"] == "td3")
    assert row["success"] == row["success_lo"] == row["success_hi"] == ""


def test_a_world_with_nothing_to_aggregate_says_why(tmp_path):
    root = tmp_path / "students"
    fake_run(root, "td3", 0, [(1000, 1.0)], [(995, 1.0)])
    fake_run(root, "td3-dynamic", 0, [(1000, 1.0)], [(995, 1.0)])
    md = leaderboard.to_markdown(leaderboard.build(root))
    assert "### Cont\n\nNothing to aggregate: td3, td3-dynamic: fewer than 2 runs on some task" in md
    assert leaderboard.plot_profiles(leaderboard.build(root), tmp_path) == []


def test_each_task_says_whether_a_method_reaches_80_percent_in_half_of_scratchs_transitions(tmp_path):
    root = tmp_path / "students"
    evals = {"late": [(500, 0.0), (1000, 0.8)], "early": [(500, 0.8), (1000, 1.0)], "never": [(500, 0.0), (1000, 0.0)]}
    for seed, speed in enumerate(["late", "late", "never"]):  # scratch: median 1,000
        fake_run(root, "td3", seed, evals[speed], [])
    for seed, speed in enumerate(["early", "early", "never"]):  # median 500: half of scratch's, met
        fake_run(root, "td3-crm-edges", seed, evals[speed], [])
    for seed, speed in enumerate(["early", "late", "late"]):  # median 1,000: not met, though one seed was early
        fake_run(root, "td3-dynamic", seed, evals[speed], [])
    board = leaderboard.build(root)
    line = next(l for l in leaderboard.to_markdown(board).splitlines() if l.startswith("Transfer target"))
    assert "`td3` needs" in line
    assert "`td3-crm-edges` met (500 against 1,000)" in line
    assert "`td3-dynamic` not met (1,000 against 1,000)" in line
    # where scratch never gets there, reaching 80% at all meets it; never reaching never does
    never = tmp_path / "never"
    for seed in range(3):
        fake_run(never, "td3", seed, evals["never"], [])
        fake_run(never, "td3-crm-edges", seed, evals["early"] if seed else evals["never"], [])
        fake_run(never, "td3-dynamic", seed, evals["never"], [])
    line = next(l for l in leaderboard.to_markdown(leaderboard.build(never)).splitlines()
                if l.startswith("Transfer target"))
    assert "`td3-crm-edges` met: scratch never got there (500 against never in 1,000)" in line  # never, 500, 500
    assert "`td3-dynamic` not met (never in 1,000 against never in 1,000)" in line
    # scratch with a smaller budget than the student's never says enough
    small = tmp_path / "small"
    for seed in range(3):
        fake_run(small, "td3", seed, [(250, 0.0), (500, 0.0)], [], budget=500)
        fake_run(small, "td3-crm-edges", seed, [(750, 0.8), (1000, 0.9)], [])
        fake_run(small, "product-td3", seed, evals["early"], [])  # no distilled target: no verdict
    line = next(l for l in leaderboard.to_markdown(leaderboard.build(small)).splitlines()
                if l.startswith("Transfer target"))
    assert line.endswith("`td3-crm-edges` not met (750 against never in 500).")
