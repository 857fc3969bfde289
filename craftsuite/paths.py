"""Where CraftSuite's data lives: the one place that knows the repo and wheel layouts, the
cache's folder, and which files make up the package (``code_digest``).

In a wheel, ``tasks/`` and ``assets/`` are shipped as ``craftsuite/_data/{tasks,assets}``
(hatchling force-include); in a source checkout they sit at the top of the repo.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent
# the data the package reads beside its code: a copy of the package is these and craftsuite/
DATA_DIRS = ("tasks", "assets")


def data_dir(name: str) -> Path:
    """The directory of ``tasks`` or ``assets`` (``DATA_DIRS``), installed or in the checkout."""
    for candidate in (_PACKAGE / "_data" / name, _PACKAGE.parent / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(
        f"CraftSuite's {name}/ directory is missing (looked in {_PACKAGE / '_data'} and "
        f"{_PACKAGE.parent}); reinstall the package"
    )


def tasks_dir() -> Path:
    return data_dir("tasks")


def assets_dir() -> Path:
    return data_dir("assets")


def cache_dir(kind: str) -> Path:
    """Where CraftSuite keeps what it computed and can compute again (``kind``: "automata",
    "references"): $CRAFTSUITE_CACHE_DIR/kind, else the XDG cache's craftsuite/kind."""
    root = os.environ.get("CRAFTSUITE_CACHE_DIR")
    if root:
        return Path(root) / kind
    xdg = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(xdg) / "craftsuite" / kind


def files_digest(roots) -> str:
    """The sha256 of every file under ``roots`` (folders), by its path below its root and its
    bytes; Python's compiled ``__pycache__`` is left out (it follows the sources)."""
    h = hashlib.sha256()
    for root in roots:
        root = Path(root)
        for path in sorted(p for p in root.rglob("*") if p.is_file() and "__pycache__" not in p.parts):
            name = path.relative_to(root).as_posix()
            h.update(f"{root.name}/{name}\0{path.stat().st_size}\0".encode())
            h.update(path.read_bytes())
    return h.hexdigest()


def code_digest() -> str:
    """A digest of the package's code and data (craftsuite/, tasks/, assets/): a result
    computed from them alone is the same while it is."""
    roots = [_PACKAGE] + [data_dir(name) for name in DATA_DIRS if not (_PACKAGE / "_data" / name).is_dir()]
    return files_digest(roots)
