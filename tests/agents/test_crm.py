"""CRM counterfactuals: rewards and dones computed for each automaton state."""

from __future__ import annotations

import numpy as np
import pytest

from craftsuite.agents.crm import counterfactuals
from craftsuite.automata import compile_ltlf

DQ = compile_ltlf("F(dragon) & (key R !sword) & (sword R !dragon) & (shield R !dragon)",
                  ("key", "shield", "sword", "dragon"), cache=False)
S = DQ.n_states


def product_obs(w, world=(0.5, 0.25)):
    one_hot = np.zeros(S, np.float32)
    one_hot[w] = 1
    return np.concatenate([np.array(world, np.float32), one_hot])


def test_dragon_counterfactuals():
    dragon = DQ.mask(["dragon"])
    armed = DQ.run([DQ.mask(["key"]), DQ.mask(["shield"]), DQ.mask(["sword"])])
    w = DQ.initial  # the real agent met the dragon unarmed: a violation, reward -0.1
    live, u_next, obs, nxt, actions, rewards, dones, timeouts = counterfactuals(
        DQ, 100.0, product_obs(w), product_obs(int(DQ.delta[w, dragon])), 2, -0.1, False, w, dragon)
    assert len(live) == (~(DQ.accepting | DQ.rejecting)).sum() == 6
    row = {int(u): i for i, u in enumerate(live)}
    # from the armed state the same step wins: the completion bonus, and the episode ends
    i = row[armed]
    assert DQ.accepting[u_next[i]] and rewards[i] == pytest.approx(99.9) and dones[i]
    # from the start state it is the violation the agent really had
    j = row[w]
    assert DQ.rejecting[u_next[j]] and rewards[j] == pytest.approx(-0.1) and dones[j]
    assert not timeouts.any()
    # the one-hots are rewritten, the world part is untouched
    assert obs[i, 2:].argmax() == armed and nxt[i, 2:].argmax() == u_next[i]
    assert (obs[:, :2] == product_obs(w)[:2]).all() and (actions == 2).all()


def test_real_completion_bonus_is_not_given_to_other_states():
    dragon = DQ.mask(["dragon"])
    armed = DQ.run([DQ.mask(["key"]), DQ.mask(["shield"]), DQ.mask(["sword"])])
    live, u_next, *_, rewards, dones, _ = counterfactuals(
        DQ, 100.0, product_obs(armed), product_obs(int(DQ.delta[armed, dragon])), 0, 99.9, False, armed, dragon)
    for u, r in zip(live, rewards):
        assert r == pytest.approx(99.9 if u == armed else -0.1)


def test_nothing_happens_step_and_timeouts():
    live, u_next, *_, rewards, dones, timeouts = counterfactuals(
        DQ, 100.0, product_obs(0), product_obs(0), 1, -0.1, True, 0, 0)
    assert (u_next == live).all()  # no label: every state stays where it is
    assert np.allclose(rewards, -0.1)
    assert dones.all() and timeouts.all()  # the time limit cut them all; none is terminal
