"""The reproduction report on synthetic runs with known answers: each Figure 5 panel says
what ran and what did not, and its verdict follows the runs' intervals."""

import json

import pytest

from craftsuite.cli import main
from craftsuite.reporting.pages import PAPER_REFERENCE
from craftsuite.reproduction import FIGURE_5, write_report

from .reporting.fakes import fake_run


def _seeds(root, method, success, world="Kinematic", task="BlindCraftsman", seeds=5, ret=0.0, **config):
    for seed in range(seeds):
        value = success + 0.01 * seed if success else 0.0
        fake_run(root, method, seed, [(500, value), (1000, value)], [(950, ret + seed)], task=task, world=world,
                 **config)


@pytest.fixture
def transfer_dir(tmp_path):
    out = tmp_path / "paper"
    students = out / "students"
    _seeds(students, "td3-dynamic", 0.8, ret=50.0)  # (e), kinematic: ahead of scratch
    _seeds(students, "td3", 0.1)
    _seeds(students, "td3-dynamic", 0.8, world_kwargs={"size": 10})  # (e), on the authors' 10x10 board
    _seeds(students, "td3-dynamic", 0.0, world="Cont", seeds=2)  # (e), MuJoCo: two seeds, nothing learned
    _seeds(students, "td3", 0.0, world="Cont", seeds=2)
    _seeds(students, "dynamic", 0.1, world="Grid10", task="DungeonQuest")  # (a): behind product DQN; static missing
    for baseline in ("crm", "product-dqn", "dqn"):
        _seeds(students, baseline, 0.6 if baseline == "product-dqn" else 0.1, world="Grid10", task="DungeonQuest")
    (out / "suite.json").write_text(json.dumps({"name": "paper", "teacher_layout_seed": None, "grid_layout_seed": None,
                                                "teacher_n_envs": 10, "dqn_n_envs": 10, "td3_n_envs": 10,
                                                "students_see_automaton": False}))
    teacher = out / "teachers" / "teacher-DungeonQuest-Grid7-s0-abc"
    teacher.mkdir(parents=True)
    (teacher / "result.json").write_text(json.dumps({"kind": "teacher", "steps": 100_000, "updates": 9_900,
                                                     "success": 0.3, "reached_target": False}))
    return out


def test_the_report_names_every_panel_what_ran_and_what_did_not(transfer_dir, tmp_path):
    page = write_report(transfer_dir, tmp_path / "docs" / "reproduction.md")
    text = page.read_text()
    rows = [line for line in text.splitlines() if line.startswith("| ") and line[2] in "abcdefg" and line[3] == " "]
    # one row per panel and world: four grid panels, three continuous ones in two worlds, and
    # Blind Craftsman's on the authors' 10x10 board too
    assert len(rows) == 4 + 3 * 2 + 1 == sum(len(p.worlds) for p in FIGURE_5)
    by_panel = {(r.split("|")[1].strip(), r.split("|")[3].strip()): r for r in rows}
    assert "td3: AUC ahead, return ahead" in by_panel["e", "Kinematic"] and "| 5 |" in by_panel["e", "Kinematic"]
    assert "fewer than 5 seeds: not a claim" in by_panel["e", "Cont"]
    assert "product-dqn: AUC behind" in by_panel["a", "Grid10"]
    assert "did not run" in by_panel["b", "Grid10"] and "did not run" in by_panel["f", "Kinematic"]
    assert "Did not run: static." in text  # a panel with a method missing says which
    # the authors' published returns stay as reference rows in the continuous panels
    assert "*reference: authors' td3-dynamic, 1 run, 2M steps" in text
    # the protocol and the teachers as run, and the paper's budget beside ours
    assert "teachers' layout new every episode" in text and "see the automaton state: no" in text
    assert "did not reach its target" in text and "20M transitions" in text
    assert "1,000 transitions" in text
    images = tmp_path / "docs" / "images" / "reproduction"
    assert (images / "curves-BlindCraftsman-Kinematic.png").exists()
    # every panel's curves are linked, a world with settings too
    for name in ("curves-BlindCraftsman-Kinematic.png", "curves-BlindCraftsman-Kinematic-size-10.png"):
        assert (images / name).exists() and f"](images/reproduction/{name})" in text
    # the kinematic panels' returns beside the authors' published curves; none in MuJoCo
    assert (images / "returns-BlindCraftsman-Kinematic.png").exists() and "returns beside the authors'" in text
    assert not (images / "returns-BlindCraftsman-Cont.png").exists()


def test_the_authors_curves_are_their_six_runs_on_their_axis():
    from craftsuite.reproduction import authors_curves

    curves = authors_curves()
    assert set(curves) == {(t, m) for t in ("BlindCraftsman", "DungeonQuest", "GoldMine")
                           for m in ("td3", "td3-dynamic")}
    for _key, curve in curves.items():
        steps = [s for s, _ in curve]
        assert steps == sorted(steps) and 19_000_000 < steps[-1] <= 20_000_000  # 2M steps of 10 envs
    # their reference rows (the last 5% of each run) agree with the binned curves' end
    last = {m: curves["GoldMine", m][-5:] for m in ("td3", "td3-dynamic")}
    assert (sum(r for _, r in last["td3-dynamic"]) / 5
            == pytest.approx(PAPER_REFERENCE["GoldMine"]["td3-dynamic"], abs=2.5))


def test_bad_input_is_named(tmp_path, capsys):
    with pytest.raises(FileNotFoundError, match="no students/"):
        write_report(tmp_path, tmp_path / "r.md")
    (tmp_path / "students").mkdir()
    with pytest.raises(ValueError, match="no finished student runs"):
        write_report(tmp_path, tmp_path / "r.md")
    assert not (tmp_path / "r.md").exists()
    assert main(["leaderboard", str(tmp_path), str(tmp_path), "--reproduction", str(tmp_path / "r.md")]) == 2
    assert "one transfer directory" in capsys.readouterr().err
    # another suite's runs (the quick suite's Reach): a page of panels that all say "did not run"
    _seeds(tmp_path / "students", "td3", 0.5, world="Cont", task="Reach")
    assert main(["leaderboard", str(tmp_path), "--reproduction", str(tmp_path / "r.md")]) == 2
    err = capsys.readouterr().err
    assert f"{tmp_path} holds no run of a task and world of Figure 5's panels (BlindCraftsman in Cont," in err
    assert err.endswith("--reproduction reads a transfer of the paper suite (craftsuite transfer --suite paper)\n")
    assert not (tmp_path / "r.md").exists() and not (tmp_path / "images").exists()
