"""How far along its task a training episode got: ``episodes.csv``'s ``seen`` and ``states``.

``seen`` is the bitmask of the task's propositions that were true at some step of the
episode (bit i: the automaton's ``propositions[i]``, the labels' own bit order); ``states``
the bitmask of the automaton states it visited (bit q: state q), its initial state
included. Both trainers keep them with ``Reached``, per env, from each step's label mask
and automaton state; ``craftsuite.reporting.obstacles`` reads them back.
"""

from __future__ import annotations

import numpy as np

# state q is bit q of a signed 64-bit integer: states 0 to 62 keep it positive, as the CSV
# log writes it and every reader parses it
MAX_STATES = 63


def check_automaton(automaton, task: str) -> None:
    """Raise ValueError for an automaton whose states do not fit ``states``'s bits."""
    if automaton.n_states > MAX_STATES:
        raise ValueError(f"task {task!r}: its automaton has {automaton.n_states} states, but episodes.csv's "
                         f"'states' column holds states 0 to {MAX_STATES - 1} as the bits of one 64-bit integer; "
                         "a task this large needs another record of the states its episodes visit")


def bits(mask: int) -> list[int]:
    """The set bits of ``mask``, lowest first."""
    return [i for i in range(mask.bit_length()) if mask >> i & 1]


class Reached:
    """The ``seen`` and ``states`` of the current episode of each of ``n_envs`` envs."""

    def __init__(self, automaton, n_envs: int, task: str = ""):
        check_automaton(automaton, task or automaton.formula)
        self._start = np.int64(1) << np.int64(automaton.initial)  # every episode starts there
        self.seen = np.zeros(n_envs, dtype=np.int64)
        self.states = np.full(n_envs, self._start, dtype=np.int64)

    def step(self, masks, states) -> None:
        """One step of every env: its label mask and the automaton state it ends in (under a
        same-step autoreset, the ending step's, not the next episode's start)."""
        self.seen |= masks
        self.states |= np.left_shift(np.int64(1), states)

    def take(self, ended) -> tuple[list[int], list[int]]:
        """The ``seen`` and ``states`` of the episodes that just ended (``ended``: a bool mask
        or indices, in that order), as Python ints; those envs start their next episode."""
        seen, states = self.seen[ended].tolist(), self.states[ended].tolist()
        self.seen[ended] = 0
        self.states[ended] = self._start
        return seen, states
