"""The gymnasium ids of CraftSuite: ``CraftSuite/<Task>-<World>-v0``, built and read here only.

A world is ``Grid<size>`` (e.g. ``Grid7``, ``Grid10``), ``Cont`` (the MuJoCo world) or
``Kinematic`` (the authors' kinematic toy); its kind is ``Grid`` or ``Cont`` (both continuous
worlds take the same 2-d actions, so every TD3 method runs in either). Everything that names an env calls ``env_id`` (or
``grid_id`` / ``cont_id``) and everything that reads one calls ``parse_id``, so the format
lives in one place. This module imports nothing of gymnasium or the worlds.
"""

from __future__ import annotations

import re

NAMESPACE = "CraftSuite"
VERSION = "v0"
# The kinds of world every task is registered in: grids (one id per size, ``Grid7``,
# ``Grid10``) and the MuJoCo world (``Cont``).
WORLD_KINDS = ("Grid", "Cont")
CONT = "Cont"
KINEMATIC = "Kinematic"
# the worlds of kind Cont, the MuJoCo world first
CONT_WORLDS = (CONT, KINEMATIC)

TASK_NAME = re.compile(r"[A-Z][A-Za-z0-9]*\Z")  # a task spec's name: CamelCase, so ids split on "-" and "/"
_GRID = re.compile(r"Grid([1-9][0-9]*)\Z")


def world_kind(world: str) -> str:
    """The kind of a world: ``Grid10`` -> ``Grid``, ``Cont`` and ``Kinematic`` -> ``Cont``.

    Raises:
        ValueError: a world that is none of these.
    """
    if world in CONT_WORLDS:
        return CONT
    if isinstance(world, str) and _GRID.match(world):
        return "Grid"
    raise ValueError(f"unknown world {world!r}: use Cont (MuJoCo), Kinematic or Grid<size>, e.g. Grid10")


def grid_world(size: int) -> str:
    """The world name of a grid size: 7 -> ``Grid7``."""
    if not isinstance(size, int) or isinstance(size, bool) or size < 1:
        raise ValueError(f"a grid size is a positive integer, got {size!r}")
    return f"Grid{size}"


def grid_size(world: str) -> int:
    """The size of a grid world: ``Grid10`` -> 10.

    Raises:
        ValueError: ``world`` is not a grid.
    """
    match = _GRID.match(world) if isinstance(world, str) else None
    if match is None:
        raise ValueError(f"{world!r} is not a grid world (Grid<size>, e.g. Grid10)")
    return int(match.group(1))


def env_id(task: str, world: str) -> str:
    """The id of a task in a world: ("Reach", "Grid10") -> ``CraftSuite/Reach-Grid10-v0``.

    Raises:
        ValueError: a task name that is no task spec's name (CamelCase letters and digits,
            e.g. a path), or an unknown world.
    """
    if not isinstance(task, str) or not TASK_NAME.match(task):
        raise ValueError(f"{task!r} is not a task name (CamelCase letters and digits, e.g. BlindCraftsman)")
    world_kind(world)
    return f"{NAMESPACE}/{task}-{world}-{VERSION}"


def grid_id(task: str, size: int) -> str:
    """The id of a task on a grid of ``size``: ``CraftSuite/<task>-Grid<size>-v0``."""
    return env_id(task, grid_world(size))


def cont_id(task: str) -> str:
    """The id of a task in the MuJoCo world: ``CraftSuite/<task>-Cont-v0``."""
    return env_id(task, CONT)


def kinematic_id(task: str) -> str:
    """The id of a task in the kinematic world: ``CraftSuite/<task>-Kinematic-v0``."""
    return env_id(task, KINEMATIC)


def parse_id(value: str) -> tuple[str, str]:
    """``CraftSuite/<Task>-<World>-v0`` -> (task, world), e.g. ("Reach", "Grid10").

    Raises:
        ValueError: anything else, naming the expected format.
    """
    namespace, _, rest = value.partition("/") if isinstance(value, str) else ("", "", "")
    parts = rest.split("-")
    ok = namespace == NAMESPACE and len(parts) == 3 and parts[2] == VERSION and TASK_NAME.match(parts[0])
    if not ok or not (parts[1] in CONT_WORLDS or _GRID.match(parts[1])):
        raise ValueError(f"{value!r} is not a CraftSuite id ({NAMESPACE}/<Task>-<World>-{VERSION}, "
                         f"e.g. {cont_id('Reach')} or {grid_id('Reach', 7)})")
    return parts[0], parts[1]


def is_id(value: str) -> bool:
    """Whether ``value`` is a CraftSuite id (by its form; registered or not)."""
    try:
        parse_id(value)
    except ValueError:
        return False
    return True


def file_stem(value: str) -> str:
    """An id as a file name, without its namespace: ``CraftSuite/Reach-Cont-v0`` -> ``Reach-Cont-v0``.

    Raises:
        ValueError: ``value`` is not a CraftSuite id.
    """
    task, world = parse_id(value)
    return f"{task}-{world}-{VERSION}"
