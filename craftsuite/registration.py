"""Task registry and gymnasium ids, built in one loop over the task specs."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym

from .spec import TaskSpec, builtin_specs, load_spec

NAMESPACE = "CraftSuite"
_TASKS: dict[str, TaskSpec] = {}


def tasks() -> dict[str, TaskSpec]:
    """Every known task by name: the built-in specs, then those added by ``register_task``."""
    if not _TASKS:
        _TASKS.update(builtin_specs())
    return _TASKS


def resolve_task(task: str | TaskSpec) -> TaskSpec:
    if isinstance(task, TaskSpec):
        return task
    known = tasks()
    if task not in known:
        raise KeyError(f"unknown task {task!r}; known tasks: {sorted(known)} "
                       "(add one with craftsuite.register_task)")
    return known[task]


def grid_id(task: str, size: int) -> str:
    return f"{NAMESPACE}/{task}-Grid{size}-v0"


def make_grid(task: str | TaskSpec, size: int, product: bool = False,
              render_mode: str | None = None) -> gym.Env:
    """Entry point of the grid ids; ``product=True`` adds the automaton one-hot."""
    from .envs.grid import GridWorldEnv
    from .wrappers import AutomatonObservation

    env = GridWorldEnv(task, size, render_mode=render_mode)
    return AutomatonObservation(env) if product else env


make_grid.metadata = {"render_modes": ["rgb_array", "ansi"], "render_fps": 8}


def _register(spec: TaskSpec, builtin: bool) -> list[str]:
    ids = []
    for size in spec.grid.sizes:
        env_id = grid_id(spec.name, size)
        if env_id in gym.registry:
            del gym.registry[env_id]  # re-registering a task replaces its ids
        gym.register(
            id=env_id,
            entry_point="craftsuite.registration:make_grid",
            # built-in tasks by name (readable specs); user tasks carry their spec, so that
            # worker processes of vector envs need not re-register them
            kwargs={"task": spec.name if builtin else spec, "size": size},
            max_episode_steps=spec.grid.max_steps,
        )
        ids.append(env_id)
    return ids


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
