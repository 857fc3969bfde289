"""Potential-based reward shaping from the automaton: the reward-machine literature's
baseline (Toro Icarte et al., JAIR 2022, "RS"), with the automaton's values as potential
(their code takes minus the values, with a discount and scale of its own; a row's
``potential_sign=-1`` takes their sign; either keeps the optimal policy).

A shaped step pays ``r + gamma * Phi(w') - Phi(w)`` (Ng, Harada and Russell 1999), which
leaves the optimal policy unchanged: over any trajectory the added terms telescope to
``gamma ** k * Phi(w_k) - Phi(w_0)``, a function of where it starts and ends. ``Phi(w)`` is
the best value of leaving automaton state w that a table of automaton values holds (value
iteration over the automaton alone for ``rs``, a teacher's distilled values for
``dynamic-rs``); an episode's end has potential 0 (its accepting and rejecting states, and
any terminal step), as the invariance needs. An n-step sample pays the shaped rewards of
its k steps, which sum to ``R + gamma ** k * Phi(w_k) - Phi(w_0)``.
"""

from __future__ import annotations

import numpy as np

from .automata import Automaton


def potential(table, automaton: Automaton) -> np.ndarray:
    """Phi per automaton state from an ``AutomatonQTable``: the largest value of a label the
    table has seen from the state; 0 where it has seen none and at accepting and rejecting
    states (an episode ends there)."""
    table.check(automaton)
    seen = table.counts > 0
    best = np.where(seen, table.q, -np.inf).max(axis=1)
    phi = np.where(np.isfinite(best), best, 0.0)
    return np.where(automaton.accepting | automaton.rejecting, 0.0, phi)


class Shaping:
    """Shaped rewards of sampled steps, for one automaton and potential."""

    def __init__(self, automaton: Automaton, phi: np.ndarray, gamma: float):
        self.delta = automaton.delta.astype(np.int64)
        self.phi = np.asarray(phi, dtype=np.float64)
        self.gamma = float(gamma)

    def __call__(self, rewards, w, last_w, last_sigma, terminals, discounts=None) -> np.ndarray:
        """Rewards (one step's, or an n-step sample's discounted sum) shaped: the potential
        after the sample's last step (``last_w``, ``last_sigma``: its automaton pair),
        discounted by ``discounts`` (gamma ** k; None: one step, gamma), 0 after a terminal
        step, less the potential of the first step's state ``w``."""
        after = self.phi[self.delta[last_w, last_sigma]] * (1.0 - terminals)
        discount = self.gamma if discounts is None else discounts
        return (rewards + discount * after - self.phi[w]).astype(np.float32)
