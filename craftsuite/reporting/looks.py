"""How many times each comparison was read before its seeds stopped growing: its looks.

A comparison whose verdict was read (reported) at fewer seeds before its seeds grew had more
than one chance to be decided, so intervals at 95% on its final sample claim more than they
hold. That holds whatever made the seeds grow (an undecided reading, or a seed count planned
in advance): counting every earlier reading is the conservative choice.
The results page reads such a comparison at ``stats.shared_level(k)`` for its k looks (1 -
0.05/k), every interval of it. Which readings were taken is a fact of the campaign, not of
the runs, so it is data, kept where the runs are: an archive's ``looks.json``, beside its
``students/`` (``results/<suite>/looks.json``), a list of items such as

    {"task": "ToolHome", "world": "Cont", "regime": "n-step-wide", "budget": 250000,
     "methods": ["td3-dynamic"], "read_at": [3, 10]}

An item names one setting of the distilled methods (the task, the world's name, the learner
regime and the transitions per run) and the distilled side's seeds at each reading taken.
Whoever adds seeds to a comparison that was read before adds that reading here.

The count (``looks``): 1, for the reading the page takes, and one more for each seed count
named below the seeds the entry has (a reading at the entry's seeds is the page's own; one
above them is of runs not here). An entry pooled from several archives counts the readings
named in any of them. A comparison no item names, or whose runs lie in no archive (a
transfer's output, an entry built by hand), was read once. An item that names no runs of
its archive is refused (``check``), so a misspelt name cannot pass for a reading.
"""

from __future__ import annotations

import json
from pathlib import Path

FILE = "looks.json"
FIELDS = {"task": str, "world": str, "regime": str, "budget": int, "methods": list, "read_at": list}
KINDS = {str: "a text", int: "a whole number", list: "a list"}
EXAMPLE = ('{"task": "ToolHome", "world": "Cont", "regime": "n-step-wide", "budget": 250000, '
           '"methods": ["td3-dynamic"], "read_at": [5, 10]}')


def read(path) -> list[dict]:
    """The items of a ``looks.json``, checked.

    Raises:
        ValueError: one line naming the file, the item and the field at fault, and the fix.
    """
    path = Path(path)
    try:
        items = json.loads(path.read_text())
    except ValueError as err:
        raise ValueError(f"{path} is not valid JSON ({err}); fix it, or delete the file if no comparison "
                         "was read more than once") from None
    if not isinstance(items, list):
        raise ValueError(f"{path}: expected a list of comparisons such as {EXAMPLE}, got {type(items).__name__}")
    for i, item in enumerate(items):
        where = f"{path}: item {i}"
        if not isinstance(item, dict):
            raise ValueError(f"{where}: expected an object such as {EXAMPLE}, got {type(item).__name__}")
        missing, unknown = [f for f in FIELDS if f not in item], sorted(set(item) - set(FIELDS))
        if missing or unknown:
            wrong = [f"no {', '.join(missing)}"] * bool(missing) + [f"unknown {', '.join(unknown)}"] * bool(unknown)
            raise ValueError(f"{where}: {'; '.join(wrong)} (an item has exactly {', '.join(FIELDS)}, e.g. {EXAMPLE})")
        for name, kind in FIELDS.items():
            if not isinstance(item[name], kind) or isinstance(item[name], bool):
                raise ValueError(f"{where}: {name} must be {KINDS[kind]}, got {item[name]!r} (e.g. {EXAMPLE})")
        if not item["methods"] or not all(isinstance(m, str) for m in item["methods"]):
            raise ValueError(f"{where}: methods must name the distilled methods read, got {item['methods']!r} "
                             '(e.g. "methods": ["td3-dynamic"])')
        if not item["read_at"] or not all(isinstance(n, int) and not isinstance(n, bool) and n > 0
                                          for n in item["read_at"]):
            raise ValueError(f"{where}: read_at must list the seeds (whole numbers above 0) at each reading, got "
                             f'{item["read_at"]!r} (e.g. "read_at": [5, 10])')
    return items


def readings(entry) -> list[int]:
    """The seed counts at which ``entry`` (a distilled method's ``board.Entry``) was read
    against its scratch counterpart, the page's own reading last (the module's docstring
    says which count)."""
    seeds = len(entry.seeds)
    items = [item for path in _paths(entry) for item in read(path) if _names(item, entry)]
    return sorted({n for item in items for n in item["read_at"] if n < seeds}) + [seeds]


def looks(entry) -> int:
    """How many times ``entry`` was read: ``len(readings(entry))``."""
    return len(readings(entry))


def check(entries) -> None:
    """Refuse a ``looks.json`` item that names no runs of ``entries`` (a board's, of every
    archive they lie in), or names a method that is not distilled.

    Raises:
        ValueError: one line naming the file, the item and what it names.
    """
    from ..methods import is_distilled

    by_path: dict[Path, list] = {}
    for e in entries:
        for path in _paths(e):
            by_path.setdefault(path, []).append(e)
    for path, mine in sorted(by_path.items()):
        for i, item in enumerate(read(path)):
            named = f"{item['task']} in {item['world']}, {item['regime']}, {item['budget']:,} transitions"
            for method in item["methods"]:
                if not is_distilled(method):
                    raise ValueError(f"{path}: item {i}: {method!r} is not a distilled method; name the distilled "
                                     "side of the comparison read")
                if not any(_names(item, e) and e.method == method for e in mine):
                    raise ValueError(f"{path}: item {i} names no runs of {method} ({named}) under "
                                     f"{path.parent / 'students'}; fix the name or remove the item")


def _paths(entry) -> list[Path]:
    """The ``looks.json`` of every archive ``entry``'s runs lie in (``<archive>/students/<run>``)."""
    return [path for archive in sorted({run.parent.parent for run in entry.runs})
            if (path := archive / FILE).is_file()]


def _names(item: dict, entry) -> bool:
    return ((item["task"], item["world"], item["regime"], item["budget"])
            == (entry.task, entry.world, entry.regime, entry.budget) and entry.method in item["methods"])
