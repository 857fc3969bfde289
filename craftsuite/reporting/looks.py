"""How many times each comparison was read before its seeds stopped growing: its looks.

A comparison that got more seeds because an earlier reading left it undecided had more than
one chance to be decided, so intervals at 95% on its final sample claim more than they hold.
The results page reads such a comparison at ``stats.shared_level(k)`` for its k looks (1 -
0.05/k), every interval of it. Which readings were taken is a fact of the campaign, not of
the runs, so it is data, kept where the runs are: an archive's ``looks.json``, beside its
``students/`` (``results/<suite>/looks.json``), a list of items such as

    {"task": "ToolHome", "world": "Cont", "regime": "n-step-wide",
     "methods": ["td3-dynamic"], "read_at": [3, 10]}

``read_at``: the distilled side's seeds at each reading taken (in any order). A reading at
the seeds the runs have now is the page's own; each one at fewer seeds is one look more. A
comparison no item names was read once. Whoever adds seeds to a comparison because a reading
left it undecided adds that reading here.
"""

from __future__ import annotations

import json
from pathlib import Path

FILE = "looks.json"
FIELDS = {"task": str, "world": str, "regime": str, "methods": list, "read_at": list}
_READ: dict[Path, tuple[int, list[dict]]] = {}  # path -> (its mtime_ns, its items)


def read(path) -> list[dict]:
    """The items of a ``looks.json``, checked.

    Raises:
        ValueError: one line naming the file, the item and the field at fault, and the fix.
    """
    path = Path(path)
    stamp = path.stat().st_mtime_ns
    if path in _READ and _READ[path][0] == stamp:
        return _READ[path][1]
    try:
        items = json.loads(path.read_text())
    except ValueError as err:
        raise ValueError(f"{path} is not valid JSON ({err})") from None
    if not isinstance(items, list):
        raise ValueError(f"{path}: expected a list of comparisons, each "
                         f"{{{', '.join(FIELDS)}}}, got {type(items).__name__}")
    for i, item in enumerate(items):
        where = f"{path}: item {i}"
        if not isinstance(item, dict):
            raise ValueError(f"{where}: expected an object with {', '.join(FIELDS)}, got {type(item).__name__}")
        missing, unknown = [f for f in FIELDS if f not in item], sorted(set(item) - set(FIELDS))
        if missing or unknown:
            wrong = [f"no {', '.join(missing)}"] * bool(missing) + [f"unknown {', '.join(unknown)}"] * bool(unknown)
            raise ValueError(f"{where}: {'; '.join(wrong)} (an item has exactly {', '.join(FIELDS)})")
        for name, kind in FIELDS.items():
            if not isinstance(item[name], kind):
                raise ValueError(f"{where}: {name} must be a {kind.__name__}, got {item[name]!r}")
        if not item["methods"] or not all(isinstance(m, str) for m in item["methods"]):
            raise ValueError(f"{where}: methods must name the distilled methods read, got {item['methods']!r}")
        if not all(isinstance(n, int) and not isinstance(n, bool) and n > 0 for n in item["read_at"]):
            raise ValueError(f"{where}: read_at must be the seeds (whole numbers above 0) at each reading, "
                             f"got {item['read_at']!r}")
    _READ[path] = (stamp, items)
    return items


def looks(entry) -> int:
    """The readings of ``entry`` (a distilled method's ``board.Entry``) against its scratch
    counterpart: 1, and one more for each seed count below its seeds now at which the
    ``looks.json`` of an archive its runs lie in says it was read."""
    seeds = len(entry.seeds)
    earlier = set()
    for path in sorted({run.parent.parent / FILE for run in entry.runs}):
        if path.is_file():
            earlier |= {n for item in read(path) if _names(item, entry) for n in item["read_at"] if n < seeds}
    return len(earlier) + 1


def _names(item: dict, entry) -> bool:
    return ((item["task"], item["world"], item["regime"]) == (entry.task, entry.world, entry.regime)
            and entry.method in item["methods"])
