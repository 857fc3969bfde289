"""Task specs: a task's objective, objects and rules as data (TOML files in ``tasks/``).

A spec says everything a world needs and nothing about how a world looks: which items lie
on the map and how many, which places act on arrival, which recipes turn inventory into
other inventory, what each proposition of the LTLf objective means, the rewards, and the
grid sizes. The grid and MuJoCo worlds both read the same spec; neither restates it.

Format (see ``tasks/blind_craftsman.toml`` for a full example)::

    name = "BlindCraftsman"          # CamelCase; ids are CraftSuite/<name>-Grid<size>-v0
    formula = "G(wood -> F factory) & F(tools3 & home)"
    tags = ["paper", "hard"]         # optional: rungs of the ladder (craftsuite tasks --tag hard)
    extends = "other_spec"           # optional: start from tasks/other_spec.toml (all but its tags)

    [propositions]                   # bit order = order written here
    wood = { obtained = "wood" }     # event: inventory count of wood went up this step
    factory = { arrived = "factory" }# event: the agent entered a factory this step
    tools3 = { at_least = { tools = 3 } }   # level: holding >= 3 tools
    gold1 = { reached = { gold = 1 } }      # event: gold count went up to exactly 1
    silver1 = { exactly = { silver = 1 } }  # level: holding exactly 1 silver

    [items.wood]                     # picked up by stepping on it
    count = 3                        # how many on the map
    reward = 1.0                     # per pickup (default 1.0)
    capacity = 2                     # carry at most this many (default: no limit)
    requires = { pickaxe = 1 }       # cannot be picked up without (default: nothing)
    excludes = ["gold"]              # cannot be picked up while holding any of these

    [places.factory]                 # stays on the map, acts on arrival
    count = 1
    placement = "corner"             # "random" (default) or "corner" (top-left cell)
    kinematic = { reward = 1.0 }     # the kinematic board's tile (all keys optional; items too):
                                     # requires, reward, consumable, ends_episode, label

    [[recipes]]                      # at = a place (on arrival) or omitted (anywhere,
    at = "factory"                   # checked after every pickup)
    consume = { wood = 1 }
    produce = { tools = 1 }
    repeat = true                    # apply as often as the inventory allows

    [rewards]
    step = -0.1
    completion = 100.0

    [grid]
    sizes = [7, 10]
    max_steps = 500
    obstacles = [[3, 5], [3, 4]]     # impassable cells as [x, y] of the largest grid size

    [continuous]                     # the MuJoCo world (all keys optional)
    arena = 7.0                      # side of the square arena
    pickup_radius = 0.4              # an object is touched within this distance
    boundary_reward = -0.1           # per step of pushing against the boundary
    control_period = 0.25            # seconds each action is held (whole physics steps of 0.025 s)
    max_steps = 200                  # decisions per episode
"""

from __future__ import annotations

import math
import os
import re
import tomllib
from dataclasses import dataclass, field, fields, is_dataclass
from functools import cache, cached_property
from pathlib import Path
from typing import Any

from .automata import Automaton, LTLfSyntaxError, compile_ltlf, parse
from .automata.ltlf import atoms
from .ids import TASK_NAME
from .names import unknown_text
from .paths import assets_dir, tasks_dir

__all__ = [
    "LEVELS", "SpecError", "TaskSpec", "Item", "Place", "BoardTile", "Recipe", "Proposition", "GridConfig",
    "ContinuousConfig",
    "load_spec", "builtin_specs",
]


# Difficulty tags, easiest first: the ladder's order. "calibration" marks the rung every
# algorithm should pass before its results above mean anything; "paper", the paper's tasks.
LEVELS = ("easy", "medium", "hard")


class SpecError(ValueError):
    """A task spec that cannot be used; the message names the file, the field and the problem."""


@dataclass(frozen=True)
class BoardTile:
    """How an object acts on the kinematic board, which follows the authors' tiles
    (``MineWorldTileType``): on every step the agent is within reach and the inventory meets
    ``requires`` (and the tile's change leaves no count negative), the tile applies its
    change, pays ``reward``, leaves the board if ``consumable`` and ends the episode if
    ``ends_episode``. ``label``: ``"acts"`` (an ``arrived`` proposition of a place is true on
    the steps it acts) or ``"cell"`` (true while the agent's position, truncated to
    integers, is the place's cell: the authors' ``at_home``). None fields take the object's
    defaults: an item is consumable, needs its ``requires``, pays its ``reward``; a place
    stays, needs nothing, pays 0. The grid and MuJoCo worlds ignore this table."""

    requires: dict[str, int] | None = None
    reward: float | None = None
    consumable: bool | None = None
    ends_episode: bool = False
    label: str = "acts"


@dataclass(frozen=True)
class Item:
    name: str
    count: int
    reward: float = 1.0
    capacity: int | None = None
    requires: dict[str, int] = field(default_factory=dict)
    excludes: tuple[str, ...] = ()
    color: str = "#888888"
    symbol: str = "?"
    kinematic: BoardTile = BoardTile()


@dataclass(frozen=True)
class Place:
    name: str
    count: int = 1
    placement: str = "random"
    color: str = "#888888"
    symbol: str = "?"
    kinematic: BoardTile = BoardTile()


@dataclass(frozen=True)
class Recipe:
    consume: dict[str, int]
    produce: dict[str, int]
    at: str | None = None
    repeat: bool = False


@dataclass(frozen=True)
class Proposition:
    """What makes one atomic proposition true after a step.

    kind: ``obtained`` (event: ``subject``'s count went up), ``arrived`` (event: entered
    a ``subject`` place), ``at_least`` (level: count of ``subject`` >= ``value``),
    ``exactly`` (level: count of ``subject`` == ``value``) or ``reached`` (event: count of
    ``subject`` went up to exactly ``value``).
    """

    name: str
    kind: str
    subject: str
    value: int = 0


@dataclass(frozen=True)
class GridConfig:
    sizes: tuple[int, ...] = (7, 10)
    max_steps: int = 500
    obstacles: tuple[tuple[int, int], ...] = ()


@dataclass(frozen=True)
class ContinuousConfig:
    """The MuJoCo world of a task; obstacles come from ``GridConfig`` (scaled to the arena).

    The default control period, 0.25 s, puts a decision on the grid teacher's time scale
    (about 14 decisions to cross the arena, as a 7x7 grid is crossed in 6 moves): every
    TD3 student that learned a task here learned it at this period, none at 0.05 s.
    """

    arena: float = 7.0
    pickup_radius: float = 0.4
    boundary_reward: float = -0.1
    control_period: float = 0.25  # seconds each action is held
    max_steps: int = 200  # decisions per episode: 50 s at the default period

    def frame_skip(self, timestep: float | None = None) -> int:
        """Physics steps per decision: the control period over the physics step (by default
        ``assets/arena.xml``'s), which must divide it.

        Raises:
            ValueError: the period is not a whole number of physics steps.
        """
        step = physics_timestep() if timestep is None else timestep
        skip = round(self.control_period / step)
        if skip < 1 or abs(skip * step - self.control_period) > 1e-9:
            raise ValueError(f"{self.control_period} s is not a whole number of physics steps of {step} s "
                             f"(e.g. {max(1, skip) * step:g})")
        return skip


@dataclass(frozen=True)
class KinematicConfig:
    """The kinematic world's own values, the authors' (their ``MineWorldEnvContinuous`` in
    ``discrete/lib/env/mineworldenv.py``, adenm-10/Automaton_Distillation): a full action moves
    the agent ``step`` board units, and an episode lasts ``max_steps`` steps. The board side,
    pickup radius and off-board penalty are ``ContinuousConfig``'s, which equal theirs.
    The same for every task (theirs are), hence no spec section."""

    step: float = 3.0
    max_steps: int = 1000


KINEMATIC_CONFIG = KinematicConfig()


@cache
def physics_timestep() -> float:
    """The MuJoCo worlds' physics step in seconds, as ``assets/arena.xml`` sets it; read
    without MuJoCo, so that a spec's control period is checked when the spec loads."""
    from xml.etree import ElementTree

    return float(ElementTree.parse(assets_dir() / "arena.xml").getroot().find("option").get("timestep"))


@dataclass(frozen=True)
class TaskSpec:
    name: str
    formula: str
    propositions: tuple[Proposition, ...]
    items: tuple[Item, ...]
    places: tuple[Place, ...]
    recipes: tuple[Recipe, ...]
    step_reward: float
    completion_reward: float
    grid: GridConfig
    continuous: ContinuousConfig = ContinuousConfig()
    description: str = ""
    tags: tuple[str, ...] = ()  # rungs of the ladder: difficulty ("easy", ...), "paper", ...
    path: Path | None = None

    @property
    def level(self) -> str | None:
        """The spec's difficulty: the first of its tags among ``LEVELS`` (None: untagged)."""
        return next((t for t in self.tags if t in LEVELS), None)

    @property
    def rung(self) -> tuple:
        """Sort key of the ladder: by level, calibration tasks first within one, then by name."""
        level = LEVELS.index(self.level) if self.level else len(LEVELS)
        return level, "calibration" not in self.tags, self.name

    @property
    def proposition_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.propositions)

    @property
    def objects(self) -> tuple[Item | Place, ...]:
        """Everything that is placed on the map, items first: index = object kind."""
        return self.items + self.places

    @property
    def inventory(self) -> tuple[str, ...]:
        """Inventory slots: every item, then everything recipes produce, in spec order."""
        names = [i.name for i in self.items]
        for r in self.recipes:
            names += [n for n in r.produce if n not in names]
        return tuple(names)

    @cached_property
    def automaton(self) -> Automaton:
        """The formula's DFA.

        Raises:
            SpecError: the objective can never be satisfied (no accepting state is reachable
                from the initial one), naming the file.
        """
        automaton = compile_ltlf(self.formula, self.proposition_names)
        if not automaton.satisfiable:
            raise SpecError(f"{self.path or f'task spec {self.name!r}'}: formula: {self.formula!r} can never be "
                            "satisfied (its automaton reaches no accepting state); no episode could succeed: "
                            "change the objective")
        return automaton

    def digest(self) -> str:
        """A short hash of the rules: everything that changes what an agent experiences, not
        the description, tags, file, colours or symbols. Runs record it and hash it into
        their run key, so a run made under other rules is never reused."""
        return self._digest

    def to_data(self) -> dict:
        """The spec as the plain data of its TOML file (``extends`` resolved, every default
        written out): ``load_spec(spec.to_data())`` rebuilds an equal spec (but for ``path``).
        JSON-ready, so a spec travels in a gymnasium ``EnvSpec`` or to a worker process.
        Proposition order is bit order: keep the tables' key order (JSON does)."""

        def proposition(p: Proposition) -> dict:
            return {p.kind: {p.subject: p.value} if p.kind in COUNTED else p.subject}

        def tile(t: BoardTile) -> dict:
            out = {"ends_episode": t.ends_episode, "label": t.label}
            for key in ("requires", "reward", "consumable"):
                if getattr(t, key) is not None:
                    out[key] = dict(t.requires) if key == "requires" else getattr(t, key)
            return out

        def item(i: Item) -> dict:
            out = {"count": i.count, "reward": i.reward, "requires": dict(i.requires), "excludes": list(i.excludes),
                   "color": i.color, "symbol": i.symbol, "kinematic": tile(i.kinematic)}
            return out if i.capacity is None else {**out, "capacity": i.capacity}

        def recipe(r: Recipe) -> dict:
            out = {"consume": dict(r.consume), "produce": dict(r.produce), "repeat": r.repeat}
            return out if r.at is None else {**out, "at": r.at}

        return {
            "name": self.name, "formula": self.formula, "description": self.description, "tags": list(self.tags),
            "propositions": {p.name: proposition(p) for p in self.propositions},
            "items": {i.name: item(i) for i in self.items},
            "places": {p.name: {"count": p.count, "placement": p.placement, "color": p.color, "symbol": p.symbol,
                                "kinematic": tile(p.kinematic)}
                       for p in self.places},
            "recipes": [recipe(r) for r in self.recipes],
            "rewards": {"step": self.step_reward, "completion": self.completion_reward},
            "grid": {"sizes": list(self.grid.sizes), "max_steps": self.grid.max_steps,
                     "obstacles": [list(c) for c in self.grid.obstacles]},
            "continuous": {f.name: getattr(self.continuous, f.name) for f in fields(self.continuous)},
        }

    @cached_property
    def _digest(self) -> str:  # a spec is frozen: its rules hash once
        import hashlib
        import json

        looks = ("description", "tags", "path", "color", "symbol")  # fields that change no rule

        def rules(value):
            if is_dataclass(value):
                return {f.name: rules(getattr(value, f.name)) for f in fields(value) if f.name not in looks}
            if isinstance(value, dict):
                return {k: rules(v) for k, v in value.items()}
            if isinstance(value, (list, tuple)):
                return [rules(v) for v in value]
            return value

        return hashlib.sha256(json.dumps(rules(self), sort_keys=True).encode()).hexdigest()[:12]


# proposition kinds whose argument is one inventory count, { name = k }
COUNTED = ("at_least", "exactly", "reached")

# Readable defaults for objects a spec gives no colour; the paper's Figure 1c colours first.
_PALETTE = ["#8b5a2b", "#d9822b", "#3d7dd8", "#7b4fb5", "#2ca58d", "#d64550", "#e0c341",
            "#5c6b73", "#9bc53d", "#f28ab2"]
_NAME = re.compile(r"[a-z_][a-z0-9_]*\Z")
_COLOR = re.compile(r"#[0-9a-fA-F]{6}\Z")
_TOP_KEYS = {"name", "formula", "description", "tags", "extends", "propositions", "items", "places",
             "recipes", "rewards", "grid", "continuous"}


class _Reader:
    """Validating accessors that know where in which file they are."""

    def __init__(self, path: Path | str):
        self.path = path

    def fail(self, where: str, problem: str):
        raise SpecError(f"{self.path}: {where}: {problem}")

    def table(self, data: Any, where: str) -> dict:
        if not isinstance(data, dict):
            self.fail(where, f"must be a table, got {type(data).__name__}")
        return data

    def keys(self, data: dict, allowed: set[str], where: str):
        unknown = set(data) - allowed
        if unknown:
            self.fail(where, unknown_text("key", sorted(unknown), sorted(allowed)))

    def int(self, data: dict, key: str, where: str, default=None, minimum: int = 0) -> int:
        value = data.get(key, default)
        if value is None:
            self.fail(f"{where}.{key}", "is required")
        if not isinstance(value, int) or isinstance(value, bool):
            self.fail(f"{where}.{key}", f"must be an integer, got {value!r}")
        if value < minimum:
            self.fail(f"{where}.{key}", f"must be >= {minimum}, got {value}")
        return value

    def float(self, data: dict, key: str, where: str, default: float) -> float:
        value = data.get(key, default)
        # finite: TOML reads inf, which a return, a size or a period cannot be (a spec's data is JSON, too)
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
            self.fail(f"{where}.{key}", f"must be a finite number, got {value!r}")
        return float(value)

    def str(self, data: dict, key: str, where: str, default=None) -> str:
        value = data.get(key, default)
        if not isinstance(value, str):
            self.fail(f"{where}.{key}", f"must be a string, got {value!r}")
        return value

    def counts(self, data: Any, where: str, known: set[str]) -> dict[str, int]:
        data = self.table(data, where)
        for name, n in data.items():
            if name not in known:
                self.fail(where, unknown_text("inventory name", name, sorted(known)))
            if not isinstance(n, int) or isinstance(n, bool) or n < 1:
                self.fail(f"{where}.{name}", f"must be a positive integer, got {n!r}")
        return dict(data)


def _merge(base: dict, override: dict) -> dict:
    out = dict(base)
    for k, v in override.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def _read_toml(path: Path) -> dict:
    if path.is_dir():
        raise SpecError(f"{path}: is a directory; give a task spec file in it (path/to/task.toml)")
    if not path.is_file():
        raise SpecError(f"{path}: no such task spec file")
    try:
        with path.open("rb") as f:
            data = tomllib.load(f)
    except tomllib.TOMLDecodeError as err:
        raise SpecError(f"{path}: not valid TOML: {err}") from None
    if not data:
        raise SpecError(f"{path}: is empty; a task spec needs at least name, formula and [propositions] "
                        "(see the specs in tasks/)")
    return data


def _raw(path: Path, seen: tuple[Path, ...] = ()) -> dict:
    data = _read_toml(path)
    base = data.pop("extends", None)
    if base is None:
        return data
    if not isinstance(base, str):
        raise SpecError(f"{path}: extends: must be a spec file name, got {base!r}")
    base_path = (path.parent / base).with_suffix(".toml")
    if base_path.resolve() in seen:
        raise SpecError(f"{path}: extends: {base!r} extends itself (cycle)")
    inherited = _raw(base_path, seen + (path.resolve(),))
    inherited.pop("tags", None)  # a variant is not on its base's rung (nor in its suites) unless it says so
    return _merge(inherited, data)


def load_spec(source: str | Path | dict, *, name_hint: str = "<dict>") -> TaskSpec:
    """Load and validate a task spec from a TOML file (or an already-parsed dict).

    Raises:
        SpecError: naming the file, the field and the problem.
    """
    if isinstance(source, dict):
        path, data = name_hint, dict(source)
        if "extends" in data:  # a file's base is found beside it; data has no folder
            raise SpecError(f"{name_hint}: extends: a spec given as data has no folder to find "
                            f"{data['extends']!r} in: load it from its file, beside its base")
    elif isinstance(source, str) and "\n" in source:  # (pathlib would say the file name is too long)
        raise SpecError("a task spec is given as its file's path or its data, got TOML text: give "
                        "tomllib.loads(text), or write it to a .toml file")
    elif isinstance(source, (str, os.PathLike)):
        path = Path(source)
        data = _raw(path)
    else:
        raise SpecError(f"a task spec is given as its file's path or its data (a dict), got {type(source).__name__}")
    return _build(_Reader(path), data, path if isinstance(path, Path) else None)


def _build(r: _Reader, data: dict, path: Path | None) -> TaskSpec:
    """A spec from its TOML data, one section at a time, in the order sections refer to
    one another: objects, then the inventory they and the recipes make, then what refers
    to inventory names (items' rules, recipes, propositions), then the formula and worlds."""
    r.keys(data, _TOP_KEYS, "top level")
    name = r.str(data, "name", "top level")
    if not TASK_NAME.match(name):
        r.fail("name", f"must be CamelCase letters and digits (e.g. 'BlindCraftsman'), got {name!r}")
    raw_items, raw_places = _object_tables(r, data)
    raw_recipes, inventory = _inventory(r, data, raw_items)
    looks = _Looks(r)
    items = _items(r, raw_items, inventory, looks)
    places = _places(r, raw_places, looks, inventory)
    recipes = _recipes(r, raw_recipes, raw_places, inventory)
    props = _propositions(r, data, raw_places, inventory)
    formula = _formula(r, data, props)
    rewards = r.table(data.get("rewards", {}), "rewards")
    r.keys(rewards, {"step", "completion"}, "rewards")
    n_objects = sum(i.count for i in items) + sum(p.count for p in places)
    grid = _grid(r, data, n_objects, corner=any(p.placement == "corner" for p in places))
    continuous = _continuous(r, data, n_objects)
    description = data.get("description", "")
    if not isinstance(description, str):
        r.fail("description", "must be a string")
    tags = _tags(r, data)
    return TaskSpec(
        name=name, formula=formula, propositions=props, items=items, places=places, recipes=recipes,
        step_reward=r.float(rewards, "step", "rewards", -0.1),
        completion_reward=r.float(rewards, "completion", "rewards", 100.0),
        grid=grid, continuous=continuous, description=description.strip(), tags=tags, path=path,
    )


class _Looks:
    """Colours and symbols of the objects: defaults from the palette and the name's first
    letter, no symbol used twice (a grid's text view would confuse them)."""

    def __init__(self, r: _Reader):
        self.r, self.palette, self.symbols = r, iter(_PALETTE * 4), {}

    def __call__(self, table: dict, where: str, obj_name: str) -> tuple[str, str]:
        r = self.r
        color = r.str(table, "color", where, default=next(self.palette))
        if not _COLOR.match(color):
            r.fail(f"{where}.color", f"must look like '#rrggbb', got {color!r}")
        symbol = r.str(table, "symbol", where, default=obj_name[0])
        if len(symbol) != 1 or symbol in ".#@":
            r.fail(f"{where}.symbol", f"must be one character other than '.', '#', '@', got {symbol!r}")
        if symbol in self.symbols:
            r.fail(f"{where}.symbol", f"{symbol!r} is already used by {self.symbols[symbol]!r}; set another")
        self.symbols[symbol] = obj_name
        return color, symbol


def _object_tables(r: _Reader, data: dict) -> tuple[dict, dict]:
    """The [items] and [places] tables, their names checked."""
    raw_items = r.table(data.get("items", {}), "items")
    raw_places = r.table(data.get("places", {}), "places")
    for obj in (*raw_items, *raw_places):
        if not _NAME.match(obj):
            r.fail(f"items/places.{obj}", "names must be lower-case identifiers")
    both = set(raw_items) & set(raw_places)
    if both:
        r.fail("places", f"{', '.join(sorted(both))} declared both as item and place")
    if not raw_items and not raw_places:
        r.fail("items", "a task needs at least one item or place")
    return raw_items, raw_places


def _inventory(r: _Reader, data: dict, raw_items: dict) -> tuple[list, set[str]]:
    """The [[recipes]] array and the inventory names: the items and all recipes produce."""
    raw_recipes = data.get("recipes", [])
    if not isinstance(raw_recipes, list):
        r.fail("recipes", "must be an array of tables ([[recipes]])")
    produced = set()
    for i, rec in enumerate(raw_recipes):
        rec = r.table(rec, f"recipes[{i}]")
        for n in r.table(rec.get("produce", {}), f"recipes[{i}].produce"):
            if not _NAME.match(n):
                r.fail(f"recipes[{i}].produce", f"{n!r} is not a lower-case identifier")
            produced.add(n)
    return raw_recipes, set(raw_items) | produced


def _items(r: _Reader, raw_items: dict, inventory: set[str], looks: _Looks) -> tuple[Item, ...]:
    items = []
    for obj, table in raw_items.items():
        where = f"items.{obj}"
        table = r.table(table, where)
        r.keys(table, {"count", "reward", "capacity", "requires", "excludes", "color", "symbol", "kinematic"}, where)
        excludes = table.get("excludes", [])
        if not isinstance(excludes, list) or any(e not in inventory for e in excludes):
            r.fail(f"{where}.excludes",
                   f"must list inventory names from {', '.join(sorted(inventory))}, got {excludes!r}")
        capacity = table.get("capacity")
        if capacity is not None:
            capacity = r.int(table, "capacity", where, minimum=1)
        color, symbol = looks(table, where, obj)
        items.append(Item(
            name=obj,
            count=r.int(table, "count", where),
            reward=r.float(table, "reward", where, 1.0),
            capacity=capacity,
            requires=r.counts(table.get("requires", {}), f"{where}.requires", inventory),
            excludes=tuple(excludes),
            color=color, symbol=symbol,
            kinematic=_board_tile(r, table, where, inventory, place=False),
        ))
    return tuple(items)


def _board_tile(r: _Reader, table: dict, where: str, inventory: set[str], place: bool) -> BoardTile:
    """An object's ``kinematic`` table (see ``BoardTile``)."""
    where = f"{where}.kinematic"
    raw = r.table(table.get("kinematic", {}), where)
    r.keys(raw, {"requires", "reward", "consumable", "ends_episode", "label"}, where)
    for key in ("consumable", "ends_episode"):
        if key in raw and not isinstance(raw[key], bool):
            r.fail(f"{where}.{key}", f"must be true or false, got {raw[key]!r}")
    label = r.str(raw, "label", where, default="acts")
    if label not in ("acts", "cell"):
        r.fail(f"{where}.label", f"must be 'acts' or 'cell', got {label!r}")
    if label == "cell" and not place:
        r.fail(f"{where}.label", "only a place can be labelled by its cell")
    return BoardTile(
        requires=r.counts(raw["requires"], f"{where}.requires", inventory) if "requires" in raw else None,
        reward=r.float(raw, "reward", where, 0.0) if "reward" in raw else None,
        consumable=raw.get("consumable"),
        ends_episode=raw.get("ends_episode", False),
        label=label,
    )


def _places(r: _Reader, raw_places: dict, looks: _Looks, inventory: set[str]) -> tuple[Place, ...]:
    places = []
    for obj, table in raw_places.items():
        where = f"places.{obj}"
        table = r.table(table, where)
        r.keys(table, {"count", "placement", "color", "symbol", "kinematic"}, where)
        placement = r.str(table, "placement", where, default="random")
        if placement not in ("random", "corner"):
            r.fail(f"{where}.placement", f"must be 'random' or 'corner', got {placement!r}")
        count = r.int(table, "count", where, default=1)
        if placement == "corner" and count != 1:
            r.fail(f"{where}.count", "a place with placement 'corner' must have count 1")
        color, symbol = looks(table, where, obj)
        places.append(Place(name=obj, count=count, placement=placement, color=color, symbol=symbol,
                            kinematic=_board_tile(r, table, where, inventory, place=True)))
    corners = [p.name for p in places if p.placement == "corner"]
    if len(corners) > 1:
        r.fail("places", f"only one place can take the corner, got {corners}")
    return tuple(places)


def _recipes(r: _Reader, raw_recipes: list, raw_places: dict, inventory: set[str]) -> tuple[Recipe, ...]:
    recipes = []
    for i, rec in enumerate(raw_recipes):
        where = f"recipes[{i}]"
        r.keys(rec, {"at", "consume", "produce", "repeat"}, where)
        at = rec.get("at")
        if at is not None and at not in raw_places:
            r.fail(f"{where}.at", unknown_text("place", at, sorted(raw_places)))
        repeat = rec.get("repeat", False)
        if not isinstance(repeat, bool):
            r.fail(f"{where}.repeat", f"must be true or false, got {repeat!r}")
        consume = r.counts(rec.get("consume", {}), f"{where}.consume", inventory)
        produce = r.counts(rec.get("produce", {}), f"{where}.produce", inventory)
        if not consume or not produce:
            r.fail(where, "a recipe needs both 'consume' and 'produce'")
        if repeat and all(produce.get(n, 0) >= k for n, k in consume.items()):
            r.fail(f"{where}.repeat", "this recipe gives back all it consumes: repeating it would never stop")
        recipes.append(Recipe(consume=consume, produce=produce, at=at, repeat=repeat))
    return tuple(recipes)


def _propositions(r: _Reader, data: dict, raw_places: dict, inventory: set[str]) -> tuple[Proposition, ...]:
    if "propositions" not in data:
        r.fail("propositions", "is required")
    props = []
    for prop, table in r.table(data["propositions"], "propositions").items():
        where = f"propositions.{prop}"
        if not _NAME.match(prop):
            r.fail(where, "proposition names must be lower-case identifiers (e.g. 'tools3', 'gold_1')")
        table = r.table(table, where)
        if len(table) != 1:
            r.fail(where, "needs exactly one of 'obtained', 'arrived', 'at_least', 'exactly', 'reached'")
        (kind, arg), = table.items()
        if kind == "obtained":
            if arg not in inventory:
                r.fail(f"{where}.obtained", unknown_text("inventory name", arg, sorted(inventory)))
            props.append(Proposition(prop, kind, arg))
        elif kind == "arrived":
            if arg not in raw_places:
                r.fail(f"{where}.arrived", unknown_text("place", arg, sorted(raw_places)))
            props.append(Proposition(prop, kind, arg))
        elif kind in COUNTED:
            counts = r.counts(arg, f"{where}.{kind}", inventory)
            if len(counts) != 1:
                r.fail(f"{where}.{kind}", "must name exactly one inventory count, e.g. { tools = 3 }")
            (subject, value), = counts.items()
            props.append(Proposition(prop, kind, subject, value))
        else:
            r.fail(where, f"unknown kind {kind!r}; use 'obtained', 'arrived', 'at_least', 'exactly' or 'reached'")
    return tuple(props)


def _formula(r: _Reader, data: dict, props: tuple[Proposition, ...]) -> str:
    """The LTLf formula, parsed, over declared propositions only."""
    formula = r.str(data, "formula", "top level")
    try:
        ast = parse(formula)
    except LTLfSyntaxError as err:
        r.fail("formula", str(err))
    unknown = atoms(ast) - {p.name for p in props}
    if unknown:
        r.fail("formula", unknown_text("proposition", sorted(unknown), [p.name for p in props],
                                       "(declared in [propositions])"))
    return formula


def _grid(r: _Reader, data: dict, n_objects: int, corner: bool) -> GridConfig:
    """The [grid] section, checked against every size: obstacles inside, objects fit."""
    raw_grid = r.table(data.get("grid", {}), "grid")
    r.keys(raw_grid, {"sizes", "max_steps", "obstacles"}, "grid")
    sizes = raw_grid.get("sizes", [7, 10])
    if not isinstance(sizes, list) or not sizes or any(
            not isinstance(s, int) or isinstance(s, bool) or s < 2 for s in sizes):
        r.fail("grid.sizes", f"must be a list of integers >= 2, got {sizes!r}")
    obstacles = raw_grid.get("obstacles", [])
    if not isinstance(obstacles, list) or any(
            not (isinstance(c, list) and len(c) == 2 and all(isinstance(v, int) for v in c))
            for c in obstacles):
        r.fail("grid.obstacles", f"must be a list of [x, y] cells, got {obstacles!r}")
    grid = GridConfig(
        sizes=tuple(sizes),
        max_steps=r.int(raw_grid, "max_steps", "grid", default=500, minimum=1),
        obstacles=tuple(tuple(c) for c in obstacles),
    )
    for size in grid.sizes:
        outside = [c for c in grid.obstacles if not (0 <= c[0] < size and 0 <= c[1] < size)]
        if outside:
            r.fail("grid.obstacles", f"cells {outside} lie outside the {size}x{size} grid")
        free = size * size - len(set(grid.obstacles)) - 1  # one cell for the agent
        if n_objects > free:
            r.fail("grid.sizes", f"{n_objects} objects do not fit a {size}x{size} grid "
                                 f"({free} free cells besides the agent)")
        if corner and (0, 0) in set(grid.obstacles):
            r.fail("grid.obstacles", "the corner cell (0, 0) is taken by a 'corner' place")
    return grid


def _continuous(r: _Reader, data: dict, n_objects: int) -> ContinuousConfig:
    """The [continuous] section: positive sizes, a whole number of physics steps per
    decision, and room for every object's pickup zone."""
    raw_cont = r.table(data.get("continuous", {}), "continuous")
    r.keys(raw_cont, {"arena", "pickup_radius", "boundary_reward", "control_period", "max_steps"}, "continuous")
    default = ContinuousConfig()
    continuous = ContinuousConfig(
        arena=r.float(raw_cont, "arena", "continuous", default.arena),
        pickup_radius=r.float(raw_cont, "pickup_radius", "continuous", default.pickup_radius),
        boundary_reward=r.float(raw_cont, "boundary_reward", "continuous", default.boundary_reward),
        control_period=r.float(raw_cont, "control_period", "continuous", default.control_period),
        max_steps=r.int(raw_cont, "max_steps", "continuous", default=default.max_steps, minimum=1),
    )
    if continuous.arena <= 0 or continuous.pickup_radius <= 0:
        r.fail("continuous", "arena and pickup_radius must be positive")
    if not continuous.control_period > 0:
        r.fail("continuous.control_period", f"must be > 0 seconds, got {continuous.control_period!r}")
    try:
        continuous.frame_skip()
    except ValueError as err:
        r.fail("continuous.control_period", str(err))
    if not _zones_fit(continuous.arena, continuous.pickup_radius, n_objects):
        r.fail("continuous.arena", _no_room(continuous.arena, continuous.pickup_radius, n_objects))
    return continuous


def _zones_fit(arena: float, pickup_radius: float, n_objects: int) -> bool:
    """Whether the objects and the agent get non-overlapping pickup zones (2 x pickup_radius
    wide): ``(arena - spacing) // spacing`` of them a side, a conservative count."""
    spacing = 2 * pickup_radius
    per_side = max(0, int((arena - spacing) // spacing))  # an arena narrower than one zone holds none, not (-1)**2
    return n_objects + 1 <= per_side * per_side


def _no_room(arena: float, pickup_radius: float, n_objects: int) -> str:
    """The problem and its fix when the pickup zones do not fit: the least arena that holds
    them, or the largest pickup_radius this arena allows, as numbers ``_zones_fit`` accepts."""
    side = math.isqrt(n_objects) + 1  # zones a side for n_objects + 1 of them
    least = math.ceil(round(2 * pickup_radius * (side + 1) * 1000, 6)) / 1000  # 3 decimals, up
    while not _zones_fit(least, pickup_radius, n_objects):  # float rounding
        least = round(least + 0.001, 3)
    most = math.floor(round(arena / (2 * (side + 1)) * 1000, 6)) / 1000
    while most > 0 and not _zones_fit(arena, most, n_objects):
        most = round(most - 0.001, 3)
    instead = f" (or pickup_radius at most {most:g})" if most > 0 else ""
    return (f"{n_objects} objects and the agent need {n_objects + 1} non-overlapping pickup zones "
            f"{2 * pickup_radius:g} wide (2 x pickup_radius), which an arena of {arena:g} cannot hold; "
            f"make arena at least {least:g}{instead}")


def _tags(r: _Reader, data: dict) -> tuple[str, ...]:
    tags = data.get("tags", [])
    if not isinstance(tags, list) or any(not isinstance(t, str) or not _NAME.match(t) for t in tags):
        r.fail("tags", f"must be a list of lower-case identifiers, e.g. [\"easy\", \"paper\"], got {tags!r}")
    if len(set(tags)) != len(tags):
        r.fail("tags", f"lists a tag twice: {tags!r}")
    return tuple(tags)


def builtin_specs() -> dict[str, TaskSpec]:
    """Every spec shipped in ``tasks/``, by task name."""
    specs = {}
    for file in sorted(tasks_dir().glob("*.toml")):
        spec = load_spec(file)
        if spec.name in specs:
            raise SpecError(f"{file}: name: {spec.name!r} is also the name of {specs[spec.name].path}")
        specs[spec.name] = spec
    return specs
