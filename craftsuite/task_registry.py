"""The known tasks by name: the built-in specs of ``tasks/`` and the user specs added at run time.

This module owns what a task name means (``tasks``, ``ladder``, ``resolve_task``,
``add_task``); ``registration`` turns the tasks into gymnasium ids, and the worlds ask this
module for their task. It imports neither gymnasium's registry nor the worlds, so both can
import it.

A user task travels as data: ``carried(spec)`` is what a gymnasium id's ``task`` keyword and
a worker process get (a built-in task's name, a user task's TOML data), and
``resolve_task`` turns either back into the spec, so a process that never registered the
user task (a vector env's worker, ``EnvSpec.from_json``) still builds its world.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path

from .names import unknown_name
from .spec import SpecError, TaskSpec, builtin_specs, load_spec

SPEC_SUFFIX = ".toml"  # a task argument ending so names a spec file, not a task
_TASKS: dict[str, TaskSpec] = {}
_BUILTIN: dict[str, TaskSpec] = {}


def tasks() -> dict[str, TaskSpec]:
    """Every known task by name: the built-in specs, then those added by ``add_task``."""
    if not _TASKS:
        specs = builtin_specs()
        _TASKS.update(specs)
        _BUILTIN.update(specs)
    return _TASKS


def builtin_names() -> frozenset[str]:
    """The names of the tasks shipped in ``tasks/``."""
    tasks()
    return frozenset(_BUILTIN)  # (its keys)


def ladder(*tags: str) -> list[TaskSpec]:
    """The known tasks as rungs of a ladder, easiest first (``TaskSpec.rung``); with
    ``tags``, only those that carry any of them.

    Raises:
        UnknownName: a tag that no task spec carries (a KeyError), naming the tags in use.
    """
    known = tasks().values()
    in_use = sorted({t for spec in known for t in spec.tags})
    unknown = [t for t in tags if t not in in_use]
    if unknown:
        raise unknown_name("tag", unknown, in_use, "(the tags the task specs' 'tags' fields hold)")
    return sorted((s for s in known if not tags or set(tags) & set(s.tags)), key=lambda s: s.rung)


def add_task(source: str | Path | TaskSpec | Mapping) -> TaskSpec:
    """Add a task from a spec file, its TOML data or a loaded spec (replacing a user task
    of the same name, with a warning where its rules differ) and return it. Gymnasium ids
    come with ``craftsuite.register_task``.

    Raises:
        SpecError: a spec that cannot be used, naming the file, the field and the problem; a
            built-in task's name on another task (runs and leaderboards know a task by its name, so
            its runs would pool with the built-in's).
    """
    spec = source if isinstance(source, TaskSpec) else _load(source)
    if spec.name in builtin_names():
        if spec.digest() != _BUILTIN[spec.name].digest():
            raise SpecError(f"{spec.path or f'<task spec {spec.name!r} given as data>'}: name: {spec.name!r} is a "
                            f"built-in task's, whose runs this task's would pool with: name yours otherwise, e.g. "
                            f"My{spec.name}")
        return _BUILTIN[spec.name]  # the same rules: the built-in itself, which travels by name
    _ = spec.automaton  # compiled now: an objective that can never be satisfied is refused before it is known
    held = tasks().get(spec.name)
    if held is not None and held.digest() != spec.digest():  # said as gymnasium says an id registered again
        warnings.warn(f"task {spec.name!r} was registered already, with other rules: this spec replaces it (runs "
                      "record their task's rules, so runs under the two never pool)", stacklevel=3)
    tasks()[spec.name] = spec
    return spec


def _load(source) -> TaskSpec:
    if isinstance(source, Mapping):
        return _from_data(json.dumps(source))
    return load_spec(source)


def resolve_task(task: str | TaskSpec | Mapping) -> TaskSpec:
    """The spec of a task given by name, by spec, or as data (``carried``).

    Raises:
        UnknownName: an unknown name (a KeyError), listing the closest and every known one.
        SpecError: data that is no valid spec.
    """
    if isinstance(task, TaskSpec):
        return task
    if isinstance(task, Mapping):
        known = tasks().get(task.get("name"))
        text = json.dumps(task)
        if known is not None and json.dumps(known.to_data()) == text:
            return known  # the registered spec itself: its automaton is compiled once per process
        return _from_data(text)
    known = tasks()
    if task not in known:
        raise unknown_name("task", task, sorted(known),
                           f"(a task of your own: a command takes its spec file, path/to/task{SPEC_SUFFIX}; in Python, "
                           f"craftsuite.register_task('path/to/task{SPEC_SUFFIX}') adds it)")
    return known[task]


@lru_cache(maxsize=64)
def _from_data(text: str) -> TaskSpec:
    """A spec from its data as JSON text; cached, so that every env of a vector env built
    from the same data shares one spec (and one compiled automaton)."""
    data = json.loads(text)
    return load_spec(data, name_hint=f"<task spec {data.get('name', '?')!r} given as data>")


def carried(spec: TaskSpec) -> str | dict:
    """How a task travels to another process or into JSON: a built-in task by name (any
    process knows it), a user task as its TOML data (``TaskSpec.to_data``)."""
    if spec.name in builtin_names() and tasks().get(spec.name) is spec:
        return spec.name
    return spec.to_data()


def is_spec_file(argument: str) -> bool:
    """Whether a task argument names a spec file (``*.toml``, or any path: a task name has
    no ``/``) rather than a task."""
    return str(argument).endswith(SPEC_SUFFIX) or "/" in str(argument)
