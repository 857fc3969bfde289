"""The record format is data: its docs page is generated from it and current, and the
checks every reader makes name the file, the line and the field they refuse."""

from pathlib import Path

import numpy as np
import pytest

from craftsuite.cli import main
from craftsuite.record_format import (FILES, RecordError, check_config, check_episodes, check_evals, check_result,
                                      markdown)

ROOT = Path(__file__).resolve().parents[1]


def test_the_docs_page_is_the_format_as_it_is():
    assert (ROOT / "docs" / "records.md").read_text() == markdown()
    for name, fields in FILES.items():
        assert f"## `{name}`" in markdown() and all(f"| `{f.name}` |" in markdown() for f in fields)


def test_the_command_writes_the_page(tmp_path, capsys):
    assert main(["records", "--markdown", str(tmp_path / "records.md")]) == 0
    assert (tmp_path / "records.md").read_text() == markdown()
    assert main(["records", "--markdown", str(tmp_path)]) == 2  # a directory: named, with the file to give
    assert "records.md" in capsys.readouterr().err


CONFIG = {"task": "Reach", "world": "Cont", "method": "my-sac", "seed": 0, "steps": 1000}


@pytest.mark.parametrize("check, message", [
    (lambda: check_config({**CONFIG, "steps": None}, "c.json"), "c.json: steps .* must be an integer > 0"),
    (lambda: check_config({k: v for k, v in CONFIG.items() if k != "world"}, "c.json"), "c.json: lacks world"),
    (lambda: check_config({**CONFIG, "seed": -1}, "c.json"), "seed must be an integer >= 0, got -1"),
    (lambda: check_config({"task": "Reach", "max_steps": 10_000, "seed": 0}, "c.json"),
     r"^c.json is a teacher's \(max_steps, not steps\), not a student's record$"),
    (lambda: check_result({"kind": "student", "steps": 999}, CONFIG, "r.json"), "steps 999 is short of the budget"),
    (lambda: check_result({"kind": "student", "steps": 1000, "updates": -2}, CONFIG, "r.json"), "updates must be"),
    (lambda: check_result({"kind": "student", "steps": 1000, "seconds_share": -1.0}, CONFIG, "r.json"),
     "r.json: seconds_share must be a number >= 0, got -1.0"),
    (lambda: check_result({"kind": "student", "steps": 1000, "members": "5"}, CONFIG, "r.json"),
     "members must be an integer > 0, got '5'"),
    (lambda: check_result({"kind": "student", "steps": 1000, "machine": 2}, CONFIG, "r.json"),
     "machine must be a string"),
    (lambda: check_result({"kind": "student", "steps": 1000, "seed": 4}, CONFIG, "r.json"),
     "seed 4 is not config.json's \\(0\\): the result of another run"),
    (lambda: check_evals({"step": ("1000",), "success": ("inf",)}, 1000, "e.csv"), "e.csv: line 2: success is inf"),
    (lambda: check_evals({"step": (), "success": ()}, 1000, "e.csv"),
     r"e.csv holds no evaluation: a finished run's record has one at least \(at its end\)"),
    (lambda: check_evals({"step": ("500", "500.5"), "success": ("1", "1")}, 1000, "e.csv"),
     "e.csv: line 3: step 500.5 is not a step of the run"),
    (lambda: check_evals({"step": ("500", "1000"), "success": ("0.5", "1.5")}, 1000, "e.csv"),
     "line 3: success 1.5 is not a rate in \\[0, 1\\]"),
    # an empty mean is allowed (not measured), and does not shift the line named after it
    (lambda: check_evals({"step": ("500", "1000", "1000"), "success": ("1", "1", "1"), "length": ("", "4", "x")},
                         1000, "e.csv"), "e.csv: line 4: length 'x' is not a number"),
    (lambda: check_evals({"step": ("500", "1000"), "success": ("1", "1"), "return": ("", "-inf")}, 1000, "e.csv"),
     "e.csv: line 3: return is -inf"),
    (lambda: check_episodes({"step": ("10",), "return": ("",), "success": ("0",)}, 1000, "p.csv"),
     "p.csv: line 2: return '' is not a"),
    (lambda: check_episodes({"step": ("10", "2000"), "return": ("1", "1"), "success": ("0", "1")}, 1000, "p.csv"),
     "p.csv: line 3: step 2000 is not a step of the run"),
    (lambda: check_episodes({"step": ("10", "20.5"), "return": ("1", "1"), "success": ("0", "1")}, 1000, "p.csv"),
     "p.csv: line 3: step 20.5 is not a step of the run"),
    (lambda: check_episodes({"step": ("10", "20"), "return": ("1", "1"), "success": ("0", "0.5")}, 1000, "p.csv"),
     "p.csv: line 3: success 0.5 is not 0 or 1"),
])
def test_a_record_that_breaks_the_format_is_named(check, message):
    with pytest.raises(RecordError, match=message):
        check()


def test_a_good_record_passes():
    check_config(CONFIG, "c.json")
    check_result({"kind": "student", "steps": 1010, "updates": 3, "task": "Reach", "seconds_share": 12.5,
                  "members": 5, "machine": "Linux x86_64, 2 cores"}, CONFIG, "r.json")
    evals = check_evals({"step": ("1000",), "success": ("0.5",), "return": ("1.5",), "length": ("",)}, 1010, "e.csv")
    episodes = check_episodes({"step": ("10", "20"), "return": ("-3.0", "1"), "success": ("0", "1")}, 1010, "p.csv")
    none = check_episodes({"step": (), "return": (), "success": ()}, 1010, "p.csv")  # no episode yet
    # the checks give the columns they read as floats, for a reader that would parse them again
    assert {k: v.tolist() for k, v in evals.items()} == {"step": [1000.0], "success": [0.5]}
    assert {k: v.tolist() for k, v in episodes.items()} == {"step": [10.0, 20.0], "return": [-3.0, 1.0],
                                                            "success": [0.0, 1.0]}
    assert all(v.dtype == np.float64 and v.shape == (0,) for v in none.values()) and len(none) == 3
