"""Leaderboard entries, aggregates and verdicts on synthetic run directories with known answers."""

import csv
import json

import numpy as np
import pytest

from craftsuite.reporting.board import Board, aggregates, build, run_metrics, verdict
from craftsuite.reporting.pages import aggregates_markdown, leaderboard_markdown, write_leaderboard

from .fakes import fake_run


def two_tasks(root, scratch: float, distilled: float, seeds=range(3)):
    """``td3`` and ``td3-dynamic`` on Reach and Blind Craftsman, every seed at these final successes."""
    for seed in seeds:
        for task in ("Reach", "BlindCraftsman"):
            fake_run(root, "td3", seed, [(1000, scratch)], [(995, 0.0)], task=task)
            fake_run(root, "td3-dynamic", seed, [(1000, distilled)], [(995, 0.0)], task=task)


def test_run_metrics_known_answers(runs):
    m = run_metrics(runs / "student-BlindCraftsman-Cont-td3-dynamic-s0")
    assert m["success"] == 1.0
    assert m["auc"] == pytest.approx((0.2 + 0.8 + 1.0 + 1.0) / 4)
    assert m["steps_to_80"] == 500
    assert m["return"] == 10.0  # only the episodes after step 900
    assert m["train_success"] == 0.75  # three of the four training episodes after step 900 won
    m = run_metrics(runs / "student-BlindCraftsman-Cont-td3-s1")
    assert m["steps_to_80"] is None and m["success"] == 0.0 and m["return"] == -100.0


def test_entries_keep_every_seed_and_give_no_interval_below_three(runs):
    entries = {e.method: e for e in build(runs)}
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
    td3 = {e.method: e for e in build(runs)}["td3"]
    values = [0.8, 0.0, 1.0]
    half = 4.302652729749464 * np.std(values, ddof=1) / np.sqrt(3)  # t(0.975, 2 degrees of freedom)
    success = td3.stats["success"]
    assert success.value == pytest.approx(0.6) and success.low == pytest.approx(max(0.0, 0.6 - half))
    assert success.high == 1.0  # the mean of a rate is at most 1
    assert str(td3.reached) == "2 of 3; median 750"


def test_a_task_only_one_method_ran_stays_out_of_the_aggregate_and_says_so(runs):
    for seed in (0, 1, 2):
        fake_run(runs, "td3", seed, [(1000, 1.0)], [(995, 1.0)], task="Reach")
    board = build(runs)
    [agg] = aggregates(list(board))
    assert agg.tasks == ["BlindCraftsman"] and agg.baseline == "td3"
    assert "task Reach: run by td3 only" in agg.left_out
    md = leaderboard_markdown(board)
    assert "## Reach (Cont)" in md and "task Reach: run by td3 only" in md
    assert "| td3-dynamic | 2 |" in md.split("## Across tasks")[1]


def test_a_record_not_read_is_named_by_its_sentence_and_a_bare_key_by_its_class(tmp_path):
    root = tmp_path / "students"
    fake_run(root, "td3", 0, [(1000, 1.0)], [(995, 1.0)])
    wrong = fake_run(root, "td3", 1, [(1000, 1.0)], [(995, 1.0)], automaton_state="yes")
    nowhere = fake_run(root, "td3", 2, [(1000, 1.0)], [(995, 1.0)], world="Grid")
    board = build(root)
    assert sorted(board.unreadable) == sorted([
        f"{wrong / 'config.json'}: automaton_state must be true, false or null, got 'yes'",
        f"{nowhere / 'config.json'}: unknown world 'Grid': use Cont (MuJoCo), Kinematic or Grid<size>, e.g. Grid10"])
    assert [e.seeds for e in board.entries] == [[0]]


def test_aggregates_pool_tasks_with_stratified_intervals_and_a_probability_of_improvement(tmp_path):
    root = tmp_path / "students"
    for task in ("Reach", "BlindCraftsman"):
        for seed in range(4):
            fake_run(root, "td3", seed, [(1000, (0.0, 0.5, 1.0, 0.5)[seed])], [(995, 0.0)], task=task)
            fake_run(root, "td3-dynamic", seed, [(1000, 1.0)], [(995, 0.0)], task=task)
    [agg] = aggregates(list(build(root)))
    assert agg.iqm["td3"]["success"].value == 0.5  # the middle half of 0, 0, .5, .5, .5, .5, 1, 1
    assert agg.iqm["td3-dynamic"]["success"].value == 1.0
    imp = agg.improvement["td3-dynamic"]["success"]
    assert imp.value == pytest.approx((3 + 0.5) / 4)  # beats 3 of td3's 4 seeds, ties the fourth
    assert imp.low < imp.value <= imp.high <= 1.0
    assert "td3" not in agg.improvement  # the baseline is not compared with itself


def test_unfinished_and_damaged_runs_are_listed_not_averaged(runs):
    unfinished = runs / "student-BlindCraftsman-Cont-td3-s7"
    unfinished.mkdir()
    (unfinished / "config.json").write_text(json.dumps({"task": "BlindCraftsman", "world": "Cont", "method": "td3",
                                                        "seed": 7, "steps": 1000}))
    damaged = fake_run(runs, "td3", 8, [(1000, 1.0)], [(995, 1.0)])
    (damaged / "config.json").write_text("{torn")
    board = build(runs)
    assert {e.method: e.seeds for e in board} == {"td3": [0, 1], "td3-dynamic": [0, 1]}
    assert [u.seed for u in board.unfinished] == [7]
    [reason] = board.unreadable
    assert "student-BlindCraftsman-Cont-td3-s8" in reason and "not valid JSON" in reason
    md = leaderboard_markdown(board)
    assert "Unfinished, not counted: td3 seed 7" in md and "Not read: " in md
    assert damaged.joinpath("config.json").read_text() == "{torn"  # nothing on disk is touched


def test_a_board_kept_to_some_runs_reads_no_other(runs):
    damaged = fake_run(runs, "td3-dynamic", 8, [(1000, 1.0)], [(995, 1.0)])
    (damaged / "evals.csv").write_text("step,success,return,episodes\nlate,1.0,0.0,10\n")
    unfinished = runs / "student-BlindCraftsman-Cont-td3-dynamic-s9"
    unfinished.mkdir()
    (unfinished / "config.json").write_text(json.dumps({"task": "BlindCraftsman", "world": "Cont",
                                                        "method": "td3-dynamic", "seed": 9, "steps": 1000}))
    everything = build(runs)
    assert len(everything.unreadable) == 1 and [u.seed for u in everything.unfinished] == [9]
    kept = build(runs, keep=lambda config: config.get("method") == "td3")  # a teacher's config names none
    assert [(e.method, e.seeds) for e in kept] == [("td3", [0, 1])]
    assert not kept.unreadable and not kept.unfinished
    [td3] = [e for e in everything if e.method == "td3"]
    assert kept.entries[0].values == td3.values  # the runs kept read as on the whole board
    with pytest.raises(KeyError, match="method"):  # the caller's test at fault, not a record
        build(runs, keep=lambda config: config["method"] == "td3")


def test_a_run_recorded_by_an_older_version_loads_beside_new_ones_but_is_not_pooled_with_them(runs):
    # the fixture's runs are records without effective settings (format 1); these two are format 2
    for seed in (0, 1):
        fake_run(runs, "td3", seed, [(1000, 1.0)], [(995, 1.0)], effective={"hyperparameters": {"lr": 1}},
                 format=2, provenance=[{"commit": "abc"}])
    rows = {e.label: e for e in build(runs) if e.method == "td3"}
    assert set(rows) == {"td3 (a)", "td3 (b)"}
    assert sorted(json.dumps(e.differs) for e in rows.values()) == sorted(
        json.dumps(d) for d in ({"effective.hyperparameters.lr": 1},
                                {"effective.hyperparameters.lr": "(not recorded)"}))


def test_runs_in_another_world_setting_get_their_own_row(runs):
    fake_run(runs, "td3", 0, [(1000, 1.0)], [(995, 50.0)], world_kwargs={"frame_skip": 10, "max_episode_steps": 200})
    fake_run(runs, "dqn", 0, [(1000, 0.5)], [(995, 5.0)], world="Grid10", layout_seed=1)
    fake_run(runs, "td3", 0, [(1000, 0.2)], [(995, 9.0)], world="Kinematic")
    entries = {(e.world_label, e.method): e for e in build(runs)}
    assert entries[("Cont", "td3")].seeds == [0, 1]  # the registered world's runs are not mixed with the others
    other = entries[("Cont: frame_skip=10, max_episode_steps=200", "td3")]
    assert other.seeds == [0] and other.stats["success"].value == 1.0
    assert (other.world, other.world_kwargs) == ("Cont", {"frame_skip": 10, "max_episode_steps": 200})
    grid = entries[("Grid10: layout_seed=1", "dqn")]
    assert grid.stats["return"].value == 5.0 and (grid.world, grid.world_kwargs) == ("Grid10", {"layout_seed": 1})
    md = leaderboard_markdown(Board(list(entries.values())))
    sections = {part.split(")")[0]: part for part in md.split("## BlindCraftsman (")[1:]}
    assert "reference" in sections["Cont: frame_skip=10, max_episode_steps=200"]  # theirs was a 2-D toy
    assert "reference" not in sections["Grid10: layout_seed=1"]  # their numbers are continuous ones
    assert "reference" in sections["Kinematic"]  # the world their figures come from


def test_runs_of_one_method_that_differ_beyond_the_seed_are_flagged_and_not_pooled(runs, tmp_path):
    fake_run(runs, "td3", 2, [(2000, 0.0)], [(1995, 0.0)], budget=2_000)  # another budget, same world
    entries = {e.label: e for e in build(runs)}
    assert set(entries) == {"td3 (a)", "td3 (b)", "td3-dynamic"}
    assert entries["td3 (a)"].seeds == [0, 1] and entries["td3 (b)"].seeds == [2]
    assert entries["td3 (a)"].differs == {"steps": 1000} and entries["td3 (b)"].differs == {"steps": 2000}
    md = leaderboard_markdown(Board(list(entries.values())))
    assert "are not pooled" in md and "- *td3 (b): steps = 2000*" in md
    # nor aggregated: the baseline is two cells on its only task, so it leaves (the task stays for the others)
    assert "td3: runs of more than one setting on BlindCraftsman" in md
    with open(write_leaderboard(Board(list(entries.values())), tmp_path).with_suffix(".csv")) as f:
        assert {(r["method"], r["variant"]): r["differs_in"] for r in csv.DictReader(f)} == {
            ("td3", "a"): "steps", ("td3", "b"): "steps", ("td3-dynamic", ""): ""}


def test_the_notes_on_variants_follow_their_letters_where_the_table_ranks_b_first(runs):
    fake_run(runs, "td3", 2, [(2000, 1.0)], [(1995, 9.0)], budget=2_000)  # (b): one seed, and at 1.0
    md = leaderboard_markdown(Board(list(build(runs))))
    assert md.index("| td3 (b) |") < md.index("| td3 (a) |")  # the table ranks by success
    assert md.index("- *td3 (a): steps = 1000*") < md.index("- *td3 (b): steps = 2000*")


def test_a_task_only_the_baseline_ran_with_one_seed_does_not_drop_the_baseline(runs):
    fake_run(runs, "td3", 0, [(1000, 1.0)], [(995, 1.0)], task="Reach")  # one seed, and only td3 ran Reach
    [agg] = aggregates(list(build(runs)))
    assert agg.baseline == "td3" and set(agg.improvement) == {"td3-dynamic"}
    assert agg.tasks == ["BlindCraftsman"] and "task Reach: run by td3 only" in agg.left_out


def test_the_baseline_in_two_settings_on_one_task_drops_that_task_not_the_baseline(tmp_path):
    root = tmp_path / "students"
    two_tasks(root, 0.5, 1.0)
    for seed in range(3):  # candidates at another budget on a third task: td3 there is two cells
        fake_run(root, "td3", seed, [(1000, 0.0)], [(995, 0.0)], task="DungeonQuest")
        fake_run(root, "td3", seed + 3, [(2000, 0.0)], [(1995, 0.0)], task="DungeonQuest", budget=2_000)
    [agg] = aggregates(list(build(root)))
    assert agg.baseline == "td3" and agg.tasks == ["Reach", "BlindCraftsman"]
    assert agg.improvement["td3-dynamic"]["success"].value == 1.0
    assert "task DungeonQuest: the baseline td3 there has runs of more than one setting" in agg.left_out


def test_another_method_in_two_settings_leaves_the_aggregate_and_the_others_keep_the_task(tmp_path):
    root = tmp_path / "students"
    for seed in range(3):
        fake_run(root, "td3", seed, [(1000, 0.5)], [(995, 0.0)])
        fake_run(root, "td3-static", seed, [(1000, 0.5)], [(995, 0.0)])
        fake_run(root, "td3-dynamic", seed, [(1000, 1.0)], [(995, 0.0)])
        fake_run(root, "td3-dynamic", seed + 3, [(2000, 1.0)], [(1995, 0.0)], budget=2_000)
    [agg] = aggregates(list(build(root)))
    assert agg.tasks == ["BlindCraftsman"] and set(agg.improvement) == {"td3-static"}
    assert "td3-dynamic: runs of more than one setting on BlindCraftsman" in agg.left_out


def test_a_method_whose_odd_cell_sat_on_a_task_the_baseline_took_away_stays(tmp_path):
    root = tmp_path / "students"
    two_tasks(root, 0.5, 1.0)
    for seed in range(3):
        for method in ("td3", "td3-dynamic"):  # both ran budget candidates on a third task
            fake_run(root, method, seed, [(1000, 0.0)], [(995, 0.0)], task="DungeonQuest")
            fake_run(root, method, seed + 3, [(2000, 0.0)], [(1995, 0.0)], task="DungeonQuest", budget=2_000)
    [agg] = aggregates(list(build(root)))
    assert agg.tasks == ["Reach", "BlindCraftsman"] and set(agg.improvement) == {"td3-dynamic"}
    assert not any(line.startswith("td3-dynamic:") for line in agg.left_out)


def test_a_baseline_two_cells_on_every_task_it_ran_leaves_and_the_others_keep_their_tasks(tmp_path):
    root = tmp_path / "students"
    for seed in range(3):
        for task in ("Reach", "BlindCraftsman"):
            fake_run(root, "td3", seed, [(1000, 0.5)], [(995, 0.0)], task=task)
            fake_run(root, "td3", seed + 3, [(2000, 0.5)], [(1995, 0.0)], task=task, budget=2_000)
            fake_run(root, "td3-dynamic", seed, [(1000, 1.0)], [(995, 0.0)], task=task)
            fake_run(root, "td3-static", seed, [(1000, 0.0)], [(995, 0.0)], task=task)
    [agg] = aggregates(list(build(root)))
    assert agg.tasks == ["Reach", "BlindCraftsman"] and agg.baseline is None
    assert set(agg.iqm) == {"td3-dynamic", "td3-static"} and not agg.against_baseline
    assert ("td3: runs of more than one setting on Reach; runs of more than one setting on BlindCraftsman"
            in agg.left_out)


def test_where_no_task_has_every_method_each_still_meets_the_baseline_on_its_own_tasks(tmp_path):
    root = tmp_path / "students"
    for seed in range(3):
        for task in ("Reach", "BlindCraftsman"):
            fake_run(root, "td3", seed, [(1000, 0.0)], [(995, 0.0)], task=task)
        fake_run(root, "td3-dynamic", seed, [(1000, 1.0)], [(995, 0.0)], task="Reach")
        fake_run(root, "td3-static", seed, [(1000, 1.0)], [(995, 0.0)], task="BlindCraftsman")
    [agg] = aggregates(list(build(root)))
    assert not agg.iqm and agg.against_baseline["td3-dynamic"].tasks == ["Reach"]
    md = "\n".join(aggregates_markdown([agg]))
    assert "Nothing to aggregate" in md and "each method against it on the tasks both ran below" in md
    assert "| td3-static | 1 (BlindCraftsman) | 3 / 3 | 1.00" in md and "None" not in md


def test_a_finished_run_without_evaluations_is_named_as_damaged_and_its_cell_keeps_the_others(runs):
    """A finished run evaluates at its end: one without an evaluation is a damaged record,
    named among those not read (as the archive refuses it), where its blank success had
    blanked its whole cell's mean."""
    bare = fake_run(runs, "td3", 2, [], [(995, 1.0)])  # finished, but never evaluated
    board = build(runs)
    td3 = {e.method: e for e in board}["td3"]
    assert td3.seeds == [0, 1] and td3.stats["success"].value == pytest.approx(0.4)  # 0.8 and 0.0
    assert board.unreadable == [f"{bare / 'evals.csv'} holds no evaluation: a finished run's record has one at least "
                                "(at its end): the record breaks the record format (docs/records.md)"]
    [agg] = aggregates(list(board))
    assert agg.runs["td3"] == 2 and agg.iqm["td3"]["success"].value == pytest.approx(0.4)


def test_each_task_says_whether_a_method_reaches_80_percent_in_half_of_scratchs_transitions(tmp_path):
    root = tmp_path / "students"
    evals = {"late": [(500, 0.0), (1000, 0.8)], "early": [(500, 0.8), (1000, 1.0)], "never": [(500, 0.0), (1000, 0.0)]}
    for seed, speed in enumerate(["late", "late", "never"]):  # scratch: median 1,000
        fake_run(root, "td3", seed, evals[speed], [])
    for seed, speed in enumerate(["early", "early", "never"]):  # median 500: half of scratch's, met
        fake_run(root, "td3-crm-edges", seed, evals[speed], [])
    for seed, speed in enumerate(["early", "late", "late"]):  # median 1,000: not met, though one seed was early
        fake_run(root, "td3-dynamic", seed, evals[speed], [])
    board = build(root)
    line = next(row for row in leaderboard_markdown(board).splitlines() if row.startswith("Transfer target"))
    assert "`td3` needs" in line
    assert "`td3-crm-edges` met (500 against 1,000; half of it 500)" in line
    assert "`td3-dynamic` not met (1,000 against 1,000; half of it 500)" in line
    # where scratch never gets there, reaching 80% within half its budget meets it; never reaching never does
    never = tmp_path / "never"
    for seed in range(3):
        fake_run(never, "td3", seed, evals["never"], [])
        fake_run(never, "td3-crm-edges", seed, evals["early"] if seed else evals["never"], [])
        fake_run(never, "td3-dynamic", seed, evals["never"], [])
    line = next(row for row in leaderboard_markdown(build(never)).splitlines()
                if row.startswith("Transfer target"))
    # seeds: never, 500, 500
    assert "`td3-crm-edges` met: scratch never got there (500 against never in 1,000; half of it above 500)" in line
    assert ("`td3-dynamic` not known: neither got there within its budget (never in 1,000 against never in 1,000; "
            "half of it above 500)") in line
    # reaching 80% after half the budget scratch never learned in says nothing either way
    small = tmp_path / "small"
    for seed in range(3):
        fake_run(small, "td3", seed, [(250, 0.0), (500, 0.0)], [], budget=500)
        fake_run(small, "td3-crm-edges", seed, [(750, 0.8), (1000, 0.9)], [])
        fake_run(small, "product-td3", seed, evals["early"], [])  # no distilled target: no verdict
    line = next(row for row in leaderboard_markdown(build(small)).splitlines()
                if row.startswith("Transfer target"))
    assert line.endswith("`td3-crm-edges` not known: scratch never got there in its budget, and this took more "
                         "than half of it (750 against never in 500; half of it above 250).")


def test_interval_verdicts_follow_the_intervals(tmp_path):
    def seeds(method, success, task="BlindCraftsman", world="Kinematic", n=5, ret=0.0):
        for seed in range(n):
            value = success + 0.01 * seed if success else 0.0
            fake_run(tmp_path, method, seed, [(500, value), (1000, value)], [(950, ret + seed)], task=task, world=world)

    seeds("td3-dynamic", 0.8, ret=50.0)
    seeds("td3", 0.1)
    seeds("td3-dynamic", 0.0, world="Cont", n=2)
    seeds("td3", 0.0, world="Cont", n=2)
    for method, success in (("dynamic", 0.1), ("crm", 0.1), ("product-dqn", 0.6)):
        seeds(method, success, task="DungeonQuest", world="Grid10")
    board = {(e.task, e.world, e.method): e for e in build(tmp_path)}
    ahead, td3 = board["BlindCraftsman", "Kinematic", "td3-dynamic"], board["BlindCraftsman", "Kinematic", "td3"]
    assert verdict(ahead, td3, "auc") == "ahead" and verdict(td3, ahead, "auc") == "behind"
    assert verdict(ahead, td3, "return") == "ahead"
    dq = {m: board["DungeonQuest", "Grid10", m] for m in ("dynamic", "crm", "product-dqn")}
    assert verdict(dq["dynamic"], dq["product-dqn"], "auc") == "behind"
    assert verdict(dq["dynamic"], dq["crm"], "auc") == "no difference measured"
    nothing = board["BlindCraftsman", "Cont", "td3-dynamic"], board["BlindCraftsman", "Cont", "td3"]
    assert verdict(*nothing, "auc") == "neither learned"
    assert verdict(*nothing, "return") == "too few seeds"  # two seeds each: no interval
    # the transfer target on the same entries: 80% at 500 against never
    assert verdict(ahead, td3, "steps_to_80") == ("met: scratch never got there (500 against never in 1,000; "
                                                  "half of it above 500)")


@pytest.mark.parametrize("name, text, problem", [
    ("result.json", "{torn", "is not valid JSON"),
    ("result.json", json.dumps({"steps": 1000}), "holds no student's or teacher's result"),
    ("result.json", json.dumps({"kind": "student"}), "holds no transitions"),
    ("evals.csv", "step,success,return,episodes\nlate,1.0,0.0,10\n", "line 2: step 'late' is not a number"),
    ("episodes.csv", "step,return,length,success\n995,high,10,1\n", "line 2: return 'high' is not a number"),
    # the record format's checks (craftsuite.record_format)
    ("evals.csv", "step,success,return,episodes\n1000,1.0,nan,10\n", "line 2: return is nan: a record holds finite"),
    ("evals.csv", "step,success,return,episodes\n1000,1.5,0.0,10\n", "line 2: success 1.5 is not a rate in [0, 1]"),
    ("evals.csv", "step,success,return,episodes\n5000,1.0,0.0,10\n", "line 2: step 5000 is not a step of the run"),
    ("episodes.csv", "step,return,length,success\n995,nan,10,1\n", "return is nan"),
    ("result.json", json.dumps({"kind": "student", "steps": 500}), "steps 500 is short of the budget in config.json"),
    ("result.json", json.dumps({"kind": "student", "steps": 1000, "task": "DungeonQuest"}),
     "task 'DungeonQuest' is not config.json's ('BlindCraftsman'): the result of another run"),
    ("config.json", json.dumps({"world": "Cont"}), "holds no run configuration"),
    ("config.json", None, "is missing beside its result.json"),
])
def test_a_damaged_record_is_named_by_its_file_and_never_pooled(runs, name, text, problem):
    damaged = fake_run(runs, "td3", 8, [(1000, 1.0)], [(995, 1.0)])
    if text is None:
        (damaged / name).unlink()
    else:
        (damaged / name).write_text(text)
    board = build(runs)
    assert {e.method: e.seeds for e in board} == {"td3": [0, 1], "td3-dynamic": [0, 1]}
    [reason] = board.unreadable
    assert reason.startswith(str(damaged / name)) and problem in reason
    assert not board.unfinished


def test_distilled_against_scratch_is_decided_only_where_the_seeds_say_so(tmp_path):
    from craftsuite.reporting.board import best_run, compare
    from craftsuite.reporting.pages import comparisons, comparisons_markdown

    def seeds(method, values, task):
        for seed, value in enumerate(values):
            fake_run(tmp_path, method, seed, [(1000, value)], [(950, float(seed))], task=task, world="Cont")

    seeds("td3", [0.9, 0.8, 1.0, 0.9, 0.85], "ToolHome")  # apart: the distilled student behind
    seeds("td3-dynamic", [0.1, 0.0, 0.2, 0.1, 0.05], "ToolHome")
    seeds("td3", [0.5, 0.52, 0.48, 0.5, 0.51], "FirstTool")  # close and tight: no difference of 0.2
    seeds("td3-dynamic", [0.49, 0.5, 0.53, 0.5, 0.5], "FirstTool")
    seeds("td3", [0.0, 1.0, 0.0, 1.0, 0.5], "TwoToolsHome")  # wide: undecided
    seeds("td3-dynamic", [1.0, 0.0, 0.5, 0.0, 1.0], "TwoToolsHome")
    seeds("td3", [0.0] * 20, "BlindCraftsman")  # nobody learned, on enough seeds: decided, but said so
    seeds("td3-dynamic", [0.0] * 20, "BlindCraftsman")
    seeds("td3", [0.0] * 5, "GoldMine")  # nobody learned on 5 seeds: a mean up to 0.52 would read so
    seeds("td3-dynamic", [0.0] * 5, "GoldMine")
    seeds("td3", [0.3, 0.35, 0.4], "Reach")  # apart, but 3 seeds a side: the probability alone does not decide
    seeds("td3-dynamic", [0.1, 0.2, 0.25], "Reach")
    seeds("td3", [0.0, 0.0], "DungeonQuest")  # two seeds: no interval
    seeds("td3-dynamic", [1.0, 1.0], "DungeonQuest")
    board = build(tmp_path)
    e = {(x.task, x.method): x for x in board}

    def said(task):
        return compare(e[task, "td3-dynamic"], e[task, "td3"])

    assert said("ToolHome").verdict == "behind" and said("ToolHome").difference.high < 0
    assert said("ToolHome").note == ""  # the probability and the difference, as the row shows them, agree
    assert compare(e["ToolHome", "td3"], e["ToolHome", "td3-dynamic"]).verdict == "ahead"
    assert said("FirstTool").verdict == "no difference of 0.2 or more" and not said("FirstTool").trivial
    assert said("TwoToolsHome").verdict == "undecided" and not said("TwoToolsHome").decided
    assert said("TwoToolsHome").seeds_to_decide > 5 and said("ToolHome").seeds_to_decide is None
    assert said("BlindCraftsman").said.endswith("(every seed of both at 0)") and said("BlindCraftsman").trivial
    # (at the level of its next reading, 97.5%: 20 seeds a side)
    assert said("GoldMine").verdict == "undecided" and said("GoldMine").seeds_to_decide == 20
    assert said("DungeonQuest").verdict == "too few seeds"
    assert said("Reach").improvement.low == 0.0 and said("Reach").verdict == "undecided"
    text = "\n".join(comparisons_markdown(comparisons([board])))
    assert ("Decided in final greedy success (ahead, behind, or no difference of 0.2 or more) on 3 of 7 comparisons, "
            "1 of them only") in text
    assert "| ToolHome | Cont | one-step | `td3-dynamic` − `td3` | 1,000 | -0.80 [" in text
    need = said("TwoToolsHome").seeds_to_decide
    assert (f"| undecided (at these means and spreads: about {need} seeds a side, where the smaller side has 5) |"
            in text)
    assert "By learner regime" not in text  # one regime: the sentence above says it all
    # the best run: the highest final success, then the hardest rung, then the return
    run, entry, i = best_run(board)
    assert (entry.task, entry.method, entry.values["success"][i]) == ("DungeonQuest", "td3-dynamic", 1.0)
    assert best_run(board, among=[r for x in board if x.task == "ToolHome" for r in x.runs])[0].name.startswith(
        "student-ToolHome-Cont-td3-s2")


def test_each_learner_regime_s_share_of_decided_comparisons_is_read_apart(tmp_path):
    from craftsuite.regimes import check_regime
    from craftsuite.reporting.pages import comparisons, comparisons_markdown

    wide = check_regime("n-step-wide").settings("td3")
    for seed in range(20):  # (every seed of both at 1 rules out a gap of 0.2 from 17 seeds a side)
        fake_run(tmp_path, "td3", seed, [(1000, 0.9)], [(950, 1.0)], task="ToolHome")  # one-step, both at 0.9
        fake_run(tmp_path, "td3-dynamic", seed, [(1000, 0.9 - 0.01 * seed)], [(950, 1.0)], task="ToolHome")
        fake_run(tmp_path, "td3", seed, [(1000, 1.0)], [(950, 1.0)], task="ToolHome", hyperparameters=wide)
        fake_run(tmp_path, "td3-dynamic", seed, [(1000, 1.0)], [(950, 1.0)], task="ToolHome", hyperparameters=wide)
    text = "\n".join(comparisons_markdown(comparisons([build(tmp_path)])))
    assert "| ToolHome | Cont | n-step-wide | `td3-dynamic` − `td3` | 1,000 | +0.00 [-0.17, +0.17] |" in text
    # both decided; the n-step-wide one only because every seed of both sat at 1
    assert "on 2 of 2 comparisons, 1 of them only" in text
    success, auc = [x for x in text.split("\n") if x.startswith("Decided")]
    assert success.endswith("By learner regime, decided and not only by all-0/all-1 seeds: `one-step` 1 of 1; "
                            "`n-step-wide` 0 of 1.")
    assert auc.startswith("Decided in AUC") and auc.endswith("`one-step` 1 of 1; `n-step-wide` 0 of 1.")


def test_a_comparison_at_two_budgets_is_a_row_of_the_table_s_width_and_is_not_counted(tmp_path):
    from craftsuite.reporting.pages import comparisons, comparisons_markdown

    for seed in range(5):
        fake_run(tmp_path, "td3", seed, [(1000, 1.0)], [(950, 1.0)], task="ToolHome")
        fake_run(tmp_path, "td3-dynamic", seed, [(2000, 1.0)], [(1950, 1.0)], task="ToolHome", budget=2000)
    lines = comparisons_markdown(comparisons([build(tmp_path)]))
    header, rule, row = lines[:3]
    assert "not compared: other budgets" in row and row.count("|") == header.count("|") == rule.count("|")
    assert "on 0 of 1 comparisons" in lines[4]


def test_a_comparison_trivial_in_final_success_can_be_decided_in_auc(tmp_path):
    # every seed of both ends at 1, but the distilled student gets there an evaluation sooner:
    # final success cannot tell them apart, AUC (the mean over the evaluations) can
    from craftsuite.reporting.board import compare
    from craftsuite.reporting.pages import comparisons, comparisons_markdown, leaderboard_markdown, summary_markdown

    for seed in range(20):  # (every seed of both at 1 rules out a gap of 0.2 from 17 seeds a side)
        late = 0.1 * seed / 19  # a little spread, so that the intervals have width
        fake_run(tmp_path, "td3", seed, [(250, 0.0), (500, late), (750, 1.0), (1000, 1.0)], [(950, 1.0)],
                 task="ToolHome")
        fake_run(tmp_path, "td3-dynamic", seed, [(250, late), (500, 1.0), (750, 1.0), (1000, 1.0)], [(950, 1.0)],
                 task="ToolHome")
    e = {x.method: x for x in build(tmp_path)}
    in_success, in_auc = compare(e["td3-dynamic"], e["td3"]), compare(e["td3-dynamic"], e["td3"], "auc")
    assert in_success.trivial and in_success.said.endswith("(every seed of both at 1)")
    assert in_auc.verdict == "ahead" and not in_auc.trivial and in_auc.difference.low > 0.2
    pairs = comparisons([build(tmp_path)])
    [row] = [x for x in comparisons_markdown(pairs) if x.startswith("| ToolHome")]
    assert row.endswith(f"| no difference of 0.2 or more (every seed of both at 1) | {in_auc.difference.value:+.2f} "
                        f"[{in_auc.difference.low:+.2f}, {in_auc.difference.high:+.2f}] | 1.00 [1.00, 1.00] | ahead |")
    success_line, auc_line = [x for x in summary_markdown(pairs, [], {}) if x.startswith("- Distilled")]
    assert "ahead on 0" in success_line and "(1 of them only" in success_line
    assert auc_line.startswith("- Distilled against scratch, AUC") and "ahead on 1" in auc_line
    with pytest.raises(ValueError, match="compare in one of"):
        compare(e["td3-dynamic"], e["td3"], "return")
    for seed in range(20):  # nobody ever succeeds: trivial in both, and AUC's wording says it held throughout
        fake_run(tmp_path, "td3", seed, [(500, 0.0), (1000, 0.0)], [(950, 0.0)], task="Reach")
        fake_run(tmp_path, "td3-dynamic", seed, [(500, 0.0), (1000, 0.0)], [(950, 0.0)], task="Reach")
    e = {(x.task, x.method): x for x in build(tmp_path)}
    never = compare(e["Reach", "td3-dynamic"], e["Reach", "td3"], "auc")
    assert never.trivial
    assert never.said == "no difference of 0.2 or more (every seed of both at 0 at every evaluation)"
    # the rung's own section says both readings (a leaderboard of one directory has no table of them)
    board_text = leaderboard_markdown(build(tmp_path)).split("\n")
    reach, toolhome = [x for x in board_text if x.startswith("Against scratch, AUC")]  # easiest rung first
    assert toolhome.endswith(": **ahead**.") and "`td3-dynamic` +" in toolhome
    assert reach.endswith(": **no difference of 0.2 or more** (every seed of both at 0 at every evaluation).")
    # read twice, a trivial row says what it rests on and how often it was read in one parenthesis
    from craftsuite.reporting.pages import _cells

    twice = compare(e["Reach", "td3-dynamic"], e["Reach", "td3"], looks=2)
    assert _cells(twice, e["Reach", "td3-dynamic"], e["Reach", "td3"]).endswith(
        "| no difference of 0.2 or more (every seed of both at 0; read 2 times: every interval at 97.5%)")


def test_the_probability_of_improvement_alone_does_not_decide(tmp_path):
    # every seed of scratch at 1, two of the distilled student's at 0: the probability's interval
    # lies below one half, but Welch's interval of the difference includes 0
    from craftsuite.reporting.board import compare

    distilled = (1.0, 1.0, 1.0, 0.75, 1.0, 1.0, 0.0, 1.0, 1.0, 0.0)
    for seed in range(10):
        fake_run(tmp_path, "dqn", seed, [(1000, 1.0)], [(950, 1.0)], task="ToolHome", world="Grid10")
        fake_run(tmp_path, "dynamic", seed, [(1000, distilled[seed])], [(950, 1.0)], task="ToolHome", world="Grid10")
    e = {x.method: x for x in build(tmp_path)}
    said = compare(e["dynamic"], e["dqn"])
    assert said.improvement.high < 0.5 and said.difference.low < 0 < said.difference.high
    assert said.verdict == "undecided" and said.seeds_to_decide > 10


def test_a_decided_gap_smaller_than_the_smallest_difference_is_named_as_small(tmp_path):
    from craftsuite.reporting.board import compare
    from craftsuite.reporting.pages import _sided, comparisons, decided_by_regime, summary_markdown

    for seed in range(5):  # scratch near 1; the distilled student a little short
        fake_run(tmp_path, "td3", seed, [(1000, (1.0, 0.99, 1.0, 0.98, 1.0)[seed])], [(950, 1.0)], task="ToolHome",
                 world="Cont")
        fake_run(tmp_path, "td3-dynamic", seed, [(1000, (0.9, 0.88, 0.85, 0.92, 0.9)[seed])], [(950, 1.0)],
                 task="ToolHome", world="Cont")
        fake_run(tmp_path, "td3-static", seed, [(1000, (0.9, 0.88, 0.85, 0.92, 0.9)[seed])], [(950, 1.0)],
                 task="ToolHome", world="Cont")
        fake_run(tmp_path, "td3", seed, [(1000, 0.1)], [(950, 1.0)], task="FirstTool", world="Cont")  # a wide gap
        fake_run(tmp_path, "td3-dynamic", seed, [(1000, 0.9)], [(950, 1.0)], task="FirstTool", world="Cont")
    board = build(tmp_path)
    e = {(x.task, x.method): x for x in board}
    close = compare(e["ToolHome", "td3-dynamic"], e["ToolHome", "td3"])
    assert close.verdict == "behind, by less than 0.2"
    assert -0.2 < close.difference.low and close.difference.high < 0.2 and close.improvement.high < 0.5
    wide = compare(e["FirstTool", "td3-dynamic"], e["FirstTool", "td3"])
    assert wide.verdict == "ahead" and not wide.small and close.small  # 0.8: no qualifier
    pairs = comparisons([board])
    [tally] = decided_by_regime(pairs).values()
    assert (tally["ahead"], tally["behind"], tally["no difference"]) == (1, 2, 0)
    assert (tally["ahead by less"], tally["behind by less"]) == (0, 2)
    # the summary's counts say which sided verdicts are small gaps, so that "behind on N" is not read as N large
    # ones: in all, and per distilled method
    short = "\n".join(summary_markdown(pairs, [], {}))
    assert "ahead on 1, behind on 2 (all of them a real gap under 0.2), no difference" in short
    assert "`td3-dynamic` (2 comparisons): ahead 1, behind 1 (a real gap under 0.2)," in short
    assert "`td3-static` (1 comparison): ahead 0, behind 1 (a real gap under 0.2)," in short
    assert _sided({"behind": 8, "behind by less": 5}, "behind") == "8 (5 of them a real gap under 0.2)"


def test_a_verdict_its_row_cannot_show_says_what_decided_it(tmp_path):
    from craftsuite.reporting.board import compare

    # 3 seeds a side: the probability does not count, so only the two t-intervals, apart, decide
    for seed in range(3):
        fake_run(tmp_path, "td3", seed, [(1000, 0.9 + seed / 100)], [(950, 1.0)], task="Reach", world="Cont")
        fake_run(tmp_path, "td3-dynamic", seed, [(1000, 0.1 + seed / 100)], [(950, 1.0)], task="Reach", world="Cont")
    e = {x.method: x for x in build(tmp_path)}
    behind = compare(e["td3-dynamic"], e["td3"])
    assert behind.said == "behind (the two means' intervals apart)" and behind.improvement.high == 0.0
    for seed in range(3, 5):  # at 5 a side the probability and the difference, as the row shows them, agree
        fake_run(tmp_path, "td3", seed, [(1000, 0.9 + seed / 100)], [(950, 1.0)], task="Reach", world="Cont")
        fake_run(tmp_path, "td3-dynamic", seed, [(1000, 0.1 + seed / 100)], [(950, 1.0)], task="Reach", world="Cont")
    e = {x.method: x for x in build(tmp_path)}
    assert compare(e["td3-dynamic"], e["td3"]).said == "behind"


def test_the_summary_says_how_many_seeds_the_undecided_comparisons_would_need(tmp_path):
    from craftsuite.reporting.pages import comparisons, summary_markdown

    for seed, (scratch, distilled) in enumerate(zip([0.0, 1.0, 0.0, 1.0, 0.0, 0.0], [1.0, 0.0, 1.0, 1.0, 0.0, 1.0])):
        fake_run(tmp_path, "td3", seed, [(1000, scratch)], [(950, 1.0)], task="ToolHome", world="Cont")
        fake_run(tmp_path, "td3-dynamic", seed, [(1000, distilled)], [(950, 1.0)], task="ToolHome", world="Cont")
    [pair] = pairs = comparisons([build(tmp_path)])
    need = pair[2].seeds_to_decide
    assert pair[2].verdict == "undecided" and need > 6
    terms, line, in_auc = [x for x in summary_markdown(pairs, [], {}) if x.startswith("- ")]
    assert terms.startswith("- Read as: a *learner regime*") and "`one-step`, one-step TD targets" in terms
    assert in_auc.startswith("- Distilled against scratch, AUC")  # one evaluation a run: AUC reads as success
    assert line.endswith(f"undecided on 1 (the interval rules would need about {need} seeds a side at the means and "
                         "spreads measured).")


def test_a_method_that_ran_more_tasks_than_the_others_is_compared_with_the_baseline_on_all_of_them(tmp_path):
    root = tmp_path / "students"
    two_tasks(root, 0.0, 1.0)
    for seed in range(3):
        fake_run(root, "td3-static", seed, [(1000, 0.0)], [(995, 0.0)], task="Reach")  # one task only
    [agg] = aggregates(list(build(root)))
    assert agg.tasks == ["Reach"]  # the tasks every method ran
    pair = agg.against_baseline["td3-dynamic"]
    assert pair.tasks == ["Reach", "BlindCraftsman"] and pair.runs == (6, 6)
    assert pair.improvement["success"].value == 1.0  # beats every td3 run on both tasks
    assert agg.against_baseline["td3-static"].tasks == ["Reach"]
    md = "\n".join(aggregates_markdown([agg]))
    assert "| td3-dynamic | 2 (Reach, BlindCraftsman) | 6 / 6 | 1.00" in md


def test_no_second_table_where_every_method_ran_every_task(tmp_path):
    root = tmp_path / "students"
    for seed in range(3):
        fake_run(root, "td3", seed, [(1000, 0.0)], [(995, 0.0)])
        fake_run(root, "td3-dynamic", seed, [(1000, 1.0)], [(995, 0.0)])
    [agg] = aggregates(list(build(root)))
    assert "on every task both ran" not in "\n".join(aggregates_markdown([agg]))


def test_the_summary_gives_each_distilled_method_against_scratch_across_the_tasks_both_ran(tmp_path):
    from craftsuite.reporting.pages import summary_markdown

    root = tmp_path / "students"
    two_tasks(root, 0.0, 1.0)
    for seed in range(3):
        fake_run(root, "product-td3", seed, [(1000, 1.0)], [(995, 0.0)], task="Reach")  # not distilled: not named
    lines = summary_markdown([], [], {}, aggregates(list(build(root))))
    assert lines[2].startswith("- Distilled against scratch across the ladder")
    assert lines[3] == "  - Cont, one-step regime: `td3-dynamic` 1.00 [1.00, 1.00], in AUC 1.00 [1.00, 1.00] (2 tasks)"
    assert "product-td3" not in "\n".join(lines)


def test_a_baseline_in_two_directories_drops_its_task_and_names_no_other_method(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    two_tasks(a, 0.0, 1.0)
    for seed in range(3):  # the baseline's Reach again, at another budget, in a second directory
        fake_run(b, "td3", seed, [(2000, 0.0)], [(1995, 0.0)], task="Reach", budget=2_000)
    [agg] = aggregates([*build(a), *build(b)])
    assert agg.baseline == "td3" and agg.tasks == ["BlindCraftsman"] and set(agg.improvement) == {"td3-dynamic"}
    assert agg.left_out == ["task Reach: the baseline td3 there has runs in more than one directory"]


def test_a_board_of_many_runs_says_how_far_its_reading_is(tmp_path, monkeypatch, capsys):
    from craftsuite.reporting import board as board_module

    for seed in range(3):
        fake_run(tmp_path, "td3", seed, [(1000, 0.5)], [(950, 1.0)])
    build(tmp_path)
    assert "reading" not in capsys.readouterr().err  # a few runs: read at once, nothing said
    monkeypatch.setattr(board_module, "PROGRESS_FROM", 3)
    build(tmp_path)
    err = capsys.readouterr().err
    assert f"reading {tmp_path}" in err and "3/3" in err
