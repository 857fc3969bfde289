"""The repository's pages speak of the repository alone, and their links lead somewhere."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TEXT = ("*.md", "*.py", "*.toml", "*.ipynb", "*.sh", "Makefile")
# Pointers out of the repository: written in halves so that this file does not match itself.
OUTSIDE = ("../" + "shared", "REFERENCE" + ".md", "the " + "issue's")
README_MAX_LINES = 150
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
FENCE = re.compile(r"^```.*?^```", re.S | re.M)


def tracked(*patterns: str) -> list[str]:
    done = subprocess.run(["git", "ls-files", "-z", "--", *patterns], cwd=ROOT, capture_output=True, text=True)
    if done.returncode != 0:
        pytest.skip("not a git checkout")
    return [name for name in done.stdout.split("\0") if name]


def relative_links(text: str) -> list[str]:
    """Links to files of the repository: not URLs, not anchors on the same page; code blocks skipped."""
    links = LINK.findall(FENCE.sub("", text))
    return [link.split("#")[0] for link in links
            if not re.match(r"^[a-z][a-z0-9+.-]*:", link) and not link.startswith("#")]


def test_no_tracked_file_points_outside_the_repository():
    found = []
    for name in tracked(*TEXT):
        path = ROOT / name
        if not path.is_file():  # deleted in the working tree, not yet committed
            continue
        text = path.read_text(errors="replace")
        found += [f"{name}: {needle!r}" for needle in OUTSIDE if needle in text]
    assert not found, "files point outside the repository:\n" + "\n".join(found)


def test_readme_fits_in_150_lines():
    lines = (ROOT / "README.md").read_text().splitlines()
    assert len(lines) <= README_MAX_LINES, f"README.md has {len(lines)} lines, at most {README_MAX_LINES}"


@pytest.mark.parametrize("page", ["README.md", "experiments/README.md",
                                  *sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "docs").glob("*.md"))])
def test_every_relative_link_resolves_to_a_tracked_file(page):
    files = set(tracked())
    folders = {parent.as_posix() for name in files for parent in Path(name).parents}
    broken = []
    for link in relative_links((ROOT / page).read_text()):
        target = ((ROOT / page).parent / link).resolve()
        if not target.is_relative_to(ROOT.resolve()):
            broken.append(link)  # outside the repository
        elif target.relative_to(ROOT.resolve()).as_posix() not in files | folders:
            broken.append(link)
    assert not broken, f"{page} links to what the repository does not hold: {broken}"


def test_the_experiments_index_names_every_folder():
    index = (ROOT / "experiments" / "README.md").read_text()
    listed = {link.split("/")[0] for link in relative_links(index) if not link.startswith("..")}
    folders = {p.name for p in (ROOT / "experiments").iterdir() if p.is_dir() and (p / "README.md").exists()}
    assert listed == folders, f"unlisted: {sorted(folders - listed)}; listed but absent: {sorted(listed - folders)}"


def test_relative_links_skip_urls_anchors_and_code():
    text = "[a](docs/x.md#part) [b](https://e.org) [c](#here) ![d](images/p.png \"title\")\n```\n[e](no.md)\n```\n"
    assert relative_links(text) == ["docs/x.md", "images/p.png"]
