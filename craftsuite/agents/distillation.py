"""Automaton distillation: a teacher's knowledge as Q-values on automaton transitions.

``AutomatonQTable`` holds ``q[w, sigma]`` and ``counts[w, sigma]`` over the automaton
states and label masks of one task (dense: ``(n_states, 2**n_props)``), with the
automaton's fingerprint so that it cannot be applied to another task by mistake.

* ``dynamic_distillation``: from a teacher's replay, the mean Q of the action taken, per
  (w, sigma) (the paper's Eq. 3-4; the authors' code uses the taken action, not the max).
* ``static_distillation``: value iteration over the abstract MDP whose states are
  automaton states and whose actions are labels (the paper's static baseline).

``DistilledTarget`` is the students' one change (Eq. 5-6): Q' = beta Q_teacher +
(1 - beta) Q_target with beta = rho ** eta_student(w, sigma), beta = 0 where the teacher
has no value. It holds the rule's settings and a student's counts (a saved student keeps
it); the population engine applies it (``craftsuite.population.targets.MemberTargets``).
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..automata import Automaton
from ..files import atomic_path, file_to_read
from ..methods import TARGET_DEFAULTS, check_target

FORMAT_VERSION = 1


class DistillationError(ValueError):
    """A distilled table that cannot be used here (corrupt, or made for another automaton)."""


@dataclass
class AutomatonQTable:
    q: np.ndarray  # (n_states, n_labels) float64; meaningless where counts == 0
    counts: np.ndarray  # (n_states, n_labels) int64: teacher transitions behind each value
    fingerprint: str
    propositions: tuple[str, ...]
    kind: str  # "dynamic" or "static"

    @property
    def seen(self) -> np.ndarray:
        return self.counts > 0

    def check(self, automaton: Automaton) -> None:
        """Raise DistillationError unless the table was made for this automaton."""
        if self.fingerprint != automaton.fingerprint or self.q.shape != automaton.delta.shape:
            raise DistillationError(
                f"this {self.kind} table was distilled for automaton {self.fingerprint} over "
                f"{', '.join(self.propositions)} ({self.q.shape[0]} states x {self.q.shape[1]} labels), not for "
                f"{automaton.fingerprint} over {', '.join(automaton.propositions)} ({automaton.formula!r}, "
                f"{automaton.delta.shape[0]} states x {automaton.delta.shape[1]} labels)"
            )

    def edge_values(self, automaton: Automaton) -> dict[tuple[int, int], float]:
        """Mean value per (source, target) edge over its seen labels (for drawings)."""
        self.check(automaton)
        out = {}
        for s, t in automaton.edges(include_sink=True):
            sel = (automaton.delta[s] == t) & self.seen[s]
            if sel.any():
                out[(s, t)] = float(np.average(self.q[s, sel], weights=self.counts[s, sel]))
        return out

    def describe(self, automaton: Automaton) -> str:
        values = self.edge_values(automaton)
        lines = [f"{self.kind} automaton Q-table for {automaton.formula}"]
        for s, t in automaton.edges(include_sink=True):
            v = values.get((s, t))
            lines.append(f"  {s} -> {t} [{automaton.guard(s, t, sink_free=True)}]: "
                         + (f"{v:.2f}" if v is not None else "unseen"))
        return "\n".join(lines)

    def save(self, path) -> Path:
        """Write the table at ``path`` (atomically).

        Raises:
            DistillationError: values that are not all finite (a teacher that diverged), named.
        """
        path = Path(path)
        self.check_finite()
        meta = {"format": FORMAT_VERSION, "fingerprint": self.fingerprint, "kind": self.kind,
                "propositions": list(self.propositions)}
        with atomic_path(path) as tmp, open(tmp, "wb") as f:  # a crash never leaves half a table behind
            np.savez(f, q=self.q, counts=self.counts, meta=np.array(json.dumps(meta)))
        return path

    def check_finite(self) -> None:
        """Raise a DistillationError where the values are not all finite (a teacher that
        diverged), naming the first edge: before the table is written, or drawn."""
        _refuse_nonfinite(self.q, "the table's")

    @classmethod
    def load(cls, path, automaton: Automaton | None = None) -> AutomatonQTable:
        """The table saved at ``path``; with ``automaton``, checked to be made for it.

        Raises:
            IsADirectoryError: a directory at ``path`` (the table file in it named).
            FileNotFoundError: no file at ``path``.
            DistillationError: the file is no distilled table (not an .npz archive, arrays
                missing or unreadable, another format) or was made for another automaton;
                the message names the file and what is wrong.
        """
        path = file_to_read(path, "distilled table", ("table.npz",))  # a teacher's run directory, most likely
        if not path.is_file():
            raise FileNotFoundError(f"no distilled table at {path}")
        where = f"{path} is not a CraftSuite distilled table"
        if not zipfile.is_zipfile(path):  # np.load would guess a pickle and advise allow_pickle, which misleads
            raise DistillationError(f"{where}: not an .npz archive (a table is written by `craftsuite teacher` "
                                    "or `craftsuite distill`)")
        try:
            with np.load(path, allow_pickle=False) as f:
                missing = [name for name in ("q", "counts", "meta") if name not in f.files]
                if missing:
                    raise DistillationError(f"{where}: it lacks the arrays {', '.join(missing)} (it has "
                                            f"{', '.join(sorted(f.files)) or 'none'})")
                meta = json.loads(str(f["meta"]))
                q, counts = f["q"], f["counts"]
        except DistillationError:
            raise
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as err:  # damaged inside
            raise DistillationError(f"{where}: its arrays cannot be read ({type(err).__name__}: {err}); "
                                    "it is damaged: distil the teacher again") from None
        if not isinstance(meta, dict) or meta.get("format") != FORMAT_VERSION:
            version = meta.get("format") if isinstance(meta, dict) else None
            raise DistillationError(f"{path}: unsupported table format {version!r} (this CraftSuite reads "
                                    f"format {FORMAT_VERSION})")
        if q.ndim != 2 or q.shape != counts.shape:
            raise DistillationError(f"{where}: q {q.shape} and counts {counts.shape} must be one matrix shape "
                                    "(automaton states x labels)")
        _refuse_nonfinite(q, f"{path}'s")
        try:
            table = cls(q=q, counts=counts, fingerprint=meta["fingerprint"],
                        propositions=tuple(meta["propositions"]), kind=meta["kind"])
        except (KeyError, TypeError) as err:
            raise DistillationError(f"{where}: its metadata lacks {err}") from None
        if automaton is not None:
            try:
                table.check(automaton)
            except DistillationError as err:
                raise DistillationError(f"{path} does not fit this task: {err}") from None
        return table


def _refuse_nonfinite(q: np.ndarray, whose: str) -> None:
    """A DistillationError where ``q`` holds NaN or infinity, naming the first edge: a student
    would train towards it, and fail only much later (NaN actions)."""
    broken = np.argwhere(~np.isfinite(q))
    if len(broken):
        w, sigma = broken[0]
        raise DistillationError(f"{whose} values are not all finite ({len(broken)} of {q.size}, the first "
                                f"{q[w, sigma]} on the edge from automaton state {w} under label {sigma}): its teacher "
                                "diverged, or the file was edited; train and distil the teacher again")


def dynamic_distillation(automaton: Automaton, w: np.ndarray, sigma: np.ndarray,
                         q_taken: np.ndarray) -> AutomatonQTable:
    """Mean teacher Q of the taken action per (w, sigma) over a teacher's transitions."""
    w, sigma = np.asarray(w).reshape(-1), np.asarray(sigma).reshape(-1)
    q_taken = np.asarray(q_taken, dtype=np.float64).reshape(-1)
    if not (len(w) == len(sigma) == len(q_taken)):
        raise ValueError("w, sigma and q_taken must have one entry per transition")
    shape = automaton.delta.shape
    if len(w) and (w.max() >= shape[0] or sigma.max() >= shape[1] or min(w.min(), sigma.min()) < 0):
        raise DistillationError("transitions name automaton states or labels this automaton does not have")
    sums = np.zeros(shape)
    counts = np.zeros(shape, dtype=np.int64)
    np.add.at(sums, (w, sigma), q_taken)
    np.add.at(counts, (w, sigma), 1)
    q = np.divide(sums, counts, out=np.zeros(shape), where=counts > 0)
    return AutomatonQTable(q, counts, automaton.fingerprint, automaton.propositions, "dynamic")


def static_distillation(automaton: Automaton, step_reward: float = -0.1, progress_reward: float = 1.0,
                        completion_reward: float = 100.0, gamma: float = 0.99,
                        tolerance: float = 1e-10) -> AutomatonQTable:
    """Value iteration over the automaton alone, with the authors' rewards.

    Each label is an action: -0.1 per transition, +1 when the automaton state changes,
    +100 on reaching acceptance. Accepting states and the rejecting sink end the episode
    (CraftSuite ends episodes there); entering the sink is no progress (no +1).
    """
    delta = automaton.delta.astype(np.int64)
    accepting, rejecting = automaton.accepting, automaton.rejecting
    terminal = accepting | rejecting
    changed = delta != np.arange(len(delta))[:, None]
    reward = (step_reward + progress_reward * (changed & ~rejecting[delta])
              + completion_reward * accepting[delta])
    cont = (~terminal[delta]).astype(np.float64)
    v = np.zeros(len(delta))
    for _ in range(100_000):
        q = reward + gamma * cont * v[delta]
        v_new = np.where(terminal, 0.0, q.max(axis=1))
        if np.abs(v_new - v).max() < tolerance:
            v = v_new
            break
        v = v_new
    q = reward + gamma * cont * v[delta]
    counts = np.where(terminal[:, None], 0, 1) * np.ones_like(delta)
    return AutomatonQTable(q, counts.astype(np.int64), automaton.fingerprint, automaton.propositions, "static")


class DistilledTarget:
    """The students' target: Q' = beta Q_teacher(w, sigma) + (1 - beta) Q_target.

    beta = rho ** eta_student(w, sigma), where eta_student counts how often (w, sigma) was
    sampled in the student's minibatches before this one (the first use trusts the teacher
    fully); beta = 0 where the teacher has no value. Counts go up by one per sampled
    transition, duplicates in a minibatch included.

    ``self_loops=False`` (not in the paper) also sets beta = 0 on labels that leave the
    automaton state unchanged, so the teacher speaks only about progress: its self-loop
    values average over every world state of an automaton state and, trusted early, give
    the student flat, optimistic values that gamma takes long to wash out
    (``experiments/self-loops``).
    """

    def __init__(self, table: AutomatonQTable, automaton: Automaton, rho: float = TARGET_DEFAULTS["rho"],
                 self_loops: bool = TARGET_DEFAULTS["self_loops"]):
        table.check(automaton)
        check_target(rho, self_loops)
        self.table, self.rho, self.self_loops = table, rho, self_loops
        self.q_teacher = table.q.astype(np.float32)
        self.seen = table.seen
        if not self_loops:  # only transitions that change the automaton state carry the teacher's value
            self.seen = self.seen & (automaton.delta != np.arange(len(automaton.delta))[:, None])
        self.student_counts = np.zeros(table.q.shape, dtype=np.int64)
