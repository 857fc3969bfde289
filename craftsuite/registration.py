"""Task registry and gymnasium ids, built in one loop over the task specs."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym

from .spec import TaskSpec, builtin_specs, load_spec

NAMESPACE = "CraftSuite"
# The kinds of world every task is registered in: grids (one id per size, ``Grid7``,
# ``Grid10``) and the MuJoCo world (``Cont``).
WORLD_KINDS = ("Grid", "Cont")
_TASKS: dict[str, TaskSpec] = {}


def tasks() -> dict[str, TaskSpec]:
    """Every known task by name: the built-in specs, then those added by ``register_task``."""
    if not _TASKS:
        _TASKS.update(builtin_specs())
    return _TASKS


def ladder(*tags: str) -> list[TaskSpec]:
    """The known tasks as rungs of a ladder, easiest first (``TaskSpec.rung``); with
    ``tags``, only those that carry any of them.

    Raises:
        KeyError: a tag that no task spec carries, naming the tags in use.
    """
    known = tasks().values()
    in_use = sorted({t for spec in known for t in spec.tags})
    unknown = [t for t in tags if t not in in_use]
    if unknown:
        raise KeyError(f"no task spec has {'tag' if len(unknown) == 1 else 'tags'} {unknown} in its 'tags' field; "
                       f"tags in use: {in_use}")
    return sorted((s for s in known if not tags or set(tags) & set(s.tags)), key=lambda s: s.rung)


def resolve_task(task: str | TaskSpec) -> TaskSpec:
    if isinstance(task, TaskSpec):
        return task
    known = tasks()
    if task not in known:
        raise KeyError(f"unknown task {task!r}; known tasks: {sorted(known)} "
                       "(add one with craftsuite.register_task)")
    return known[task]


def world_kind(world: str) -> str:
    """The kind of a student world: ``Grid10`` -> ``Grid``, ``Cont`` -> ``Cont``."""
    if world == "Cont":
        return "Cont"
    if world.startswith("Grid") and world[4:].isdigit():
        return "Grid"
    raise ValueError(f"unknown world {world!r}: use Cont (MuJoCo) or Grid<size>, e.g. Grid10")


def parse_id(env_id: str) -> tuple[str, str]:
    """``CraftSuite/<Task>-<World>-v0`` -> (task, world), e.g. ("Reach", "Grid10")."""
    namespace, _, rest = env_id.partition("/")
    parts = rest.split("-")
    if namespace != NAMESPACE or len(parts) != 3 or parts[2] != "v0":
        raise ValueError(f"{env_id!r} is not a CraftSuite id ({NAMESPACE}/<Task>-<World>-v0, "
                         f"e.g. {cont_id('Reach')})")
    return parts[0], parts[1]


def grid_id(task: str, size: int) -> str:
    return f"{NAMESPACE}/{task}-Grid{size}-v0"


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


def cont_id(task: str) -> str:
    return f"{NAMESPACE}/{task}-Cont-v0"


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


def _register(spec: TaskSpec, builtin: bool) -> list[str]:
    # built-in tasks by name (readable specs); user tasks carry their spec, so that worker
    # processes of vector envs need not re-register them
    task = spec.name if builtin else spec
    worlds = [(grid_id(spec.name, size), "make_grid", {"size": size}, spec.grid.max_steps)
              for size in spec.grid.sizes]
    worlds.append((cont_id(spec.name), "make_continuous", {}, spec.continuous.max_steps))
    for env_id, entry, kwargs, max_steps in worlds:
        if env_id in gym.registry:
            del gym.registry[env_id]  # re-registering a task replaces its ids
        gym.register(id=env_id, entry_point=f"craftsuite.registration:{entry}",
                     kwargs={"task": task, **kwargs}, max_episode_steps=max_steps)
    return [w[0] for w in worlds]


def register_task(spec: str | Path | TaskSpec) -> list[str]:
    """Add a task from a spec file (or a loaded spec) and register its gymnasium ids.

    Returns the new ids, e.g. ``["CraftSuite/MyTask-Grid7-v0", ...]``.
    """
    if not isinstance(spec, TaskSpec):
        spec = load_spec(spec)
    tasks()[spec.name] = spec
    return _register(spec, builtin=False)


def register_builtin() -> list[str]:
    ids = []
    for spec in tasks().values():
        ids += _register(spec, builtin=True)
    return ids


def registered_ids() -> list[str]:
    return sorted(i for i in gym.registry if i.startswith(f"{NAMESPACE}/"))
