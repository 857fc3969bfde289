"""A comparison read more than once before its seeds stopped growing is read at 1 - 0.05/k
for its k looks: one after each campaign part that added seeds to either side (the commits
its runs' records name), and each reading the archive's looks.json names besides."""

import json

import pytest

from craftsuite import stats
from craftsuite.reporting.board import build, compare
from craftsuite.reporting.looks import check, looks, read, readings
from craftsuite.reporting.pages import comparisons, comparisons_markdown
from craftsuite.reporting.sources import read_runs

from .fakes import fake_run

# ten seeds a side, the distilled student behind by about 0.12: decided at 95%, not at 98.3%
SCRATCH = [0.9, 0.7, 0.8, 0.95, 0.6, 0.85, 0.75, 0.9, 0.7, 0.8]
DISTILLED = [0.75, 0.55, 0.7, 0.85, 0.5, 0.7, 0.6, 0.75, 0.6, 0.7]


@pytest.fixture
def archive(tmp_path):
    for seed in range(10):
        for method, values in (("td3", SCRATCH), ("td3-dynamic", DISTILLED), ("td3-static", DISTILLED)):
            fake_run(tmp_path / "students", method, seed, [(1000, values[seed])], [(950, 1.0)], task="ToolHome")
    return tmp_path


def entries(root):
    return {e.method: e for e in build(root / "students")}


def write(root, items):
    (root / "looks.json").write_text(json.dumps(items))


def sessions(root, method, seeds, *parts):
    """Give the fixture's runs of ``method`` (``seeds``) the sessions that trained them, each
    part (commit, when it began) in turn: the last one finished them."""
    for seed in seeds:
        run = root / "students" / f"student-ToolHome-Cont-{method}-s{seed}"
        config = json.loads((run / "config.json").read_text())
        config["provenance"] = [{"at": at, "commit": commit, "versions": {}} for commit, at in parts]
        (run / "config.json").write_text(json.dumps(config))


def pair(distilled, scratch):
    """A reading named by both sides' seeds, as looks.json names it."""
    return {"distilled": distilled, "scratch": scratch}


def item(method="td3-dynamic", read_at=(5,), **changes):
    """A looks.json item naming the fixture's ToolHome runs (one-step, 1,000 transitions)."""
    return {"task": "ToolHome", "world": "Cont", "regime": "one-step", "budget": 1000, "methods": [method],
            "read_at": list(read_at), **changes}


def test_the_shared_level_splits_the_error_over_the_looks():
    assert [round(stats.shared_level(k), 4) for k in (1, 2, 3)] == [0.95, 0.975, 0.9833]
    with pytest.raises(ValueError, match="read at least once"):
        stats.shared_level(0)


def test_each_earlier_reading_below_todays_seeds_is_one_look_more(archive):
    e = entries(archive)
    assert looks(e["td3-dynamic"], e["td3"]) == 1  # no commits named, no looks.json: read once
    write(archive, [item(read_at=[5, 3, 10, 20])])  # 10: today's reading; 20: not reached
    e = entries(archive)
    assert readings(e["td3-dynamic"], e["td3"]) == [(3, None), (5, None), (10, 10)]
    assert looks(e["td3-static"], e["td3"]) == 1  # another method
    for other in ({"world": "Grid10"}, {"budget": 2000}, {"regime": "n-step-wide"}):
        write(archive, [item(**other)])
        e = entries(archive)
        assert looks(e["td3-dynamic"], e["td3"]) == 1, other  # another setting


def test_each_part_that_added_seeds_to_either_side_was_a_reading(archive):
    first, second, third = ("aaa", "2026-01-01T10:00:00+00:00"), ("bbb", "2026-01-02T10:00:00+00:00"), \
        ("ccc", "2026-01-03T10:00:00+00:00")
    sessions(archive, "td3", range(5), first)
    sessions(archive, "td3-dynamic", range(5), first)
    sessions(archive, "td3", range(5, 10), second)  # scratch grew alone: the comparison read at 5/10
    sessions(archive, "td3-dynamic", range(5, 8), third)
    sessions(archive, "td3-dynamic", range(8, 10), ("ddd", "2026-01-01T12:00:00+00:00"), third)  # finished in the third
    sessions(archive, "td3-static", range(10), first)
    e = entries(archive)
    assert readings(e["td3-dynamic"], e["td3"]) == [(5, 5), (5, 10), (10, 10)]
    assert readings(e["td3-static"], e["td3"]) == [(10, 5), (10, 10)]
    write(archive, [item(read_at=[5, 7])])  # 5: the records' reading already; 7: one they cannot show
    e = entries(archive)
    assert readings(e["td3-dynamic"], e["td3"]) == [(5, 5), (5, 10), (7, None), (10, 10)]
    assert compare(e["td3-dynamic"], e["td3"], looks=looks(e["td3-dynamic"], e["td3"])).level == stats.shared_level(4)


def test_a_reading_named_by_both_sides_seeds_counts_where_only_scratch_grew_since(archive):
    # both sides' runs at one commit (a part read part way, as its scratch side grew): the
    # records give today's reading alone, and a distilled count cannot name 10 at 10 today
    sessions(archive, "td3", range(10), ("aaa", "2026-01-01T10:00:00+00:00"))
    sessions(archive, "td3-dynamic", range(10), ("aaa", "2026-01-01T10:00:00+00:00"))
    write(archive, [item(read_at=[10])])
    e = entries(archive)
    assert readings(e["td3-dynamic"], e["td3"]) == [(10, 10)]
    # [10, 10]: today's; [10, 12] and [12, 5]: a side above today's; [5, 3] twice: one reading
    write(archive, [item(read_at=[pair(10, 4), pair(5, 3), pair(5, 3), pair(10, 10), pair(10, 12), pair(12, 5)])])
    e = entries(archive)
    assert readings(e["td3-dynamic"], e["td3"]) == [(5, 3), (10, 4), (10, 10)]
    # a pair the records give already, and a distilled count a pair gives, add nothing
    sessions(archive, "td3", range(5, 10), ("bbb", "2026-01-02T10:00:00+00:00"))
    write(archive, [item(read_at=[pair(10, 5), pair(7, 2), 7])])
    e = entries(archive)
    assert readings(e["td3-dynamic"], e["td3"]) == [(7, 2), (10, 5), (10, 10)]
    assert compare(e["td3-dynamic"], e["td3"], looks=looks(e["td3-dynamic"], e["td3"])).level == stats.shared_level(3)


def test_a_commit_shortened_or_marked_dirty_is_one_part_and_so_are_runs_naming_none(archive):
    # archiving a part's first runs dirties the tree, so the rest of that part names the commit
    # dirty, and records name 8, 10 or 40 digits of it: one part, one reading after it
    sessions(archive, "td3", range(10), ("0123456789", "2026-01-01T10:00:00+00:00"))
    sessions(archive, "td3-dynamic", range(5), ("01234567", "2026-01-01T10:00:00+00:00"))
    sessions(archive, "td3-dynamic", range(5, 10), ("0123456789-dirty", "2026-01-01T11:00:00+00:00"))
    e = entries(archive)
    assert readings(e["td3-dynamic"], e["td3"]) == [(10, 10)]
    # outside a checkout: each run's own start time, nothing to tell its sessions apart by
    for seed in range(10):
        sessions(archive, "td3-static", [seed], (None, f"2026-01-02T09:{seed:02d}:00+00:00"))
    e = entries(archive)
    assert readings(e["td3-static"], e["td3"]) == [(10, 10)]


def test_an_entry_pooled_from_two_archives_counts_the_readings_of_both(archive, tmp_path_factory):
    other = tmp_path_factory.mktemp("other")
    for seed in range(10, 15):
        fake_run(other / "students", "td3-dynamic", seed, [(1000, 0.7)], [(950, 1.0)], task="ToolHome")
    write(archive, [item(read_at=[5])])
    write(other, [item(read_at=[10])])
    pooled = {e.method: e for e in build(archive / "students", other / "students")}
    assert len(pooled["td3-dynamic"].seeds) == 15 and looks(pooled["td3-dynamic"], pooled["td3"]) == 3


def test_a_comparison_decided_at_one_look_can_be_undecided_at_three(archive):
    e = entries(archive)
    once, thrice = compare(e["td3-dynamic"], e["td3"]), compare(e["td3-dynamic"], e["td3"], looks=3)
    assert once.verdict == "behind" and once.level == 0.95
    assert thrice.verdict == "undecided" and thrice.looks == 3
    assert thrice.difference.low < once.difference.low and thrice.difference.value == once.difference.value
    assert thrice.seeds_to_decide > 10


def test_the_page_reads_the_looks_and_says_so(archive):
    write(archive, [item(read_at=[3, 5])])
    pairs = comparisons([read_runs(archive).board])
    said = {entry.method: c for entry, _, c in pairs}
    assert said["td3-dynamic"].looks == 3 and said["td3-dynamic"].verdict == "undecided"
    assert said["td3-static"].looks == 1 and said["td3-static"].verdict == "behind"
    text = "\n".join(comparisons_markdown(pairs))
    assert "| undecided (read 3 times: every interval at 98.3%; at these means and spreads: about" in text
    assert "on 1 of 2 comparisons" in text


@pytest.mark.parametrize("named, problem", [
    ({"task": "ToolHmoe"}, "item 0 names no runs of td3-dynamic (ToolHmoe in Cont, one-step, 1,000 transitions)"),
    ({"budget": 2000}, "item 0 names no runs of td3-dynamic (ToolHome in Cont, one-step, 2,000 transitions)"),
    ({"methods": ["td3"]}, "item 0: 'td3' is not a distilled method"),
])
def test_an_item_that_names_no_runs_is_refused_by_name(archive, named, problem):
    write(archive, [item(**named)])
    with pytest.raises(ValueError) as err:
        read_runs(archive)
    assert str(err.value).startswith(str(archive / "looks.json")) and problem in str(err.value)
    check([])  # no entries: no archive, nothing to check


@pytest.mark.parametrize("items, problem", [
    ("[", "is not valid JSON"),
    ({"task": "ToolHome"}, "expected a list of comparisons"),
    ([{k: v for k, v in item().items() if k != "read_at"}],
     "item 0: no read_at (an item has exactly task, world, regime, budget, methods, read_at, e.g. {"),
    ([item(seeds=10)], "item 0: unknown seeds"),
    ([item(budget="1k")], "item 0: budget must be a whole number, got '1k'"),
    ([item(methods="td3-dynamic")], "item 0: methods must be a list"),
    ([item(read_at=[0])], "item 0: read_at must list the seeds (whole numbers above 0)"),
    ([item(read_at=[])], "item 0: read_at must list the seeds"),
    ([item(read_at=[5, [10, 20]])], "item 0: read_at's reading [10, 20] does not say which side is which; write it "
                                     '{"distilled": 10, "scratch": 20}'),
    ([item(read_at=[[10]])], "item 0: read_at must list the seeds (whole numbers above 0) at each reading, the "
                              "distilled side's or both sides' by name, got [[10]] (e.g. \"read_at\": [5, 10] "
                              'or [{"distilled": 10, "scratch": 20}])'),
    ([item(read_at=[pair(10, 0)])], 'or both sides\' by name, got [{"distilled": 10, "scratch": 0}]'),
    ([item(read_at=[{"distilled": 10}])], 'or both sides\' by name, got [{"distilled": 10}]'),
    ([item(read_at=[{**pair(10, 20), "baseline": 20}])], "or both sides' by name"),
])
def test_a_bad_looks_file_is_named_by_its_item_and_field(tmp_path, items, problem):
    path = tmp_path / "looks.json"
    path.write_text(items if isinstance(items, str) else json.dumps(items))
    with pytest.raises(ValueError) as err:
        read(path)
    assert str(err.value).startswith(str(path)) and problem in str(err.value)
