"""Where CraftSuite's data lives: the one place that knows the repo and wheel layouts.

In a wheel, ``tasks/`` and ``assets/`` are shipped as ``craftsuite/_data/{tasks,assets}``
(hatchling force-include); in a source checkout they sit at the top of the repo.
"""

from __future__ import annotations

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
