"""Leaderboards and results pages rendered from synthetic run directories."""

import csv
import json
import shutil

import pytest

from craftsuite.reporting.board import Board, build
from craftsuite.reporting.pages import leaderboard_markdown, write_leaderboard, write_results_page
from .fakes import fake_run


def test_a_single_seed_reads_as_its_value_and_never_as_an_interval(tmp_path):
    root = tmp_path / "students"
    fake_run(root, "td3", 0, [(500, 0.3), (1000, 0.5)], [(995, 22.2)])
    board = build(root)
    md = leaderboard_markdown(board)
    assert "| td3 | 1 | 0.50 | 0.50 | 0.40 | 22.2 |" in md and "[22.2, 22.2]" not in md
    assert "| 0 of 1 |" in md


def test_a_row_lists_its_seeds_up_to_twenty_and_counts_them_beyond(tmp_path):
    def md(seeds):
        root = tmp_path / f"students-{seeds}"
        for seed in range(seeds):  # per seed: 0, 1, 1, 0.5, 0, 1, 1, 0.5, ...
            fake_run(root, "td3", seed, [(1000, (0.0, 1.0, 1.0, 0.5)[seed % 4])], [(995, 1.0)])
        return leaderboard_markdown(build(root))

    listed, counted = md(20), md(21)
    assert "] | 0.00 1.00 1.00 0.50 0.00 1.00 1.00 0.50 " in listed and " between |" not in listed
    assert "| td3 | 21 | 0.60 [" in counted and "] | 6 at 0.00, 10 at 1.00, 5 between | " in counted
    from craftsuite.reporting.pages import per_seed_text

    assert per_seed_text([0.0] * 20 + [float("nan")]) == "20 at 0.00, 0 at 1.00, 0 between, 1 not measured"


def test_markdown_csv_and_profile(runs, tmp_path):
    board = build(runs)
    md = write_leaderboard(board, tmp_path).read_text()
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
    assert (tmp_path / "profile-Cont-one-step.png").exists() and "](profile-Cont-one-step.png)" in md


def test_budget_reads_in_transitions_and_gradient_updates_and_methods_are_explained(runs):
    for seed, updates in ((5, 240), (6, 260)):
        run = fake_run(runs, "td3-dynamic-edges", seed, [(1000, 0.5)], [(995, 1.0)])
        (run / "result.json").write_text(json.dumps({"kind": "student", "steps": 1000, "updates": updates}))
    entries = {e.method: e for e in build(runs)}
    assert entries["td3-dynamic-edges"].budget_text == "1,000 / 250"
    assert entries["td3"].budget_text == "1,000 / ?"  # runs from before updates were recorded
    md = leaderboard_markdown(Board(list(entries.values())))
    assert "| 1,000 / 250 |" in md
    assert "- `td3-dynamic-edges`: td3-dynamic with the teacher's values on the automaton's edges only" in md
    assert md.index("- `td3`:") < md.index("- `td3-dynamic`:")  # the legend follows the methods table


def test_results_page_names_the_missing_and_the_empty(tmp_path):
    with pytest.raises(FileNotFoundError, match="no run directory"):
        write_results_page([tmp_path / "nope"], tmp_path / "results.md")
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="no finished student runs"):
        write_results_page([tmp_path / "empty"], tmp_path / "results.md")
    assert not (tmp_path / "results.md").exists()


def test_a_directory_of_unfinished_runs_only_is_named_as_such(tmp_path):
    run = tmp_path / "students" / "student-Reach-Cont-td3-s0"
    run.mkdir(parents=True)
    (run / "config.json").write_text(json.dumps({"task": "Reach", "world": "Cont", "method": "td3", "seed": 0,
                                                 "steps": 1000}))
    with pytest.raises(ValueError, match=r"no finished student runs under .*students \(1 unfinished\)"):
        write_results_page([tmp_path], tmp_path / "results.md")
    assert not (tmp_path / "results.md").exists() and (run / "config.json").exists()


def test_a_world_with_nothing_to_aggregate_says_why(tmp_path):
    root = tmp_path / "students"
    fake_run(root, "td3", 0, [(1000, 1.0)], [(995, 1.0)])
    fake_run(root, "td3-dynamic", 0, [(1000, 1.0)], [(995, 1.0)])
    md = leaderboard_markdown(build(root))
    assert "### Cont, one-step regime\n\nNothing to aggregate: td3, td3-dynamic: fewer than 2 runs on some task" in md


def test_a_page_of_archived_runs_says_it_has_no_video_and_its_size(tmp_path):
    from craftsuite.archive import keep

    for seed in range(3):
        run = fake_run(tmp_path / "out", "td3", seed, [(1000, 0.5 + 0.1 * seed)], [(950, 1.0)])
        keep(run, tmp_path / "results" / "standard", "students")
    text = write_results_page([tmp_path / "results" / "standard"], tmp_path / "docs" / "results.md").read_text()
    assert "No video: the best student here, `student-BlindCraftsman-Cont-td3-s2` (greedy success 0.70)" in text
    assert "The records in `" in text and " MB." in text
    # a directory that kept its video names it instead
    (tmp_path / "results" / "standard" / "best-x.mp4").write_bytes(b"mp4")
    text = write_results_page([tmp_path / "results" / "standard"], tmp_path / "docs" / "results.md").read_text()
    assert "No video" not in text and "Video of the best student: [best-x.mp4]" in text


def test_the_tasks_page_reads_scratch_success_from_the_archive(tmp_path):
    from craftsuite.references import scratch_success

    for seed in range(3):
        fake_run(tmp_path / "results" / "standard" / "students", "td3", seed, [(800_000, 0.2 * seed)], [(1, 0.0)],
                 task="ToolHome", budget=800_000)
        fake_run(tmp_path / "results" / "standard" / "students", "td3-dynamic", seed, [(800_000, 1.0)], [(1, 0.0)],
                 task="ToolHome", budget=800_000)
    # 0.74: the t-interval's 0.70 widened by the score interval, the page's interval of a rate
    assert scratch_success(tmp_path / "results") == {
        "ToolHome": ["0.20 [0.00, 0.74] at 0.8M (3 seeds, standard, one-step)"]}
    # the same rung in another learner regime is another figure, named by its regime
    from craftsuite.regimes import check_regime

    for seed in range(2):
        fake_run(tmp_path / "results" / "standard" / "students", "td3", seed, [(250_000, 1.0)], [(1, 0.0)],
                 task="ToolHome", budget=250_000, hyperparameters=check_regime("n-step-wide").settings("td3"))
    assert sorted(scratch_success(tmp_path / "results")["ToolHome"]) == [
        "0.20 [0.00, 0.74] at 0.8M (3 seeds, standard, one-step)",
        "1.00 at 0.25M (2 seeds, standard, n-step-wide)"]
    assert scratch_success(tmp_path / "nowhere") == {} and scratch_success(None) == {}


def test_a_results_page_lists_its_teachers_and_names_a_damaged_one(tmp_path):
    from craftsuite.reporting.pages import teachers_markdown

    good = tmp_path / "teachers" / "teacher-GoldMine-Grid7-s0-abc"
    good.mkdir(parents=True)
    (good / "config.json").write_text(json.dumps({"task": "GoldMine", "layout_seed": 0, "target_success": 0.9}))
    (good / "result.json").write_text(json.dumps({"kind": "teacher", "env_id": "CraftSuite/GoldMine-Grid7-v0",
                                                 "steps": 55000, "updates": 53999, "success": 1.0,
                                                 "reached_target": True}))
    torn = tmp_path / "teachers" / "teacher-Reach-Grid7-s0-def"
    torn.mkdir()
    (torn / "config.json").write_text("{torn")
    stray = tmp_path / "teachers" / "teacher-GoldMine-Grid7-s1-fed"  # a config without its target
    stray.mkdir()
    (stray / "config.json").write_text(json.dumps({"task": "GoldMine", "layout_seed": 1}))
    (stray / "result.json").write_text((good / "result.json").read_text())
    text = "\n".join(teachers_markdown(tmp_path / "teachers"))
    assert "| GoldMine | `CraftSuite/GoldMine-Grid7-v0` | fixed (0) | 55,000 / 53,999 | 1.00 | yes (90%) |" in text
    # CraftSuite's own errors say what went wrong in their sentence, without their class's name;
    # Python's keep it (a KeyError's message is the key alone)
    assert f"- not read: {torn} ({torn / 'config.json'} is not valid JSON" in text
    assert f"- not read: {stray} (KeyError: 'target_success')" in text
    assert teachers_markdown(tmp_path / "nowhere") == []


def test_a_task_no_method_learned_says_where_its_episodes_stopped(tmp_path):
    from craftsuite.reporting.board import build
    from craftsuite.reporting.pages import obstacles_markdown
    from craftsuite.runs import EPISODE_FIELDS, write_csv
    from craftsuite.task_registry import resolve_task

    automaton = resolve_task("BlindCraftsman").automaton
    wood = 1 << automaton.propositions.index("wood")
    start = 1 << automaton.initial
    root = tmp_path / "students"
    for seed in range(3):
        for method in ("td3", "td3-dynamic"):
            run = fake_run(root, method, seed, [(1000, 0.0)], [], budget=1000)
            # every episode saw wood; td3-dynamic's half of them also the automaton's next state
            moved = start | (1 << automaton.step(automaton.initial, wood))
            write_csv(run / "episodes.csv", EPISODE_FIELDS,
                      [{"step": 500 * (i + 1), "return": 0.0, "length": 10, "success": 0, "seen": wood,
                        "states": moved if method == "td3-dynamic" and i == 0 else start} for i in range(2)])
    rows = list(build(root))
    text = "\n".join(obstacles_markdown(rows))
    assert "| method | seeds | completed per 100k | furthest automaton state | propositions reached |" in text
    assert "| td3 | 3 | 0.0 (0 of 6 episodes) | state 0 (the initial)," in text
    assert "wood 100%" in text and "home 0%" in text
    assert "| td3-dynamic | 3 | 0.0 (0 of 6 episodes) | state 1 (after wood), 1 edge from acceptance" in text
    assert "(50% of episodes)" in text  # td3-dynamic: one episode of two moved on
    from craftsuite.reporting.pages import _share

    assert (_share(0.0), _share(2 / 47_000), _share(0.5)) == ("0%", "<1%", "50%")  # a few is not none
    # a task some method learned needs no such table
    learned = fake_run(tmp_path / "other", "td3", 0, [(1000, 1.0)], [(995, 1.0, 1)])
    assert obstacles_markdown(list(build(learned.parent))) == []


def test_the_wall_time_is_summed_per_kind_of_machine():
    from craftsuite.reporting.timing import wall_time_lines

    sessions = [{"command": "craftsuite transfer --suite standard", "seconds": 3600.0, "machine": "Linux, 2 cores"},
                {"command": "craftsuite transfer --suite standard", "seconds": 1800.0, "machine": "Linux, 2 cores"},
                {"command": "craftsuite transfer --suite standard", "seconds": 360.0, "machine": "Linux, 16 cores"},
                {"command": "craftsuite transfer --suite standard", "seconds": None, "machine": "Linux, 2 cores"},
                {"command": "craftsuite archive out --suite standard", "seconds": 0.0, "machine": "Linux, 2 cores"},
                {"command": "craftsuite transfer --suite standard", "seconds": 720.0,
                 "machine": "Linux x86_64, AMD EPYC (family 23 model 1, AVX2), 2 cores, 23.5 GiB, Python 3.11.7"}]
    # machines of one core count apart where their records name the CPU, together where not
    assert wall_time_lines(sessions) == ["- Wall time of the sessions that trained these runs: 0.1 h on 16 cores, "
                                         "1.5 h on 2 cores, 0.2 h on 2 cores of AMD EPYC (family 23 model 1, "
                                         "AVX2); 1 session not finished, not counted"]
    assert wall_time_lines(sessions[4:5]) == []


def test_the_runs_training_time_counts_each_population_once_per_machine_and_regime(tmp_path):
    from craftsuite.reporting.timing import training_time_lines

    def timed(method, seed, **result):
        run = fake_run(tmp_path, method, seed, [(1000, 0.5)], [(995, 1.0)])
        record = json.loads((run / "result.json").read_text())
        (run / "result.json").write_text(json.dumps({**record, **result}))

    for seed in range(4):  # a population of 4 that ran 2 h in all, across a stop: half an hour each
        timed("td3", seed, seconds_share=1800.0, seconds_this_session=600.0, members=4, device="cpu",
              machine="Linux x86_64, 2 cores, 23.5 GiB, Python 3.11.7")
    timed("td3-dynamic", 0, seconds_share=1800.0, members=1, device="cuda", machine="Linux x86_64, 16 cores")
    timed("td3-dynamic", 1, seconds_this_session=1800.0, members=2)  # an older record: its last session's only
    [line] = training_time_lines(build(tmp_path))
    assert line.endswith("`one-step` 2.0 h (2 cores, cpu), 0.5 h (16 cores, cuda), 0.2 h (machine not recorded, "
                         "device not recorded) (1 of the runs were stopped and resumed before records kept the time "
                         "across a stop: their last session's time only)")
    assert line.startswith("- Training time recorded by the 6 runs")


def _rebudgeted(root):
    """A standard suite directory whose KeySwordDragon Grid10 cells ran at today's budget
    (scratch 0.3, distilled 0.9) and at twice it (both 0.9); returns today's budget."""
    from craftsuite.regimes import check_regime
    from craftsuite.suites import SUITES

    suite = SUITES["standard"]
    spec = next(s for s in suite.rungs() if s.name == "KeySwordDragon")
    now = suite.budget(spec, "Grid10")
    wide = check_regime(suite.regime).settings("dqn")
    (root / "students").mkdir(parents=True)
    (root / "suite.json").write_text(json.dumps({"name": "standard"}))
    for budget, scratch, distilled in ((now, 0.3, 0.9), (2 * now, 0.9, 0.9)):
        for seed in range(3):
            for method, value in (("dqn", scratch), ("dynamic", distilled)):
                run = fake_run(root / "students", method, seed, [(budget, value)], [(budget, 1.0)], budget=budget,
                               task="KeySwordDragon", world="Grid10", hyperparameters=wide, layout_seed=1)
                result = json.loads((run / "result.json").read_text())
                (run / "result.json").write_text(json.dumps({**result, "seconds_share": 10.0, "device": "cpu"}))
    return now


def test_a_suite_s_runs_at_a_budget_it_no_longer_asks_for_are_set_apart_not_pooled(tmp_path):
    """A rung re-calibrated after its cells ran: the runs at the old budget stay on the page,
    in a section of their own, and the comparisons read the cells at today's budget."""
    from craftsuite.suites import SUITES

    suite = SUITES["standard"]
    root = tmp_path / "standard"
    now = _rebudgeted(root)
    text = write_results_page([root], tmp_path / "results.md").read_text()
    compared = [line for line in text.splitlines() if line.startswith("| KeySwordDragon | Grid10")]
    assert len(compared) == 1 and f"| {now:,} | " in compared[0] and "+0.60" in compared[0]
    assert "(a)" not in text and "(b)" not in text  # never variants of one another
    apart = text[text.index("### At budgets the suite no longer asks for"):]
    assert "| dqn | 3 | 0.90 [0.90, 0.90] | 0.90 0.90 0.90 |" in apart and f"{2 * now:,} / " in apart
    # the rungs learned read both: `dqn` learned it only at the old budget
    assert "KeySwordDragon (`dynamic` 0.90 and 1 other method)" in text
    short = text[text.index("## In short"):text.index("## Distilled against scratch")]
    assert "- Distilled against scratch, final greedy success: `n-step-wide` 1 comparison: ahead on 1, behind on " \
           "0, no difference of 0.2 or more on 0 (0 of them only because every seed of both sat at 0 or at 1), " \
           "undecided on 0." in short
    assert "### What the undecided would ask" not in text  # every comparison decided: nothing asked
    assert (": standard: Grid10 1 of 6 (KeySwordDragon; not yet run: Reach, FirstWood, FirstTool, ToolHome, "
            "TwoToolsHome), Cont 0 of 6 (not yet run: Reach, FirstWood, FirstTool, KeySwordDragon, ToolHome, "
            "TwoToolsHome).") in short
    asked = len(suite.student_configs(root / "teachers"))
    assert f"- Archived of each suite as defined now: standard 0 of {asked:,} runs (" in short
    # the Grid10 runs recorded their time, no Cont run did: the projection says so
    assert "h on 2 cores at the rates recorded; Cont not counted: no rate recorded)." in short
    # a cell at today's budget that has not finished: the old budget's runs stay apart, the page says so
    for run in (root / "students").iterdir():
        if json.loads((run / "config.json").read_text())["steps"] == now:
            (run / "result.json").unlink()
    text = write_results_page([root], tmp_path / "results.md").read_text()
    assert "### At budgets the suite no longer" in text and "No run finished yet; unfinished: dqn seed 0" in text


def test_the_results_page_lists_what_each_undecided_comparison_would_ask(tmp_path):
    spread = [1.0, 0.0, 0.5, 0.0, 1.0, 0.5]
    for seed in range(5):
        fake_run(tmp_path, "td3", seed, [(1000, spread[seed])], [(950, 1.0)], task="ToolHome")
        fake_run(tmp_path, "td3-dynamic", seed, [(1000, spread[seed + 1])], [(950, 1.0)], task="ToolHome")
    text = write_results_page([tmp_path], tmp_path / "results.md").read_text()
    assert text.index("## Distilled against scratch") < text.index("### What the undecided would ask")
    asked = text[text.index("### What the undecided would ask"):]
    row = "| ToolHome | Cont | one-step | `td3-dynamic` − `td3` | final greedy success | 1,000 | 5 / 5 |"
    assert asked.index(row) < asked.index("\n## ")  # inside the comparisons' section, before the next



def test_the_short_answer_tallies_each_distilled_method_apart(tmp_path):
    spread = [1.0, 0.0, 0.5, 0.0, 1.0, 0.5]
    for seed in range(5):
        fake_run(tmp_path, "td3", seed, [(1000, 0.1 * spread[seed])], [(950, 1.0)], task="ToolHome")
        fake_run(tmp_path, "td3-dynamic", seed, [(1000, spread[seed + 1])], [(950, 1.0)], task="ToolHome")
        fake_run(tmp_path, "td3-dynamic-edges", seed, [(1000, 0.9 + 0.01 * seed)], [(950, 1.0)], task="ToolHome")
    text = write_results_page([tmp_path], tmp_path / "results.md").read_text()
    short = text[text.index("## In short"):text.index("## Distilled against scratch")]
    assert "`one-step` 2 comparisons: ahead on 1, behind on 0" in short
    assert ("  - per distilled method, `one-step`: `td3-dynamic` (1 comparison): ahead 0, behind 0, no difference 0 "
            "(0 only at all-0/all-1), undecided 1; `td3-dynamic-edges` (1 comparison): ahead 1, behind 0, no "
            "difference 0 (0 only at all-0/all-1), undecided 0") in short


def test_one_suite_directory_s_leaderboard_sets_them_apart_too_unless_it_ran_at_one_budget(tmp_path, capsys):
    from craftsuite.cli import main

    root = tmp_path / "standard"
    now = _rebudgeted(root)
    assert main(["leaderboard", str(root)]) == 0
    text = (root / "leaderboard.md").read_text()
    assert "\n## At budgets the suite no longer asks for" in text and "(a)" not in text
    assert "| dynamic | 3 | 0.90" in text and "| dqn | 3 | 0.30" in text
    budgets = [row["budget_transitions"] for row in csv.DictReader((root / "leaderboard.csv").open())]
    assert sorted(budgets) == sorted([str(now)] * 2 + [str(2 * now)] * 2)  # every run a row of the CSVs
    # without a cell at today's budget (a directory trained with --steps, say) its runs are the
    # rung's only ones: nothing is set apart
    for run in (root / "students").iterdir():
        if json.loads((run / "config.json").read_text())["steps"] == now:
            shutil.rmtree(run)
    assert main(["leaderboard", str(root)]) == 0
    text = (root / "leaderboard.md").read_text()
    assert "At budgets the suite" not in text and "| dqn | 3 | 0.90" in text and "(a)" not in text


def test_the_scope_line_names_the_last_transfer_only_where_it_was_the_only_one():
    from craftsuite.reporting.pages import _suite_scope

    suite = {"tasks": ["DungeonQuest"], "worlds": ["Cont"], "methods": ["td3"], "seeds": 10}
    transfer = {"command": "craftsuite transfer --suite hard --tasks DungeonQuest"}
    archive = {"command": "craftsuite --debug archive runs/hard --suite hard", "archived": {"students": 5}}
    # the same command again (a resumed or fully reused run) leaves the scope the directory's
    once = _suite_scope(suite, [transfer, archive, transfer, archive])
    assert once.startswith(" As last run: rungs DungeonQuest; worlds Cont;")
    gathered = _suite_scope(suite, [transfer, archive, {"command": "python: craftsuite.suite_runner.transfer()"}])
    assert gathered == " Gathered from 2 different transfers, each listed below with its command."


def test_a_difference_whose_bound_rounds_to_the_smallest_difference_prints_it_apart():
    from craftsuite.reporting.pages import _difference_text
    from craftsuite.stats import Estimate

    # the verdict reads unrounded bounds: inside the band and just past it must not print alike
    assert _difference_text(Estimate(0.10, 0.01, 0.1996)) == "+0.1000 [+0.0100, +0.1996]"
    assert _difference_text(Estimate(0.04, -0.13, 0.2004)) == "+0.0400 [-0.1300, +0.2004]"
    assert _difference_text(Estimate(0.04, -0.198, 0.15)) == "+0.040 [-0.198, +0.150]"
    assert _difference_text(Estimate(0.10, 0.01, 0.17)) == "+0.10 [+0.01, +0.17]"  # far from it: two decimals
    assert _difference_text(Estimate(-0.1, -0.2, 0.0)) == "-0.10 [-0.20, +0.00]"  # exactly on it reads as it is


def test_a_difference_whose_interval_excludes_zero_never_prints_a_bound_of_zero():
    from craftsuite.reporting.pages import _difference_text
    from craftsuite.stats import Estimate

    # a real gap (the interval one side of 0) shows the side its near bound lies on
    assert _difference_text(Estimate(-0.01, -0.02, -0.003)) == "-0.010 [-0.020, -0.003]"
    assert _difference_text(Estimate(0.04, 0.0004, 0.08)) == "+0.0400 [+0.0004, +0.0800]"
    assert _difference_text(Estimate(-0.04, -0.08, -0.00003)) == "-0.0400 [-0.0800, -3.0e-05]"  # past 4 decimals
    assert _difference_text(Estimate(2e-5, 1e-5, 3e-5)) == "+2.0e-05 [+1.0e-05, +3.0e-05]"
    # an interval across 0 keeps two decimals: its bound near 0 says nothing the verdict reads
    assert _difference_text(Estimate(-0.004, -0.01, 0.002)) == "-0.00 [-0.01, +0.00]"


def test_a_page_of_two_directories_projects_at_one_rate_per_regime_and_world(tmp_path):
    """Each directory's coverage reads the rate of every directory's runs, not its own: the
    page's projections then agree with each other and with its planning table."""
    first, second = tmp_path / "a" / "standard", tmp_path / "b" / "standard"
    _rebudgeted(first)
    _rebudgeted(second)
    steps = seconds = 0.0
    for root, share in ((first, 10.0), (second, 30.0)):
        for run in (root / "students").iterdir():
            result = json.loads((run / "result.json").read_text())
            (run / "result.json").write_text(json.dumps({**result, "seconds_share": share}))
            steps, seconds = steps + result["steps"], seconds + share
    text = write_results_page([first, second], tmp_path / "results.md").read_text()
    pooled = f"Grid10 {steps / seconds:,.0f} transitions/s"
    assert text.count(pooled) == 2  # the two directories' coverage sentences, at the pooled rate
    alone = f"Grid10 {steps / 2 / (seconds * 0.25):,.0f} transitions/s"  # the first directory's own rate
    assert alone not in text
