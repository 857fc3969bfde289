"""How many times each comparison was read before its seeds stopped growing: its looks.

A comparison whose verdict was read (reported) at fewer seeds before its seeds grew had more
than one chance to be decided, so intervals at 95% on its final sample claim more than they
hold. That holds whatever made the seeds grow (an undecided reading, or a seed count planned
in advance): counting every earlier reading is the conservative choice.
The results page reads such a comparison at ``stats.shared_level(k)`` for its k looks (1 -
0.05/k), every interval of it.

The readings come from two places:

* the runs' own records. Each run's ``config.json`` names the commit of the session that
  finished it (the last of its ``provenance``, which the board keeps as
  ``Entry.finished_by``); a campaign runs each part at the commit of its plan, and reads its
  page after each part. So the runs of both sides, taken commit by commit in the order those
  sessions began, give the seeds (distilled, scratch) after each part; every such state
  before today's, with runs on both sides, is a reading. Two commits
  with no reading between them count twice: conservative again. A commit and the same one
  marked ``-dirty`` are one part (archiving a part's first runs dirties the tree for the
  rest); runs that name no commit are one part between them;
* ``looks.json``, beside an archive's ``students/`` (``results/<suite>/looks.json``), for a
  reading the records cannot show (a page read part way through a part), a list of items
  such as

    {"task": "ToolHome", "world": "Cont", "regime": "n-step-wide", "budget": 250000,
     "methods": ["td3-dynamic"], "read_at": [3, 10]}

  An item names one setting of the distilled methods (the task, the world's name, the
  learner regime and the transitions per run) and the distilled side's seeds at each
  reading. A count below the seeds the entry has today adds a reading, unless the records
  or a pair already give one at that count; one at or above them is of runs not here. Any
  reading may instead be named by both sides' seeds, ``{"distilled": 10, "scratch": 20}``
  (by name: a bare pair would not say which side is which), and one where only the scratch
  side has grown since (the distilled side then as today) must be: a pair adds a reading
  unless it is today's or the records' own, or either side is above today's. An
  entry pooled from several archives counts the items of each. An item that names no runs of its
  archive is refused (``check``), so a misspelt name cannot pass for a reading.

The count (``looks``) is those readings and the page's own. A comparison whose runs name no
commit (a transfer outside a checkout, an entry built by hand) and that no item names was
read once.
"""

from __future__ import annotations

import json
from pathlib import Path

FILE = "looks.json"
FIELDS = {"task": str, "world": str, "regime": str, "budget": int, "methods": list, "read_at": list}
KINDS = {str: "a text", int: "a whole number", list: "a list"}
SIDES = ("distilled", "scratch")  # a reading named by both sides' seeds: an object with these keys
PAIR = json.dumps(dict(zip(SIDES, (10, 20))))
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
        for n in item["read_at"]:
            if isinstance(n, list) and len(n) == 2 and all(map(_seeds, n)):
                raise ValueError(f"{where}: read_at's reading {json.dumps(n)} does not say which side is which; "
                                 f"write it {json.dumps(dict(zip(SIDES, n)))}")
        if not item["read_at"] or not all(_seeds(n) or _pair(n) for n in item["read_at"]):
            raise ValueError(f"{where}: read_at must list the seeds (whole numbers above 0) at each reading, the "
                             f'distilled side\'s or both sides\' by name, got {json.dumps(item["read_at"])} '
                             f'(e.g. "read_at": [5, 10] or [{PAIR}])')
    return items


def _seeds(n) -> bool:
    return isinstance(n, int) and not isinstance(n, bool) and n > 0


def _pair(n) -> bool:
    """Whether ``n`` names a reading by both sides' seeds, ``{"distilled": 10, "scratch": 20}``."""
    return isinstance(n, dict) and set(n) == set(SIDES) and all(_seeds(n[side]) for side in SIDES)


def readings(entry, baseline) -> list[tuple[int, int | None]]:
    """The seeds (distilled, scratch) at each reading of ``entry`` (a distilled method's
    ``board.Entry``) against ``baseline`` (its scratch counterpart), the page's own last; a
    reading ``looks.json`` names by the distilled side's seeds alone has None for the scratch
    side (the module's docstring says which readings count)."""
    now = (len(entry.seeds), len(baseline.seeds))
    recorded = [state for state in _parts(entry, baseline) if state != now]
    named = [n for path in _paths(entry) for item in read(path) if _names(item, entry) for n in item["read_at"]]
    pairs = {tuple(n[side] for side in SIDES) for n in named if isinstance(n, dict)}
    pairs = {n for n in pairs if n[0] <= now[0] and n[1] <= now[1] and n != now and n not in recorded}
    known = {x for x, _ in recorded} | {x for x, _ in pairs}
    counts = {n for n in named if isinstance(n, int) and n < now[0] and n not in known}
    return sorted(recorded + list(pairs) + [(n, None) for n in counts], key=lambda s: (s[0], s[1] or 0)) + [now]


def looks(entry, baseline) -> int:
    """How many times ``entry`` was read against ``baseline``: ``len(readings(...))``."""
    return len(readings(entry, baseline))


def _parts(entry, baseline) -> list[tuple[int, int]]:
    """The seeds (distilled, scratch) after each commit's runs of either side, in the order
    those sessions began, where both sides had runs: each a state the page was read at."""
    finished = {}  # part -> [when its first session began, distilled runs, scratch runs]
    for side, sessions in enumerate((entry.finished_by, baseline.finished_by)):
        for session in sessions:
            at = session.get("at") or ""
            part = finished.setdefault(_part(session), [at, 0, 0])
            part[0] = min(part[0], at)
            part[1 + side] += 1
    states, x, y = [], 0, 0
    for _, dx, dy in sorted(finished.values()):
        x, y = x + dx, y + dy
        if x and y:
            states.append((x, y))
    return states


def _part(session: dict) -> str | None:
    """The part of the campaign a run's finishing session belongs to: its commit, as the
    first 7 digits (records name 8, 10 or 40) and without ``-dirty`` (archiving a part's
    first runs changes tracked files under ``results/``, so the rest of the same part can
    name the commit dirty; runs on a tree changed before they began would merge into the
    commit's part too, which a campaign avoids by committing each plan before its runs).
    Runs that name no commit (trained outside a checkout) are one part: their records stamp
    each run, not each session, so nothing tells their sessions apart."""
    commit = session.get("commit")
    return commit.removesuffix("-dirty")[:7] if commit else None


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
