"""What the undecided comparisons ask: seeds a side, runs to add per side, their cost, quickest first."""

import json

from craftsuite.reporting.board import build
from craftsuite.reporting.pages import comparisons, in_metric
from craftsuite.reporting.timing import rates
from craftsuite.reporting.to_decide import asks, to_decide_markdown
from .fakes import fake_run

SPREAD = [1.0, 0.0, 0.5, 0.0, 1.0, 0.5, 1.0, 0.0, 0.5, 1.0, 0.0, 0.5]  # bimodal-ish: wide intervals


def _timed(run, seconds):
    """A run whose record says it trained for ``seconds`` of one process."""
    result = json.loads((run / "result.json").read_text())
    (run / "result.json").write_text(json.dumps({**result, "device": "cpu", "seconds_share": seconds}))
    return run


def test_undecided_comparisons_are_listed_quickest_first_with_the_runs_each_side_lacks(tmp_path):
    # Cont, ToolHome: 40 scratch seeds against 5 distilled at 1,000 transitions a run, at 1 per second;
    # Grid10, TwoToolsHome: 5 a side at 10,000 a run, more transitions but at 1,000 per second;
    # Kinematic, FirstTool: 5 a side at 20 a run, the fewest transitions, but no run of it timed
    for seed in range(40):
        _timed(fake_run(tmp_path, "td3", seed, [(1000, SPREAD[seed % 12])], [(950, 1.0)], task="ToolHome"), 1000.0)
    for seed in range(5):
        _timed(fake_run(tmp_path, "td3-dynamic", seed, [(1000, (1.0, 1.0, 0.5, 0.5, 1.0)[seed])], [(950, 1.0)],
                        task="ToolHome"), 1000.0)
        for method, shift in (("dqn", 0), ("dynamic", 1)):
            _timed(fake_run(tmp_path, method, seed, [(10_000, SPREAD[seed + shift])], [(9_500, 1.0)], budget=10_000,
                            task="TwoToolsHome", world="Grid10"), 10.0)
        for method, shift in (("td3", 0), ("td3-dynamic", 1)):
            fake_run(tmp_path, method, seed, [(20, SPREAD[seed + shift])], [(15, 1.0)], budget=20,
                     task="FirstTool", world="Kinematic")
    board = build(tmp_path)
    pairs = comparisons([board])
    found = asks(pairs, in_metric(pairs, "auc"), rates(board))
    success = {a.entry.world: a for a in found if a.metric == "success"}
    assert [a.entry.world for a in found if a.metric == "success"] == ["Grid10", "Cont", "Kinematic"]
    grid, cont, kinematic = success["Grid10"], success["Cont"], success["Kinematic"]
    assert grid.transitions > cont.transitions > kinematic.transitions  # by hours, not by transitions
    assert abs(cont.hours - cont.transitions / 1 / 3600) < 1e-9  # 1,000 transitions in 1,000 s
    assert abs(grid.hours - grid.transitions / 1_000 / 3600) < 1e-9 and kinematic.hours is None
    assert 5 < cont.seeds < 40 and cont.runs == (cont.seeds - 5, 0)  # scratch has enough already
    assert grid.runs == (grid.seeds - 5, grid.seeds - 5) and cont.transitions == (cont.seeds - 5) * 1_000
    text = "\n".join(to_decide_markdown(found))
    assert (f"| ToolHome | Cont | one-step | `td3-dynamic` − `td3` | final greedy success | 1,000 | 5 / 40 | "
            f"{cont.seeds} | {cont.seeds - 5} + 0 | {cont.transitions:,} | {cont.hours:.1f} |") in text
    assert "| FirstTool | Kinematic | one-step | `td3-dynamic` − `td3` | AUC | 20 | 5 / 5 | " in text
    assert text.splitlines()[-3].endswith(" | ? |")  # the last row: no rate


def test_nothing_is_listed_where_every_comparison_is_decided(tmp_path):
    for seed in range(5):
        fake_run(tmp_path, "td3", seed, [(1000, 0.0)], [(950, 0.0)], task="ToolHome")
        fake_run(tmp_path, "td3-dynamic", seed, [(1000, 1.0)], [(950, 1.0)], task="ToolHome")
    board = build(tmp_path)
    pairs = comparisons([board])
    assert asks(pairs, in_metric(pairs, "auc"), rates(board)) == [] and to_decide_markdown([]) == []


def test_the_comparisons_of_the_regime_the_suites_run_now_come_first(tmp_path):
    from craftsuite.regimes import check_regime

    wide = check_regime("n-step-wide").settings("td3")
    for seed in range(5):
        for method, shift in (("td3", 0), ("td3-dynamic", 1)):
            # one-step: quick (1,000 transitions a second); n-step-wide: slow (1 a second)
            _timed(fake_run(tmp_path, method, seed, [(1000, SPREAD[seed + shift])], [(950, 1.0)], task="ToolHome"),
                   1.0)
            _timed(fake_run(tmp_path, method, seed, [(1000, SPREAD[seed + shift])], [(950, 1.0)], task="ToolHome",
                            hyperparameters=wide), 1000.0)
    board = build(tmp_path)
    pairs = comparisons([board])
    auc, measured = in_metric(pairs, "auc"), rates(board)
    assert [a.entry.regime for a in asks(pairs, auc, measured)][:2] == ["one-step"] * 2  # quickest first
    now = asks(pairs, auc, measured, frozenset({"n-step-wide"}))
    assert [a.entry.regime for a in now] == ["n-step-wide"] * 2 + ["one-step"] * 2
    assert ("those of the learner regime the suites run now (`n-step-wide`) first, each group quickest first"
            in "\n".join(to_decide_markdown(now, frozenset({"n-step-wide"}))))


def test_a_distilled_side_whose_teacher_is_no_longer_trained_is_marked(tmp_path):
    """A distilled run's key names its teacher: where today's suites train another (the
    one-step runs read a teacher the SB3 engine trained), more of its runs cannot be made,
    and the row says so rather than ask for them."""
    for seed in range(5):
        fake_run(tmp_path, "dqn", seed, [(10_000, SPREAD[seed])], [(9_500, 1.0)], budget=10_000,
                 task="TwoToolsHome", world="Grid10")
        fake_run(tmp_path, "dynamic", seed, [(10_000, SPREAD[seed + 1])], [(9_500, 1.0)], budget=10_000,
                 task="TwoToolsHome", world="Grid10",
                 effective={"teacher": "teacher-TwoToolsHome-Grid7-s0-old/table.npz"})
    board = build(tmp_path)
    pairs = comparisons([board])
    for teachers, gone in ((frozenset({"teacher-TwoToolsHome-Grid7-s0-old"}), None),
                           (frozenset({"teacher-TwoToolsHome-Grid7-s0-new"}), "teacher-TwoToolsHome-Grid7-s0-old")):
        found = asks(pairs, in_metric(pairs, "auc"), rates(board), teachers=teachers)
        assert found and all(a.gone == gone for a in found)
        a = found[0]
        assert a.transitions == (a.runs[1] if gone else sum(a.runs)) * 10_000  # runs that can be made alone
        text = "\n".join(to_decide_markdown(found))
        assert (f"| {a.runs[0]}* + {a.runs[1]} | {a.transitions:,} |" in text) == (gone is not None)
        assert ("(teacher-TwoToolsHome-Grid7-s0-old): `craftsuite transfer` adds to the scratch side only" in text) \
            == (gone is not None)
    assert all(a.gone is None for a in asks(pairs, in_metric(pairs, "auc"), rates(board)))  # no suite: none said
