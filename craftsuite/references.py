"""Reference scores of every task in every world, and the tasks page built from them.

Two policies bracket what a learner does on a rung: the scripted planner (``scripted.py``:
it knows the task and walks to the next object the objective needs) shows the task can be
done and how many decisions it takes; a uniformly random policy shows how often chance
alone completes it and how far it gets (automaton steps: transitions that change the
automaton's state, the task's progress). Both play the registered ids as users get them,
on episode seeds 0, 1, ...

``craftsuite tasks --markdown docs/tasks.md`` writes the page; nothing in it is typed by hand.
The references depend on the code alone, the archive's figures on the page do not: the
references are kept in the cache (``paths.cache_dir("references")``), keyed by a digest of the
package's code and data, the ids' registrations and specs, the episodes, the versions of the
libraries that simulate and the Python version and CPU architecture, so that the page
rebuilt after runs land plays its thousands of episodes again only when one of those changed
(any change to the package's code counts; delete the cache's ``references/`` folder to play
them again regardless).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
from dataclasses import dataclass
from pathlib import Path

import gymnasium as gym
import numpy as np

POLICIES = ("scripted", "random")
# the libraries whose versions can change a reference (the scenes, the simulation, its random numbers)
SIMULATING = ("gymnasium", "dm-control", "mujoco", "numpy")
# bump when the cache file's layout changes: old entries then miss
CACHE_FORMAT = 1

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Reference:
    env_id: str
    policy: str  # "scripted" or "random"
    episodes: int
    success: float  # share of episodes that completed the objective
    steps: float  # mean decisions per completed episode (nan: none completed)
    automaton_steps: float  # mean transitions that changed the automaton state, per episode
    violations: float  # share of episodes that broke the objective


def reference(env_id: str, policy: str, episodes: int = 100, seed: int = 0) -> Reference:
    """Play ``episodes`` episodes of ``policy`` ("scripted" or "random") on ``env_id``."""
    from .episodes import rollout
    from .scripted import scripted_policy

    if policy not in POLICIES:
        raise ValueError(f"policy must be one of {', '.join(POLICIES)}, got {policy!r}")
    env = gym.make(env_id)
    if policy == "scripted":
        act = scripted_policy(env)
    else:
        env.action_space.seed(seed)
        act = lambda _obs: env.action_space.sample()  # noqa: E731
    edges = 0

    def count_edges(episode, reward, info):
        nonlocal edges
        w, _, w2 = info["automaton_transition"]
        edges += w != w2

    played = rollout(env, act, episodes, seed, on_step=count_edges)
    wins = sum(e.success for e in played)
    broken = sum(bool(e.info["violation"]) for e in played)
    lengths = [e.length for e in played if e.success]
    env.close()
    return Reference(env_id, policy, episodes, wins / episodes, float(np.mean(lengths)) if lengths else float("nan"),
                     edges / episodes, broken / episodes)


def references(env_ids, episodes: int = 100, progress: bool = True) -> dict[tuple[str, str], Reference]:
    """Every policy's reference (``POLICIES``) on each of ``env_ids``, keyed by (id, policy):
    from the cache where the same code, data, specs and libraries computed them before, else
    played (and kept there, unless the code on disk changed while they played). A cache that
    cannot be read or written is passed by with a warning; an id whose registration has no
    JSON form (a callable entry point) is played every time."""
    from .files import atomic_write
    from .paths import cache_dir
    from .progress import progress_iter

    env_ids = list(env_ids)
    key = _cache_key(env_ids, episodes)
    path = None if key is None else cache_dir("references") / f"{key}.json"
    cached = None if path is None else _load(path, env_ids, episodes)
    if cached is not None:
        return cached
    refs = {}
    for env_id in progress_iter(env_ids, "references", "id", enabled=progress):
        for policy in POLICIES:
            refs[env_id, policy] = reference(env_id, policy, episodes)
    if path is not None and _cache_key(env_ids, episodes) == key:
        rows = [{k: None if isinstance(v, float) and np.isnan(v) else v for k, v in dataclasses.asdict(r).items()}
                for r in refs.values()]  # NaN as null: strict JSON
        try:
            atomic_write(path, json.dumps(rows))
        except OSError as err:  # a read-only home must not stop anyone from writing the page
            log.warning("could not write the references cache %s (%s)", path, err)
    return refs


def _cache_key(env_ids: list[str], episodes: int) -> str | None:
    """What the references hang on: the package's code and data, the simulating libraries and
    the platform, and each id's registration and task spec (a task registered from Python is
    in no file); None where a registration has no JSON form."""
    import platform
    from importlib.metadata import version

    from .ids import parse_id
    from .paths import code_digest
    from .task_registry import tasks

    try:
        registrations = {env_id: gym.spec(env_id).to_json() for env_id in env_ids}
    except (TypeError, ValueError):  # gymnasium's refusal of a callable entry point
        return None
    what = {"format": CACHE_FORMAT, "code": code_digest(), "episodes": episodes, "ids": registrations,
            "tasks": {env_id: tasks()[parse_id(env_id)[0]].digest() for env_id in env_ids},
            "libraries": {name: version(name) for name in SIMULATING},
            "platform": [platform.python_version(), platform.machine()]}
    return hashlib.sha256(json.dumps(what, sort_keys=True).encode()).hexdigest()[:32]


_NUMBERS = ("success", "steps", "automaton_steps", "violations")


def _load(path: Path, env_ids: list[str], episodes: int) -> dict[tuple[str, str], Reference] | None:
    """The cached references at ``path``, checked to be those asked for; None: not cached."""
    try:
        refs = {}
        for row in json.loads(path.read_text()):
            r = Reference(**{**row, **{k: float("nan") for k in _NUMBERS if row.get(k, 0) is None}})
            if r.episodes != episodes or not all(isinstance(getattr(r, k), (int, float)) for k in _NUMBERS):
                raise ValueError(f"its row for {r.env_id} ({r.policy}) is not a reference of {episodes} episodes")
            refs[r.env_id, r.policy] = r
        asked = {(env_id, policy) for env_id in env_ids for policy in POLICIES}
        if set(refs) != asked:
            missing, extra = sorted(asked - set(refs)), sorted(set(refs) - asked)
            raise ValueError(f"it lacks {missing[:2]}" if missing else f"it holds {extra[:2]}, not asked for")
    except (FileNotFoundError, NotADirectoryError):  # not cached (or no cache folder can be made)
        return None
    except (OSError, ValueError, TypeError, AttributeError) as err:  # torn, or not this layout
        log.warning("ignoring unreadable references cache %s (%s); playing the episodes again", path, err)
        return None
    return refs


def _ids_of(name: str) -> list[str]:
    """A task's ids: the grids by size, then the MuJoCo world, then the kinematic one."""
    from .ids import CONT_WORLDS, grid_size, parse_id
    from .registration import registered_ids

    def order(env_id):
        world = parse_id(env_id)[1]
        cont = world in CONT_WORLDS
        return (cont, CONT_WORLDS.index(world) if cont else grid_size(world))

    return sorted((i for i in registered_ids() if parse_id(i)[0] == name), key=order)


def scratch_success(results) -> dict[str, list[str]]:
    """Per task, TD3 from scratch in MuJoCo as the results archive under ``results`` holds it
    (every suite's directory): the mean final greedy success [95% t], at each budget and
    learner regime run (a regime changes how hard a rung reads: n-step returns learn it
    sooner)."""
    from .ids import CONT
    from .reporting.board import build

    out: dict[str, list[str]] = {}
    for students in sorted(Path(results).glob("*/students")) if results is not None else []:
        for e in build(students, keep=lambda config: config.get("method") == "td3"):
            if e.world == CONT and not e.world_kwargs:
                s = e.stats["success"]
                interval = f" [{s.low:.2f}, {s.high:.2f}]" if s.has_interval else ""
                out.setdefault(e.task, []).append(f"{s.value:.2f}{interval} at {e.budget / 1e6:g}M "
                                                  f"({len(e.seeds)} seeds, {students.parent.name}, {e.regime})")
    return out


def tasks_page(episodes: int = 100, progress: bool = True, results="results") -> str:
    """The tasks page in Markdown: the ladder's rungs, easiest first, with their references
    and, where the results archive (``results``; None: none) holds it, TD3 from scratch's
    success in MuJoCo."""
    from .task_registry import ladder

    specs = ladder()
    ids = [env_id for spec in specs for env_id in _ids_of(spec.name)]
    periods = ", ".join(sorted({f"{s.continuous.control_period:g} s" for s in specs}))
    refs = references(ids, episodes, progress)
    lines = [
        "# Tasks",
        "",
        "<!-- generated by `craftsuite tasks --markdown docs/tasks.md` from the specs in tasks/ and the results in "
        "results/; do not edit -->",
        "",
        "The task ladder, easiest rung first. Every task is a TOML spec in `tasks/` and is registered in",
        "every world: `CraftSuite/<Task>-Grid7-v0`, `-Grid10-v0` (the grids), `-Cont-v0` (MuJoCo) and",
        "`-Kinematic-v0` (the authors' kinematic toy and rules: jumps of 3 x the action, 1000-step episodes). Tags",
        "select rungs (`craftsuite tasks --tag easy`, a suite's `tags`): a difficulty (`easy`, `medium`,",
        "`hard`), `calibration` for the rung any algorithm should pass before its results above mean",
        "anything, `middle` for the rungs between the two-stage rung and the paper's tasks, `paper` for the",
        "paper's tasks.",
        "",
        "Scratch success: TD3 from scratch in MuJoCo, greedy success at the last evaluation, the mean over seeds",
        "[95% t-interval], at each budget and learner regime a suite ran it (from the results archive, `results/`).",
        "Each middle rung is calibrated to land between 0.2 and 0.8 at its suite's budget in its suite's regime:",
        "where methods can differ.",
        "",
        f"References, {episodes} episodes per id on seeds 0-{episodes - 1}: the *scripted* planner (walks to the "
        "next object the objective needs) and a uniformly *random* policy. Steps are decisions per completed "
        "episode; automaton steps are transitions that change the automaton's state, per episode (the "
        "task's progress; a completion needs at least the automaton's shortest accepting path). The MuJoCo "
        f"world holds each action for the spec's control period ({periods}) for at most its "
        "`continuous.max_steps` decisions; the grids allow the spec's `grid.max_steps` moves (the "
        "episode limit column).",
        "",
        "| task | tags | objective | automaton (states / transitions) | scratch success (MuJoCo) |",
        "|---|---|---|---|---|",
    ]
    scratch = scratch_success(results)
    for spec in specs:
        states, edges = spec.automaton.size()
        formula = spec.formula.replace("|", "\\|")
        lines.append(f"| [{spec.name}](#{spec.name.lower()}) | {', '.join(spec.tags)} | `{formula}` | "
                     f"{states} / {edges} | {'; '.join(scratch.get(spec.name, [])) or 'not run'} |")
    for spec in specs:
        states, edges = spec.automaton.size()
        lines += ["", f"## {spec.name}", "", spec.description, "",
                  f"- spec: `tasks/{spec.path.name}`" if spec.path else "- spec: registered from Python",
                  f"- tags: {', '.join(f'`{t}`' for t in spec.tags) or 'none'}",
                  f"- objective: `{spec.formula}` over {', '.join(f'`{p}`' for p in spec.proposition_names)}",
                  f"- automaton: {states} states, {edges} transitions"
                  + (" (+ a rejecting sink: some label sequences break the objective)"
                     if spec.automaton.rejecting.any() else ""),
                  "",
                  "| id | episode limit | scripted success | scripted steps | random success "
                  "| random automaton steps / episode | random violations |",
                  "|---|---|---|---|---|---|---|"]
        for env_id in _ids_of(spec.name):
            s, r = refs[env_id, "scripted"], refs[env_id, "random"]
            limit = gym.spec(env_id).max_episode_steps
            lines.append(f"| `{env_id}` | {limit} | {s.success:.2f} | {s.steps:.1f} | {r.success:.2f} | "
                         f"{r.automaton_steps:.2f} | {r.violations:.2f} |")
    # no wall time here: the page is the same wherever and whenever it is regenerated
    lines += ["", f"*{len(ids)} ids, {len(POLICIES) * len(ids) * episodes:,} episodes.*", ""]
    return "\n".join(lines)


def write_tasks_page(path, episodes: int = 100, progress: bool = True, results="results") -> Path:
    from .files import atomic_write

    path = Path(path)
    atomic_write(path, tasks_page(episodes, progress, results))
    return path
