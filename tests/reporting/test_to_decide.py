"""What the undecided comparisons ask: seeds a side, runs to add per side, their cost, cheapest first."""

import json

from craftsuite.reporting.board import build
from craftsuite.reporting.pages import comparisons, in_metric
from craftsuite.reporting.to_decide import asks, to_decide_markdown
from .fakes import fake_run

SPREAD = [1.0, 0.0, 0.5, 0.0, 1.0, 0.5, 1.0, 0.0, 0.5, 1.0, 0.0, 0.5]  # bimodal-ish: wide intervals


def _timed(run, seconds):
    """A run whose record says it trained for ``seconds`` of one process."""
    result = json.loads((run / "result.json").read_text())
    (run / "result.json").write_text(json.dumps({**result, "device": "cpu", "seconds_share": seconds}))


def test_undecided_comparisons_are_listed_quickest_first_with_the_runs_each_side_lacks(tmp_path):
    # ToolHome: 12 scratch seeds against 5 distilled, at 1,000 transitions a run, timed at 100 per second;
    # TwoToolsHome: 5 a side at 10,000 a run: dearer per seed, and no run of its world is timed
    for seed in range(12):
        _timed(fake_run(tmp_path, "td3", seed, [(1000, SPREAD[seed])], [(950, 1.0)], task="ToolHome"), 10.0)
    for seed in range(5):
        _timed(fake_run(tmp_path, "td3-dynamic", seed, [(1000, SPREAD[seed + 1])], [(950, 1.0)], task="ToolHome"),
               10.0)
        for method, shift in (("dqn", 0), ("dynamic", 1)):
            fake_run(tmp_path, method, seed, [(10_000, SPREAD[seed + shift])], [(9_500, 1.0)], budget=10_000,
                     task="TwoToolsHome", world="Grid10")
    board = build(tmp_path)
    pairs = comparisons([board])
    found = asks(pairs, in_metric(pairs, "auc"), [board])
    success = [a for a in found if a.metric == "success"]
    assert [a.entry.task for a in success] == ["ToolHome", "TwoToolsHome"]  # no rate for TwoToolsHome: last
    timed = [a.hours for a in found if a.hours is not None]
    assert timed == sorted(timed) and found[-1].hours is None
    tool, two = success
    assert tool.seeds > 12 and tool.runs == (tool.seeds - 5, tool.seeds - 12)  # each side to the same count
    assert tool.transitions == sum(tool.runs) * 1_000
    assert abs(tool.hours - tool.transitions / 100 / 3600) < 1e-9  # 1,000 transitions in 10 s: 100 per second
    assert two.hours is None and two.runs == (two.seeds - 5, two.seeds - 5)
    text = "\n".join(to_decide_markdown(found))
    assert (f"| ToolHome | Cont | one-step | `td3-dynamic` − `td3` | final greedy success | 1,000 | 5 / 12 | "
            f"{tool.seeds} | {tool.runs[0]} + {tool.runs[1]} |") in text
    assert f"| {two.seeds} | {two.runs[0]} + {two.runs[1]} |" in text and text.count("| ? |") >= 1


def test_nothing_is_listed_where_every_comparison_is_decided(tmp_path):
    for seed in range(5):
        fake_run(tmp_path, "td3", seed, [(1000, 0.0)], [(950, 0.0)], task="ToolHome")
        fake_run(tmp_path, "td3-dynamic", seed, [(1000, 1.0)], [(950, 1.0)], task="ToolHome")
    board = build(tmp_path)
    pairs = comparisons([board])
    assert asks(pairs, in_metric(pairs, "auc"), [board]) == [] and to_decide_markdown([]) == []
