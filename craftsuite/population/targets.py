"""The distilled target for K members: ``agents.distillation.DistilledTarget``'s rule with
one count table per member (each member's own minibatches decide how far it trusts the
teacher), the teacher's table shared; and the bootstrap's discount of a minibatch.

With n-step returns the rule mixes the teacher in after the n-step target
r_0 + ... + gamma^(k-1) r_(k-1) + gamma^k Q(s_k) is made, with the (w, sigma) of the
sample's first step, the one its action took (the replay's ``Batch`` holds ``w``, ``sigma``
at the window's start, not at its k-th step): the teacher's Q(w, sigma) is its value of
that first transition, which the target estimates; the student's count of that pair is
the one that goes up.
"""

from __future__ import annotations

import numpy as np
import torch as th

from ..agents.distillation import DistilledTarget


class MemberTargets:
    """Q' = beta Q_teacher(w, sigma) + (1 - beta) Q_target, beta = rho ** count_k(w, sigma)
    where the teacher has a value (``DistilledTarget``), counted per member ``k``."""

    def __init__(self, rule: DistilledTarget, members: int):
        self.rule = rule
        self.members = members
        self.n_labels = rule.q_teacher.shape[1]
        self.cells = rule.q_teacher.size
        self.counts = np.zeros((members, self.cells), dtype=np.int64)
        # the rule's public tables, flat: one fancy index per array per minibatch
        self._seen = rule.seen.reshape(-1).astype(np.float32)
        self._teacher = rule.q_teacher.reshape(-1)
        self._offsets = (np.arange(members) * self.cells)[:, None]  # member k's counts

    def __call__(self, w: np.ndarray, sigma: np.ndarray, q_target: th.Tensor) -> th.Tensor:
        """``w``, ``sigma`` ``(K, B)``; ``q_target`` ``(K, B, 1)``."""
        flat = w * self.n_labels + sigma
        own = flat + self._offsets
        mix = np.empty((2, *flat.shape), dtype=np.float32)
        mix[0] = self._seen[flat] * self.rule.rho ** self.counts.reshape(-1)[own]  # beta
        mix[1] = self._teacher[flat]
        np.add.at(self.counts.reshape(-1), own.reshape(-1), 1)
        beta, teacher = th.from_numpy(mix).to(q_target.device).reshape(2, *q_target.shape)
        return q_target + beta * (teacher - q_target)

    def member(self, k: int) -> DistilledTarget:
        """Member ``k``'s rule as an ``DistilledTarget`` with its counts (what a saved agent keeps)."""
        import copy

        rule = copy.deepcopy(self.rule)
        rule.student_counts[...] = self.counts[k].reshape(rule.student_counts.shape)
        return rule


def discount(batch, gamma: float, device) -> float | th.Tensor:
    """What the bootstrap of ``batch`` is discounted by: ``gamma`` for one-step samples
    (the very float the one-step target always used), ``gamma ** k`` per sample ``(K, B, 1)``
    after an n-step sample's k rewards."""
    if batch.discounts is None:
        return gamma
    return th.as_tensor(batch.discounts, device=device).reshape(*batch.discounts.shape, 1)
