"""Bad input to ``craftsuite leaderboard``: a damaged run is named by its file and left out,
a path that cannot be written is named by its flag before anything is read, and a refused
command writes nothing."""

from pathlib import Path

import pytest

from craftsuite.cli import main
from craftsuite.reporting.board import build
from craftsuite.reporting.plots import plot_curves

from .fakes import fake_run


def _files(root):
    """Every file and folder under ``root``, relative to it: what a command left there."""
    return sorted(str(p.relative_to(root)) for p in root.rglob("*"))


@pytest.mark.parametrize("text, problem", [
    (None, "evals.csv is missing"),
    ("", "the file is empty"),
    ("garbage\n", "its header lacks step, success"),
    ("\x00\x01 not a log,at all\n", "its header lacks step, success"),
    ("step,success,return,episodes\nhello\nworld\n", "its line 2 has fewer fields than its header"),
])
def test_a_damaged_evals_log_is_named_and_its_run_left_off_the_leaderboard(runs, capsys, text, problem):
    damaged = fake_run(runs, "td3", 7, [(1000, 1.0)], [(995, 1.0)])
    if text is None:
        (damaged / "evals.csv").unlink()
    else:
        (damaged / "evals.csv").write_text(text)
    assert main(["leaderboard", str(runs)]) == 0
    out = capsys.readouterr().out
    [line] = [s for s in out.splitlines() if s.startswith("Not read:")]
    assert str(damaged / "evals.csv") in line and problem in line and "damaged" in line
    assert "| td3 | 2 |" in (runs / "leaderboard.md").read_text()  # the two good seeds, not the damaged one
    assert (runs / "curves-BlindCraftsman-Cont.png").is_file()


def test_a_run_never_evaluated_is_drawn_without_a_curve(runs):
    fake_run(runs, "td3", 2, [], [(995, 1.0)])  # the header alone: finished, never evaluated
    assert [p.name for p in plot_curves(build(runs), runs.parent)] == ["curves-BlindCraftsman-Cont.png"]


def test_a_failure_while_drawing_leaves_no_part_of_the_leaderboard(runs, monkeypatch, capsys):
    import craftsuite.reporting.plots

    def broken(*_):
        raise RuntimeError("drawing failed")

    before = _files(runs)
    monkeypatch.setattr(craftsuite.reporting.plots, "draw_curves", broken)
    assert main(["leaderboard", str(runs)]) == 2
    assert "drawing failed" in capsys.readouterr().err
    assert _files(runs) == before  # neither leaderboard.md nor .csv nor a profile


def test_a_failure_while_rendering_leaves_no_profile_behind(runs, monkeypatch):
    import craftsuite.reporting.pages
    from craftsuite.reporting.pages import write_leaderboard

    def broken(*_, **__):
        raise RuntimeError("rendering failed")

    before = _files(runs)
    monkeypatch.setattr(craftsuite.reporting.pages, "leaderboard_markdown", broken)
    with pytest.raises(RuntimeError, match="rendering failed"):
        write_leaderboard(build(runs), runs)
    assert _files(runs) == before


def test_a_results_page_that_fails_on_its_second_directory_writes_no_image_of_the_first(
        runs, tmp_path, monkeypatch):
    import craftsuite.reporting.pages

    real, calls = craftsuite.reporting.pages.draw_curves, []

    def second_fails(board):
        calls.append(board)
        if len(calls) == 2:
            raise RuntimeError("drawing failed")
        return real(board)

    monkeypatch.setattr(craftsuite.reporting.pages, "draw_curves", second_fails)
    monkeypatch.chdir(tmp_path)
    before = _files(tmp_path)
    assert main(["leaderboard", str(runs), str(runs), "--page", "docs/results.md"]) == 2
    assert _files(tmp_path) == before


@pytest.mark.parametrize("args, problem", [
    (["--out", "a-file"], "--out a-file is a file, not a directory: give a directory to write in"),
    (["--out", "a-file/board"], "--out a-file/board: a-file/board cannot be made: a-file is a file"),
    (["--page", "a-dir"], "--page a-dir is a directory, not a file: give the file to write, e.g. a-dir/results.md"),
    (["--page", "new/"], "--page new/ names a directory, not a file: give the file to write, e.g. new/results.md"),
    (["--page", "a-file/results.md"], "--page a-file/results.md: a-file is a file, not a directory"),
    (["--reproduction", "a-dir"], "--reproduction a-dir is a directory, not a file: give the file to write, e.g. "
                                  "a-dir/reproduction.md"),
])
def test_a_path_that_cannot_be_written_is_named_by_its_flag_before_anything_is_read(
        tmp_path, monkeypatch, capsys, args, problem):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a-file").write_text("kept as it was")
    (tmp_path / "a-dir").mkdir()
    (tmp_path / "a-dir" / "notes.md").write_text("kept as it was")
    before = _files(tmp_path)
    # RUNS does not exist: the path is refused first, before any run is read
    assert main(["leaderboard", "no-such-runs", *args]) == 2
    [line] = capsys.readouterr().err.splitlines()
    assert line.startswith("craftsuite leaderboard: error: ") and problem in line
    assert "Errno" not in line
    assert _files(tmp_path) == before  # no image in the working directory, nothing replaced
    assert (tmp_path / "a-file").read_text() == "kept as it was"


def test_a_page_in_a_folder_that_cannot_be_written_is_named(runs, tmp_path, monkeypatch, capsys):
    import craftsuite.files

    locked = tmp_path / "locked"
    locked.mkdir()
    # (no chmod: the tests may run as root, who writes anywhere)
    monkeypatch.setattr(craftsuite.files.os, "access", lambda path, mode: Path(path) != locked)
    assert main(["leaderboard", str(runs), "--page", str(locked / "results.md")]) == 2
    assert f"{locked} is not writable here; give a directory you can write in" in capsys.readouterr().err
    assert not any(locked.iterdir())

def test_a_good_page_path_still_writes_the_page_and_its_images(runs, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["leaderboard", str(runs), "--page", "docs/results.md"]) == 0
    assert (tmp_path / "docs" / "results.md").is_file()
    assert {p.name for p in (tmp_path / "docs" / "images").rglob("*.png")} == {
        "profile-Cont-one-step.png", "curves-BlindCraftsman-Cont.png"}


def test_a_directory_given_as_the_page_draws_no_image_into_the_working_directory(runs, tmp_path, monkeypatch,
                                                                                  capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "docs").mkdir()
    before = _files(tmp_path)
    assert main(["leaderboard", str(runs), "--page", "docs"]) == 2
    assert "--page docs is a directory, not a file" in capsys.readouterr().err
    assert _files(tmp_path) == before  # no images/ beside it
