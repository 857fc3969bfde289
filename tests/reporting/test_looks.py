"""A comparison read more than once before its seeds stopped growing is read at 1 - 0.05/k
for its k looks, which the archive's looks.json names."""

import json

import pytest

from craftsuite import stats
from craftsuite.reporting.board import build, compare
from craftsuite.reporting.looks import looks, read
from craftsuite.reporting.pages import comparisons, comparisons_markdown

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


def test_the_shared_level_splits_the_error_over_the_looks():
    assert [round(stats.shared_level(k), 4) for k in (1, 2, 3)] == [0.95, 0.975, 0.9833]
    with pytest.raises(ValueError, match="read at least once"):
        stats.shared_level(0)


def test_each_earlier_reading_below_todays_seeds_is_one_look_more(archive):
    assert looks(entries(archive)["td3-dynamic"]) == 1  # no looks.json: read once
    write(archive, [{"task": "ToolHome", "world": "Cont", "regime": "one-step", "methods": ["td3-dynamic"],
                     "read_at": [5, 3, 10, 20]}])  # 10: today's reading; 20: not reached
    e = entries(archive)
    assert looks(e["td3-dynamic"]) == 3
    assert looks(e["td3-static"]) == 1  # another method
    write(archive, [{"task": "ToolHome", "world": "Grid10", "regime": "one-step", "methods": ["td3-dynamic"],
                     "read_at": [5]}])
    assert looks(entries(archive)["td3-dynamic"]) == 1  # another world


def test_a_comparison_decided_at_one_look_can_be_undecided_at_three(archive):
    e = entries(archive)
    once, thrice = compare(e["td3-dynamic"], e["td3"]), compare(e["td3-dynamic"], e["td3"], looks=3)
    assert once.verdict == "behind" and once.level == 0.95
    assert thrice.verdict == "undecided" and thrice.looks == 3
    assert thrice.difference.low < once.difference.low and thrice.difference.value == once.difference.value
    assert thrice.seeds_to_decide > 10


def test_the_page_reads_the_looks_and_says_so(archive):
    write(archive, [{"task": "ToolHome", "world": "Cont", "regime": "one-step", "methods": ["td3-dynamic"],
                     "read_at": [3, 5]}])
    pairs = comparisons([build(archive / "students")])
    said = {entry.method: c for entry, _, c in pairs}
    assert said["td3-dynamic"].looks == 3 and said["td3-dynamic"].verdict == "undecided"
    assert said["td3-static"].looks == 1 and said["td3-static"].verdict == "behind"
    text = "\n".join(comparisons_markdown(pairs))
    assert "| undecided (its 3 looks: every interval at 98.3%) (at these means and spreads: about" in text
    assert "on 1 of 2 comparisons" in text


@pytest.mark.parametrize("items, problem", [
    ("[", "is not valid JSON"),
    ({"task": "ToolHome"}, "expected a list of comparisons"),
    ([{"task": "ToolHome", "world": "Cont", "regime": "one-step", "methods": ["td3-dynamic"]}],
     "item 0: no read_at (an item has exactly task, world, regime, methods, read_at)"),
    ([{"task": "ToolHome", "world": "Cont", "regime": "one-step", "methods": ["td3-dynamic"], "read_at": [5],
       "seeds": 10}], "item 0: unknown seeds"),
    ([{"task": "ToolHome", "world": "Cont", "regime": "one-step", "methods": "td3-dynamic", "read_at": [5]}],
     "item 0: methods must be a list"),
    ([{"task": "ToolHome", "world": "Cont", "regime": "one-step", "methods": ["td3-dynamic"], "read_at": [0]}],
     "item 0: read_at must be the seeds (whole numbers above 0)"),
])
def test_a_bad_looks_file_is_named_by_its_item_and_field(tmp_path, items, problem):
    path = tmp_path / "looks.json"
    path.write_text(items if isinstance(items, str) else json.dumps(items))
    with pytest.raises(ValueError) as err:
        read(path)
    assert str(err.value).startswith(str(path)) and problem in str(err.value)
