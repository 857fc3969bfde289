"""The distilled target as the population engine applies it (``MemberTargets``), against
hand-computed numbers, and the paper's Theorem 1 (tabular: distilled Q-learning converges
to Q*)."""

from __future__ import annotations

import numpy as np
import pytest
import torch as th

from craftsuite.agents import DistilledTarget
from craftsuite.population.targets import MemberTargets

from ..agents.test_distillation import SHIELD, SWORD, TOY, table


class OneMember:
    """A member's distilled target over a minibatch ``(B,)``: ``MemberTargets`` for K = 1."""

    def __init__(self, rule: DistilledTarget):
        self.targets = MemberTargets(rule, 1)

    def __call__(self, w, sigma, q_target: th.Tensor) -> th.Tensor:
        return self.targets(np.asarray(w)[None], np.asarray(sigma)[None], q_target[None])[0]

    def counts(self) -> np.ndarray:
        return self.targets.counts[0].reshape(TOY.delta.shape)


def test_target_anneals_from_teacher_to_td_target():
    target = OneMember(DistilledTarget(table({(0, SWORD): 10.0}), TOY, rho=0.5))
    q_target = th.full((1, 1), 2.0)
    got = [float(target(np.array([0]), np.array([SWORD]), q_target)) for _ in range(4)]
    # beta = 0.5 ** (times sampled before): 1, 0.5, 0.25, 0.125
    assert got == pytest.approx([10.0, 6.0, 4.0, 3.0])


def test_counts_rise_per_sampled_transition_including_duplicates():
    target = OneMember(DistilledTarget(table({(0, SWORD): 10.0, (0, SHIELD): 20.0}), TOY, rho=0.5))
    w, sigma = np.array([0, 0, 0]), np.array([SWORD, SWORD, SHIELD])
    first = target(w, sigma, th.zeros((3, 1))).reshape(-1).tolist()
    assert first == pytest.approx([10.0, 10.0, 20.0])  # counts are read before the batch
    assert target.counts()[0, SWORD] == 2 and target.counts()[0, SHIELD] == 1
    second = target(w, sigma, th.zeros((3, 1))).reshape(-1).tolist()
    assert second == pytest.approx([2.5, 2.5, 10.0])  # 0.5**2 * 10, 0.5**1 * 20
    saved = target.targets.member(0)  # what a saved student keeps: its counts
    assert saved.student_counts[0, SWORD] == 4 and saved.student_counts[0, SHIELD] == 2


def test_transitions_the_teacher_never_saw_use_the_td_target():
    target = OneMember(DistilledTarget(table({(0, SWORD): 10.0}), TOY, rho=0.999))
    out = target(np.array([0, 1]), np.array([SHIELD, SWORD]), th.tensor([[3.0], [4.0]]))
    assert out.reshape(-1).tolist() == pytest.approx([3.0, 4.0])


def test_without_self_loops_the_teacher_speaks_only_about_progress():
    values = {(0, 0): 50.0, (0, SWORD): 10.0}  # label {} keeps state 0, {sword} leaves it
    assert TOY.delta[0, 0] == 0 and TOY.delta[0, SWORD] != 0
    w, sigma, td = np.array([0, 0]), np.array([0, SWORD]), th.tensor([[3.0], [4.0]])
    paper = OneMember(DistilledTarget(table(values), TOY, rho=0.999))
    assert paper(w, sigma, td).reshape(-1).tolist() == pytest.approx([50.0, 10.0])
    progress_only = OneMember(DistilledTarget(table(values), TOY, rho=0.999, self_loops=False))
    assert progress_only(w, sigma, td).reshape(-1).tolist() == pytest.approx([3.0, 10.0])


# -- the paper's Theorem 1, tabular: distilled Q-learning converges to Q* ------------------------
def corridor(n=5):
    """Sword at cell 0, shield at cell n-1, actions left/right; labels on entering a cell."""
    nxt = np.array([[max(c - 1, 0), min(c + 1, n - 1)] for c in range(n)])
    label = np.array([[SWORD if m == 0 and m != c else SHIELD if m == n - 1 and m != c else 0
                       for m in row] for c, row in enumerate(nxt)])
    return nxt, label


def product_q_star(nxt, label, gamma):
    n, S = len(nxt), TOY.n_states
    q = np.zeros((n, S, 2))
    for _ in range(2000):
        v = q.max(axis=2)
        for c in range(n):
            for w in range(S):
                for a in range(2):
                    w2 = TOY.step(w, int(label[c, a]))
                    done = TOY.accepting[w2]
                    q[c, w, a] = -0.1 + 100 * done + (0 if done else gamma * v[nxt[c, a], w2])
    return q


def test_theorem1_distilled_q_learning_converges_to_q_star():
    gamma = 0.9
    nxt, label = corridor()
    q_star = product_q_star(nxt, label, gamma)
    rng = np.random.default_rng(0)
    wrong = table({(w, s): rng.uniform(-50, 200) for w in range(4) for s in range(4)})
    target = OneMember(DistilledTarget(wrong, TOY, rho=0.99))
    n, S = len(nxt), TOY.n_states
    live = [(c, w, a) for c in range(n) for w in range(S) for a in range(2) if not TOY.accepting[w]]
    cs, ws, acts = map(np.array, zip(*live))
    w2 = np.array([TOY.step(int(w), int(label[c, a])) for c, w, a in live])
    sig = label[cs, acts]
    done = TOY.accepting[w2]
    reward = -0.1 + 100 * done
    q = np.zeros((n, S, 2))
    for t in range(1, 3001):  # synchronous Q-learning: every live (s, w, a) once per sweep
        td = reward + np.where(done, 0.0, gamma * q[nxt[cs, acts], w2].max(axis=1))
        mixed = target(ws, sig, th.as_tensor(td, dtype=th.float32).reshape(-1, 1)).numpy().reshape(-1)
        alpha = 1.0 / t ** 0.6
        q[cs, ws, acts] += alpha * (mixed - q[cs, ws, acts])
    live_mask = ~TOY.accepting[np.arange(S)]
    assert np.abs(q[:, live_mask] - q_star[:, live_mask]).max() < 0.5
    # early on the wrong teacher dominated: the error shrank because beta -> 0
    assert (wrong.seen[ws, sig] * 0.99 ** target.counts()[ws, sig]).max() < 1e-3
