"""Where training got stuck: how often a run's training episodes ended, and how far along its
task they got, from ``episodes.csv`` (its ``seen`` and ``states`` columns: ``craftsuite.reached``).

For a task no method learns, a success curve is flat at 0 and says nothing; what the
episodes reached does: the propositions that ever held, the automaton states visited, and
the furthest of them, the visited state fewest automaton edges from acceptance.
``episode_progress`` reads one run, ``pool`` the seeds of one method (the results page
shows one line per method). A reader of many logs keeps each run's ``tally`` (a few dozen
pairs of cells for its thousands of episodes) and reads no log twice.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..record_format import RecordError, breaks_format, check_config, completions, required
from ..runs import RunError, read_columns, read_config, reading_log, recorded_rules


@dataclass(frozen=True)
class Furthest:
    """The visited automaton state closest to acceptance."""
    state: int
    distance: int  # automaton edges to an accepting state (0: accepting)
    share: float  # of the episodes, those that visited it


@dataclass(frozen=True)
class Progress:
    """What one run's training episodes (or several seeds', ``pool``) reached.

    Shares are over the ``marked`` episodes, those whose row carries ``seen`` and
    ``states`` (all of them but those logged, before the columns came, by an earlier session
    of a resumed run)."""
    task: str
    runs: int  # seeds pooled (1: one run)
    budget: int  # transitions (config.json's steps), summed over the runs
    episodes: int  # training episodes that ended
    completed: int  # of them, those that completed the task
    completed_per_100k: float  # completed episodes per 100k transitions (pooled: the runs' mean)
    marked: int
    seen_share: dict[str, float]  # proposition -> share of episodes in which it held
    state_share: dict[int, float]  # automaton state -> share of episodes that visited it
    closest_share: dict[int, float]  # distance -> share of episodes whose closest visited state is that far
    distance: tuple[int | None, ...]  # per state, edges to acceptance (None: it cannot get there)
    depth: tuple[int | None, ...]  # per state, edges from the initial state (None: the sink)
    furthest: Furthest | None  # None: no marked episode


def distances(automaton, forward: bool = False) -> list[int | None]:
    """Each state's fewest DFA edges to an accepting state (``forward``: from the initial
    state), over the transitions some label takes, not counting self-loops nor the rejecting
    sink (None: out of reach)."""
    links: dict[int, list[int]] = {}
    for source, target in automaton.edges():  # (the sink's edges are left out)
        if source != target:
            a, b = (source, target) if forward else (target, source)
            links.setdefault(a, []).append(b)
    if forward:
        out: list[int | None] = [0 if q == automaton.initial else None for q in range(automaton.n_states)]
    else:
        out = [0 if a else None for a in automaton.accepting.tolist()]
    frontier = [q for q, d in enumerate(out) if d == 0]
    while frontier:  # breadth first
        nxt = []
        for q in frontier:
            for other in links.get(q, ()):
                if out[other] is None:
                    out[other] = out[q] + 1
                    nxt.append(other)
        frontier = nxt
    return out


def route(automaton, state: int) -> list[str] | None:
    """How the automaton reaches ``state`` from its initial state in the fewest edges (self-
    loops and the rejecting sink left out), an edge named by the one proposition whose
    label alone takes it, or by its guard where none does: what a page names a state by
    (e.g. ``["key", "sword"]``; [] for the initial state, None for one out of reach)."""
    came: dict[int, tuple[int, str]] = {}
    edges = automaton.edges()  # (the sink's left out)
    frontier, seen = [automaton.initial], {automaton.initial}
    while frontier and state not in seen:
        nxt = []
        for q in frontier:
            for _, target in [e for e in edges if e[0] == q]:
                if target in seen:
                    continue
                seen.add(target)
                came[target] = (q, _edge_name(automaton, q, target))
                nxt.append(target)
        frontier = nxt
    if state not in seen:
        return None
    names = []
    while state != automaton.initial:
        state, name = came[state]
        names.append(name)
    return names[::-1]


def _edge_name(automaton, source: int, target: int) -> str:
    for i, name in enumerate(automaton.propositions):
        if automaton.step(source, 1 << i) == target:
            return name
    return automaton.guard(source, target, sink_free=True)


def episode_progress(run, tallied: tuple[np.ndarray, dict[tuple[str, str], int]] | None = None) -> Progress | None:
    """What the training episodes of the run at ``run`` reached; None for a record made before
    ``episodes.csv`` had its ``seen`` and ``states`` columns (no episode carries them).
    ``tallied``: its episodes' completions (0/1) and its log's ``tally``, as a reader of the log
    kept them (the log is then read only to name a cell at fault); by default the log is read here.

    Raises:
        RunError: a record that does not read (the file named), of a task unknown here or of
            other rules than the task's now (its bits would name other propositions).
    """
    run = Path(run)
    config = read_config(run)
    budget = _budget(run, config)
    spec = _spec(run, config)
    path = run / "episodes.csv"  # (or the archive's episodes.csv.gz: read_columns reads either)
    log = None
    if tallied is None:
        log, completed = _read_episodes(path)
        tallied = completed, tally(log)
    try:  # each distinct pair of cells read once, as many times over as episodes logged it
        return _summarized(spec, budget, tallied[0], *_untally(tallied[1]))
    except ValueError:
        pass  # a cell that is no mask, or bits the task has not: read again in the log's order, to name its line
    completed = tallied[0]
    if log is None:
        log, now = _read_episodes(path)
        if len(now) != len(completed):  # (rewritten, or swapped for another record, since it was tallied)
            raise RunError(f"{path} holds {len(now):,} episodes where it held {len(completed):,} when it was read: "
                           "it changed since; read its runs again")
    with reading_log(path):  # (a mask that does not read: the file named)
        seen, seen_given = _masks(log, "seen", len(completed))
        states, states_given = _masks(log, "states", len(completed))
    try:
        return _summarized(spec, budget, completed, seen, states, seen_given & states_given)
    except ValueError as err:
        raise RunError(f"{path}: {err}: the record was made with another automaton") from None


def _summarized(spec, budget: int, completed, seen, states, marked) -> Progress | None:
    """``summarize`` of a run's episodes; None where no episode carries its masks."""
    if len(completed) and not marked.any():
        return None
    return summarize(spec.automaton, spec.name, budget, completed, seen, states, marked)


def tally(log: dict) -> dict[tuple[str, str], int]:
    """A log's (``read_columns``) ``seen`` and ``states`` cells, each pair of one row counted:
    what ``Progress`` reads of them, a run's thousands of episodes in a few dozen pairs ("" for a
    cell a row lacks, an empty one or a log without the column)."""
    n = len(next(iter(log.values()), ()))
    return dict(Counter(zip(log.get("seen") or ("",) * n, log.get("states") or ("",) * n)))


def _untally(pairs: dict[tuple[str, str], int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A ``tally``'s masks as ``seen``, ``states`` and ``marked`` arrays, one entry an episode
    (in no log's order: a cell at fault is named by the index of its pair, not its line).

    Raises:
        ValueError: a cell that is no mask.
    """
    cells = {"seen": tuple(s for s, _ in pairs), "states": tuple(q for _, q in pairs)}
    counts = np.fromiter(pairs.values(), dtype=np.int64, count=len(pairs))
    seen, seen_given = _masks(cells, "seen", len(pairs))
    states, states_given = _masks(cells, "states", len(pairs))
    return np.repeat(seen, counts), np.repeat(states, counts), np.repeat(seen_given & states_given, counts)


def _masks(log: dict, name: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``seen`` or ``states`` column of a log's ``n`` rows as int64 masks, and whether each
    row has one (not an empty cell, logged before the column came, nor a log without it).

    Raises:
        ValueError: the first cell that is no integer, or none a 64-bit mask holds, named by its line.
    """
    values, given = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=bool)
    cells = log.get(name)
    if cells is None:
        return values, given
    given = np.fromiter((cell != "" for cell in cells), dtype=bool, count=n)
    try:  # int() as the log's writer wrote them (numpy's own parsing of strings drops NUL bytes)
        values[given] = np.fromiter((int(cell) for cell in cells if cell != ""), dtype=np.int64,
                                    count=int(given.sum()))
    except (ValueError, OverflowError):
        for line, cell in enumerate(cells, start=2):  # the first cell that is no mask, named
            if cell == "":
                continue
            try:
                mask = int(cell)
            except ValueError:
                raise ValueError(f"line {line}: {name} {cell!r} is not an integer") from None
            if not -2**63 <= mask < 2**63:
                raise ValueError(f"line {line}: {name} {cell} is beyond a signed 64-bit mask (every task's "
                                 "propositions and states are its bits 0 to 62)") from None
        raise
    return values, given


def _read_episodes(path: Path) -> tuple[dict, np.ndarray]:
    """A run's ``episodes.csv`` as columns, and its episodes' completions (0/1) as the record
    format checks them."""
    with reading_log(path):
        log = read_columns(path, required("episodes.csv"))
    try:
        return log, completions(log, path)
    except RecordError as err:
        raise RunError(breaks_format(err)) from None


def _budget(run: Path, config: dict) -> int:
    """A student's transitions budget, as its ``config.json`` records it (the record format's
    check of a config, whose ``steps`` is that budget)."""
    try:
        check_config(config, run / "config.json")
    except RecordError as err:
        raise RunError(breaks_format(err)) from None
    return config["steps"]


def summarize(automaton, task: str, budget: int, completed, seen, states, marked=None) -> Progress:
    """The ``Progress`` of one run of ``budget`` transitions from its episodes: per episode,
    completed (0/1), ``seen`` and ``states`` in the bits of ``automaton``, and ``marked``:
    whether its row has both (not one logged, before the columns came, by an earlier session
    of a resumed run; the shares count the marked episodes alone; default: every one).

    Raises:
        ValueError: a marked episode with bits the automaton has no proposition or state for, or
            arrays of different lengths (one entry an episode in each).
    """
    completed, seen, states = (np.asarray(x, dtype=np.int64) for x in (completed, seen, states))
    marked = np.ones(len(completed), dtype=bool) if marked is None else np.asarray(marked, dtype=bool)
    lengths = {"completed": len(completed), "seen": len(seen), "states": len(states), "marked": len(marked)}
    if len(set(lengths.values())) > 1:
        raise ValueError("summarize() takes one entry an episode in each array, got "
                         + ", ".join(f"{name} {n}" for name, n in lengths.items()))
    n_props, n_states = len(automaton.propositions), automaton.n_states
    far = distances(automaton)
    seen, states = seen[marked], states[marked]
    wrong = (seen < 0) | (states < 0) | ((seen >> n_props) != 0) | ((states >> n_states) != 0)
    if wrong.any():
        first = int(np.flatnonzero(wrong)[0])
        number = int(np.flatnonzero(marked)[first]) + 1  # counting every episode, marked or not
        raise ValueError(f"episode {number} (line {number + 1}: seen {seen[first]}, states {states[first]}) names "
                         f"propositions or states that task {task!r} does not have ({n_props} propositions, "
                         f"{n_states} states)")
    seen_counts = [int(((seen >> i) & 1).sum()) for i in range(n_props)]
    visits = [((states >> q) & 1) == 1 for q in range(n_states)]
    state_counts = [int(v.sum()) for v in visits]
    # each episode's closest visited state: the fewest edges to acceptance among those it visited
    unreached = np.iinfo(np.int64).max  # an episode that visited no state acceptance can be reached from
    closest = np.full(len(states), unreached)
    for q, dq in enumerate(far):
        if dq is not None:
            closest = np.where(visits[q], np.minimum(closest, dq), closest)
    near, counts = np.unique(closest[closest != unreached], return_counts=True)
    done = int(completed.sum())
    return _progress(task, 1, budget, len(completed), done, done * 100_000 / budget, int(marked.sum()),
                     automaton.propositions, seen_counts, state_counts,
                     {int(d): int(c) for d, c in zip(near, counts)}, tuple(far),
                     tuple(distances(automaton, forward=True)))


def _spec(run: Path, config: dict):
    from ..task_registry import resolve_task

    try:
        spec = resolve_task(config["task"])
    except (KeyError, ValueError) as err:
        raise RunError(f"{run / 'config.json'}: task {config['task']!r} is unknown here ({err}): register it to "
                       "read what its episodes reached") from None
    recorded = recorded_rules(config)
    if recorded is not None and recorded != spec.digest():
        raise RunError(f"{run / 'config.json'}: task {spec.name!r} ran under other rules (digest {recorded}) than "
                       f"this version's ({spec.digest()}): its episodes' bits may name another automaton's "
                       "propositions and states; read it with the version that trained it")
    return spec


def _progress(task, runs, budget, episodes, completed, per_100k, marked, propositions, seen_counts, state_counts,
              closest_counts, far, depth) -> Progress:
    def share(count):
        return count / marked if marked else 0.0

    furthest = None
    if closest_counts:
        d = min(closest_counts)
        # of the visited states that close, the one furthest from the start (where a label no
        # world makes, two events at once, skips a state, the start and the state after it
        # are as close), then the one more episodes visited, then the lower number
        state = max((q for q, dq in enumerate(far) if dq == d and state_counts[q]),
                    key=lambda q: (depth[q], state_counts[q], -q))
        furthest = Furthest(state, d, share(state_counts[state]))
    return Progress(task, runs, budget, episodes, completed, per_100k, marked,
                    {p: share(c) for p, c in zip(propositions, seen_counts)},
                    {q: share(c) for q, c in enumerate(state_counts)},
                    {d: share(c) for d, c in sorted(closest_counts.items())}, far, depth, furthest)


def pool(progress: list[Progress]) -> Progress:
    """Several seeds' ``Progress`` of one method as one: the mean of their completed episodes
    per 100k transitions, their episodes' shares pooled (each episode counts once).

    Raises:
        ValueError: no runs, or runs of different tasks.
    """
    if not progress:
        raise ValueError("pool() needs at least one run's progress")
    tasks = sorted({p.task for p in progress})
    if len(tasks) > 1:
        raise ValueError(f"pool() pools the seeds of one task's runs, got the tasks {tasks}")
    first = progress[0]
    marked = sum(p.marked for p in progress)

    def counts(field: str) -> dict:
        out: dict = {}
        for p in progress:
            for key, s in getattr(p, field).items():
                out[key] = out.get(key, 0) + round(s * p.marked)  # shares of whole episodes: exact counts
        return out

    seen, states, closest = counts("seen_share"), counts("state_share"), counts("closest_share")
    return _progress(first.task, sum(p.runs for p in progress), sum(p.budget for p in progress),
                     sum(p.episodes for p in progress), sum(p.completed for p in progress),
                     sum(p.completed_per_100k * p.runs for p in progress) / sum(p.runs for p in progress), marked,
                     tuple(first.seen_share), [seen[k] for k in first.seen_share],
                     [states[q] for q in first.state_share], {d: c for d, c in closest.items() if c}, first.distance,
                     first.depth)


def method_progress(runs, tallied=None) -> Progress | None:
    """The pooled ``Progress`` of one method's seeds (run directories or archived records),
    over those whose records carry the columns; None where none does. ``tallied``: per run,
    as ``episode_progress`` takes it.

    Raises:
        RunError: as ``episode_progress``, for any of them.
    """
    runs = list(runs)
    tallied = [None] * len(runs) if tallied is None else list(tallied)
    found = [p for p in (episode_progress(run, t) for run, t in zip(runs, tallied, strict=True)) if p is not None]
    return pool(found) if found else None


def completed_per_100k(run) -> float:
    """A run's completed training episodes per 100k transitions of its budget, from its log's
    ``success`` column (every record has it, old ones too)."""
    run = Path(run)
    budget = _budget(run, read_config(run))
    _, completed = _read_episodes(run / "episodes.csv")
    return float(completed.sum()) * 100_000 / budget
