"""Gymnasium ids of every known task, registered in one loop over the task specs.

The tasks themselves live in ``task_registry`` (names, ladder, user specs), the id format in
``ids``; this module registers each task's ids with gymnasium and holds their entry points
(``make_grid``, ``make_continuous``, ``make_kinematic``; ``make_grid_vector``) and ``make_vec``,
gymnasium's with ``num_envs`` checked in every mode. The task and id names are imported from
their own modules, not from here.
"""

from __future__ import annotations

import functools
import inspect
from pathlib import Path

import gymnasium as gym

from .ids import CONT, NAMESPACE, cont_id, grid_id, grid_size, kinematic_id, parse_id, world_kind
from .ids import KINEMATIC as KINEMATIC_WORLD
from .names import unknown_keywords
from .spec import KINEMATIC_CONFIG, TaskSpec
from .task_registry import add_task, carried, tasks

# gymnasium.make's own keywords: it takes them itself, so a world's entry point never sees them
MAKE_KEYWORDS = ("max_episode_steps", "disable_env_checker")
# registered with every grid id: the id itself, so its entry points can refuse another size
ID_KEYWORD = "env_id"
_ENTRY_POINTS: dict[str, object] = {}  # world ("Grid", "Cont", "Kinematic") -> its entry point, unchecked
_WORLD_NAMES = {"Grid": "grid", CONT: "MuJoCo", KINEMATIC_WORLD: "kinematic"}
# keywords another world takes that a world refuses for a reason of its own, stated in the error
_WHY_NOT = {"Grid": {side: "the grid world draws every cell {tile} pixels a side (Grid7: {frame}x{frame} "
                           "frames); it has no frame size to set" for side in ("width", "height")}}
# keywords of a world's entry point that a run sets itself, refused in a run's flags (--env)
# with who sets them; the others' listings leave them out
_PRODUCT = ("whether the automaton state is observed is the run's to say (its method; a video's checkpoint, "
            "or --product)")
# the command renders where it shows something: a run trains unrendered, a video asks for frames
_RENDER = "the command sets it (runs train unrendered; craftsuite video renders its frames itself)"
_RUN_OWNS = {"Grid": {"product": _PRODUCT, "size": "the world (Grid7, Grid10) fixes the grid's size",
                      "layout_seed": "a run's layout seed is its own setting (--layout-seed)", "render_mode": _RENDER},
             CONT: {"product": _PRODUCT, "render_mode": _RENDER},
             KINEMATIC_WORLD: {"product": _PRODUCT, "render_mode": _RENDER}}


def world_keywords(world: str) -> tuple[str, ...]:
    """The keywords ``gymnasium.make`` takes for a world (``Grid7``, ``Cont``, ``Kinematic``)
    beyond its id: its entry point's, then gymnasium.make's own."""
    make = _ENTRY_POINTS[_entry_key(world)]
    return tuple(p for p in inspect.signature(make).parameters if p != "task") + MAKE_KEYWORDS


def check_world_kwargs(world: str, kwargs, source: str | None = None) -> None:
    """Raise a ValueError (``source``: where they came from, e.g. ``--env``) when ``kwargs``
    hold a keyword ``world`` does not take, naming the keywords it does, or a ``product``
    that is not True or False; before anything is built, so a misspelt keyword is not
    Python's "unexpected keyword argument"."""
    kind = _entry_key(world)
    prefix = f"{source}: " if source else ""
    accepted = world_keywords(world)
    if source is not None:  # a run's flag: what the id or the run's own settings fix is not the flag's
        owns = _RUN_OWNS.get(kind, {})
        owned = sorted(set(kwargs) & set(owns))
        if owned:
            raise ValueError(f"{prefix}{owned[0]}: {owns[owned[0]]}; leave it out of {source}")
        accepted = tuple(k for k in accepted if k not in owns)
    unknown = sorted(set(kwargs) - set(accepted) - {"task"})
    if not unknown:
        from .envs.vector import check_world_values

        check_world_values(kwargs, prefix)
        return
    why = [_WHY_NOT.get(kind, {}).get(k) for k in unknown]
    if all(why):
        from .rendering.grid import TILE

        raise ValueError(f"{prefix}{', '.join(unknown)}: " + why[0].format(tile=TILE, frame=7 * TILE))
    raise ValueError(prefix + unknown_keywords(unknown, accepted, f"the {_WORLD_NAMES[kind]} world"))


def _entry_key(world: str) -> str:
    return world if world in _ENTRY_POINTS else "Grid" if world_kind(world) == "Grid" else world


def _check_grid_size(kwargs: dict) -> None:
    """Raise a ValueError when a grid id is made with a ``size`` other than its own.

    gymnasium merges a caller's keywords over the id's registered ones, so the entry point
    cannot tell the id's ``size`` from a caller's; the id itself, registered under
    ``ID_KEYWORD``, says which it is. Pops ``ID_KEYWORD`` (no world takes it).
    """
    name = kwargs.pop(ID_KEYWORD, None)
    if name is None or "size" not in kwargs:
        return
    task, world = parse_id(name)
    size, fixed = kwargs["size"], grid_size(world)
    if size != fixed:
        raise ValueError(f"size={size!r}: {name} is the {fixed}x{fixed} grid (its id fixes the size); "
                         f"{_grid_fix(task, size)}")


def _grid_fix(task: str, size) -> str:
    """What to do instead of giving a grid id another ``size``: that size's id, or the task's grids."""
    if isinstance(size, int) and size > 0 and grid_id(task, size) in gym.registry:
        return f"use {grid_id(task, size)}"
    grids = sorted((w for t, w in map(parse_id, registered_ids()) if t == task and world_kind(w) == "Grid"),
                   key=grid_size)
    return f"leave size out ({task}'s grids: {', '.join(grids)})"


def _entry_point(world: str):
    """A world's entry point, its keywords checked first (``check_world_kwargs``): every
    gymnasium.make of a CraftSuite id goes through one."""
    def wrap(make):
        _ENTRY_POINTS[world] = make

        @functools.wraps(make)
        def checked(*args, **kwargs):
            _check_grid_size(kwargs)
            check_world_kwargs(world, kwargs)
            return make(*args, **kwargs)
        return checked
    return wrap


@_entry_point("Grid")
def make_grid(task: str | TaskSpec, size: int, product: bool = False,
              render_mode: str | None = None, layout_seed: int | None = None,
              status_panel: bool = False) -> gym.Env:
    """Entry point of the grid ids; ``product=True`` adds the automaton one-hot,
    ``layout_seed`` fixes the objects' layout across episodes, ``status_panel=True`` draws
    the inventory and automaton state under each frame (for videos)."""
    from .envs.grid import GridWorldEnv
    from .wrappers import AutomatonObservation

    env = GridWorldEnv(task, size, render_mode=render_mode, layout_seed=layout_seed,
                       status_panel=status_panel)
    return AutomatonObservation(env) if product else env


make_grid.metadata = {"render_modes": ["rgb_array", "ansi"], "render_fps": 8}


@_entry_point(CONT)
def make_continuous(task: str | TaskSpec, product: bool = False, render_mode: str | None = None,
                    width: int = 240, height: int = 240, frame_skip: int | None = None,
                    status_panel: bool = False) -> gym.Env:
    """Entry point of the MuJoCo ids; ``product=True`` adds the automaton one-hot,
    ``frame_skip`` sets the physics steps per action (None: the world's default),
    ``width`` x ``height`` the frame, ``status_panel=True`` draws the inventory and
    automaton state under each frame (for videos)."""
    from .envs.continuous import ContinuousWorldEnv
    from .wrappers import AutomatonObservation

    env = ContinuousWorldEnv(task, render_mode=render_mode, width=width, height=height,
                             frame_skip=frame_skip, status_panel=status_panel)
    return AutomatonObservation(env) if product else env


make_continuous.metadata = {"render_modes": ["rgb_array"], "render_fps": 4}  # the default world; each env sets its own


@_entry_point(KINEMATIC_WORLD)
def make_kinematic(task: str | TaskSpec, product: bool = False, render_mode: str | None = None,
                   width: int = 240, height: int = 240, status_panel: bool = False, size: int = 7,
                   observation: str = "authors") -> gym.Env:
    """Entry point of the kinematic ids (the authors' continuous toy and rules, no MuJoCo);
    ``product=True`` adds the automaton one-hot, ``width`` x ``height`` the frame,
    ``status_panel=True`` draws the inventory and automaton state under each frame,
    ``size`` is the board's side (7 or 10), ``observation`` "authors" or "craftsuite"."""
    from .envs.kinematic import KinematicWorldEnv
    from .wrappers import AutomatonObservation

    env = KinematicWorldEnv(task, render_mode=render_mode, width=width, height=height,
                            status_panel=status_panel, size=size, observation=observation)
    return AutomatonObservation(env) if product else env


make_kinematic.metadata = {"render_modes": ["rgb_array"], "render_fps": 8}


def make_grid_vector(num_envs: int, **kwargs) -> gym.vector.VectorEnv:
    """Vector entry point of the grid ids: ``craftsuite.envs.vector.make_grid_vector``, the
    id's size checked first (as ``make_grid``'s)."""
    from .envs.vector import make_grid_vector as make

    _check_grid_size(kwargs)
    return make(num_envs, **kwargs)


def make_vec(id: str | gym.envs.registration.EnvSpec, num_envs: int = 1, vectorization_mode=None,
             **kwargs) -> gym.vector.VectorEnv:
    """``gymnasium.make_vec``, ``num_envs`` checked first in every vectorization mode.

    gymnasium's "sync" and "async" modes build ``num_envs`` single envs and read the first
    one, so with none they fail with an IndexError before any CraftSuite code runs; their
    make_vec has no hook for a check (the "vector_entry_point" mode checks in the vector env).
    """
    from .envs.vector import check_num_envs

    check_num_envs(num_envs)
    return gym.make_vec(id, num_envs=num_envs, vectorization_mode=vectorization_mode, **kwargs)


# the grid's passes through make_grid_vector above, which checks the id's size
_VECTOR = {"grid": "craftsuite.registration:make_grid_vector",
           "kinematic": "craftsuite.envs.vector:make_kinematic_vector",
           # a module of its own: craftsuite.envs.vector stays free of MuJoCo
           "continuous": "craftsuite.envs.continuous_vector:make_continuous_vector"}


def _register(spec: TaskSpec) -> list[str]:
    # the ids carry the task as plain data (a built-in by name, a user task as its TOML data):
    # worker processes of vector envs need not re-register it, and EnvSpec.to_json works
    task = carried(spec)
    # (id, entry point, vector entry point, kwargs, max steps); the vector entry points are
    # the natively vectorized worlds of craftsuite.envs.vector and, for the MuJoCo ids,
    # craftsuite.envs.continuous_vector (make_vec's "vector_entry_point"; strings, imported lazily)
    worlds = [(grid_id(spec.name, size), "make_grid", _VECTOR["grid"],
               {"size": size, ID_KEYWORD: grid_id(spec.name, size)}, spec.grid.max_steps)
              for size in spec.grid.sizes]
    worlds.append((cont_id(spec.name), "make_continuous", _VECTOR["continuous"], {}, spec.continuous.max_steps))
    worlds.append((kinematic_id(spec.name), "make_kinematic", _VECTOR["kinematic"], {}, KINEMATIC_CONFIG.max_steps))
    for env_id, entry, vector_entry, kwargs, max_steps in worlds:
        if env_id in gym.registry:
            del gym.registry[env_id]  # re-registering a task replaces its ids
        gym.register(id=env_id, entry_point=f"craftsuite.registration:{entry}", vector_entry_point=vector_entry,
                     kwargs={"task": task, **kwargs}, max_episode_steps=max_steps)
    return [w[0] for w in worlds]


def register_task(spec: str | Path | TaskSpec | dict) -> list[str]:
    """Add a task from a spec file (or its TOML data, or a loaded spec) and register its
    gymnasium ids.

    Returns the new ids, e.g. ``["CraftSuite/MyTask-Grid7-v0", ...]``.
    """
    return _register(add_task(spec))


def register_builtin() -> list[str]:
    ids = []
    for spec in tasks().values():
        ids += _register(spec)
    return ids


def registered_ids() -> list[str]:
    return sorted(i for i in gym.registry if i.startswith(f"{NAMESPACE}/"))
