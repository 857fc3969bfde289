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
    (root / "student-unfinished").mkdir()  # no result.json: ignored
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


def test_entries_average_seeds_with_bootstrap_intervals(runs):
    entries = {e.method: e for e in leaderboard.build(runs)}
    assert set(entries) == {"td3-dynamic", "td3"}
    dyn, td3 = entries["td3-dynamic"], entries["td3"]
    assert dyn.seeds == 2 and dyn.censored == 0
    mean, lo, hi = dyn.stats["success"]
    assert mean == pytest.approx(0.8) and lo == pytest.approx(0.6) and hi == pytest.approx(1.0)
    assert dyn.stats["return"][0] == pytest.approx(15.0)
    assert dyn.stats["train_success"][0] == pytest.approx((0.75 + 0.0) / 2)
    assert dyn.stats["steps_to_80"] == (500.0, 500.0, 500.0)  # both seeds agree: a point interval
    assert td3.censored == 1
    assert td3.stats["steps_to_80"][0] == 1000.0  # the censored seed counts at its budget


def test_bootstrap_interval_covers_the_mean_and_narrows_with_seeds():
    rng = np.random.default_rng(1)
    few, many = rng.normal(size=4), rng.normal(size=400)
    m, lo, hi = leaderboard.bootstrap_ci(few)
    assert lo <= m <= hi and hi > lo
    m2, lo2, hi2 = leaderboard.bootstrap_ci(many)
    assert hi2 - lo2 < hi - lo
    assert abs(m2) < 0.2 and lo2 < 0 < hi2


def test_markdown_csv_and_plot(runs, tmp_path):
    entries = leaderboard.build(runs)
    md = leaderboard.write(entries, tmp_path).read_text()
    assert "## BlindCraftsman (Cont)" in md
    assert md.index("| td3-dynamic |") < md.index("| td3 |")  # ranked by AUC
    assert ">= 1,000" in md and "(1/2 reached)" in md
    assert "reference: authors' td3-dynamic" in md and "19.95" in md
    with open(tmp_path / "leaderboard.csv") as f:
        rows = {r["method"]: r for r in csv.DictReader(f)}
    assert float(rows["td3-dynamic"]["success"]) == pytest.approx(0.8)
    assert float(rows["td3-dynamic"]["train_success"]) == pytest.approx(0.375)
    assert "| training success (last 10%) |" in md and "| 0.38 [0.00, 0.75] |" in md
    assert rows["td3"]["steps_to_80_censored"] == "1"
    [png] = leaderboard.plot_curves(runs, tmp_path)
    assert png.name == "curves-BlindCraftsman-Cont.png" and png.read_bytes()[:4] == b"\x89PNG"


def test_runs_in_another_world_setting_get_their_own_row_and_plot(runs, tmp_path):
    fake_run(runs, "td3", 0, [(1000, 1.0)], [(995, 50.0)], world_kwargs={"frame_skip": 10, "max_episode_steps": 200})
    fake_run(runs, "dqn", 0, [(1000, 0.5)], [(995, 5.0)], world="Grid10", layout_seed=1)
    entries = {(e.world, e.method): e for e in leaderboard.build(runs)}
    assert entries[("Cont", "td3")].seeds == 2  # the registered world's runs are not mixed with the others
    other = entries[("Cont: frame_skip=10, max_episode_steps=200", "td3")]
    assert other.seeds == 1 and other.stats["success"][0] == 1.0
    assert entries[("Grid10: layout_seed=1", "dqn")].stats["return"][0] == 5.0
    md = leaderboard.to_markdown(list(entries.values()))
    sections = {part.split(")")[0]: part for part in md.split("## BlindCraftsman (")[1:]}
    assert "reference" in sections["Cont: frame_skip=10, max_episode_steps=200"]  # theirs was a 2-D toy
    assert "reference" not in sections["Grid10: layout_seed=1"]  # their numbers are continuous ones
    names = {p.name for p in leaderboard.plot_curves(runs, tmp_path)}
    assert names == {"curves-BlindCraftsman-Cont.png", "curves-BlindCraftsman-Grid10-layout_seed-1.png",
                     "curves-BlindCraftsman-Cont-frame_skip-10-max_episode_steps-200.png"}
    # settings that read alike in a file name do not overwrite each other's plot
    fake_run(runs, "td3", 0, [(1000, 0.0)], [(995, 0.0)], world_kwargs={"x": -1})
    fake_run(runs, "td3", 0, [(1000, 0.0)], [(995, 0.0)], world_kwargs={"x": 1})
    assert len({p.name for p in leaderboard.plot_curves(runs, tmp_path)}) == 5


def test_runs_pooled_in_one_row_that_differ_beyond_the_seed_are_flagged(runs, tmp_path):
    fake_run(runs, "td3", 2, [(2000, 0.0)], [(1995, 0.0)], budget=2_000)  # another budget, same world
    entries = {e.method: e for e in leaderboard.build(runs)}
    assert entries["td3"].differs == ("steps",) and entries["td3-dynamic"].differs == ()
    md = leaderboard.to_markdown(list(entries.values()))
    assert "*td3: its 3 runs differ in steps, not only in the seed" in md and "td3-dynamic: its" not in md
    with open(leaderboard.write(list(entries.values()), tmp_path).with_suffix(".csv")) as f:
        assert {r["method"]: r["pooled_runs_differ_in"] for r in csv.DictReader(f)} == {"td3": "steps", "td3-dynamic": ""}


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
