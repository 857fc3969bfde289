"""Potential-based reward shaping (``rs``, ``dynamic-rs`` and their TD3 rows): the shaped
optimum is the unshaped one, the replay shapes what it samples (one step and n steps), the
population engine trains it, and its members save as their method."""

from __future__ import annotations

import numpy as np
import pytest

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.agents.distillation import static_distillation
from craftsuite.configs import StudentConfig
from craftsuite.methods import METHODS, Method, MethodError
from craftsuite.population import train_population
from craftsuite.population.replay import PopulationReplay
from craftsuite.shaping import Shaping, potential
from craftsuite.task_registry import resolve_task

GAMMA = 0.99


def _line_world(automaton, length=7, wood=1, factory=5, step=-0.1, completion=100.0):
    """FirstTool on a line: positions 0..length-1, moves left, stay, right; ``wood`` labels
    the wood's cell, ``factory`` the factory's. Returns (next state index, reward, terminal,
    label, automaton state of the source) per (state, action), states (position, w)."""
    labels = np.zeros(length, dtype=np.int64)
    labels[wood], labels[factory] = 1, 2  # the propositions' bits: wood, factory
    n_w = automaton.n_states
    states = [(x, w) for x in range(length) for w in range(n_w)]
    index = {s: i for i, s in enumerate(states)}
    out = np.zeros((len(states), 3, 5))
    for (x, w), i in index.items():
        for a, move in enumerate((-1, 0, 1)):
            x2 = min(max(x + move, 0), length - 1)
            w2 = int(automaton.delta[w, labels[x2]])
            terminal = bool(automaton.accepting[w2] or automaton.rejecting[w2])
            out[i, a] = (index[(x2, w2)], step + completion * automaton.accepting[w2], terminal, labels[x2], w)
    return states, out


def _q_values(table, rewards):
    """Value iteration over the line world, with the rewards given per (state, action)."""
    nxt, term = table[..., 0].astype(int), table[..., 2]
    q = np.zeros(rewards.shape)
    for _ in range(5000):
        q = rewards + GAMMA * (1 - term) * q.max(axis=1)[nxt]
    return q


@pytest.mark.parametrize("sign", [1, -1])  # Phi = V, and Phi = -V (the sign of Toro Icarte et al.'s code)
def test_the_shaped_optimum_is_the_unshaped_one_on_a_tabular_task(sign):
    spec = resolve_task("FirstTool")
    a = spec.automaton
    states, table = _line_world(a)
    phi = sign * potential(static_distillation(a, completion_reward=spec.completion_reward), a)
    assert sign * phi[0] > 0 and phi[a.accepting].max() == 0  # a potential that says something, 0 where episodes end
    shape = Shaping(a, phi, GAMMA)
    w, sigma, term = table[..., 4].astype(int), table[..., 3].astype(int), table[..., 2]
    rewards = table[..., 1]
    shaped = shape(rewards, w, w, sigma, term)
    assert not np.allclose(shaped, rewards)
    q, q_shaped = _q_values(table, rewards), _q_values(table, shaped.astype(np.float64))
    live = np.array([not (a.accepting[s[1]] or a.rejecting[s[1]]) for s in states])
    # Ng et al.: Q' = Q - Phi(w), so the greedy policy is the same in every state
    np.testing.assert_allclose(q_shaped[live], (q - phi[w])[live], atol=1e-3)
    assert (q_shaped[live].argmax(axis=1) == q[live].argmax(axis=1)).all()


@pytest.mark.parametrize("n_steps", [1, 3])
def test_the_replay_shapes_each_sample_from_its_first_state_to_the_state_after_its_last_step(n_steps):
    spec = resolve_task("FirstTool")
    a = spec.automaton
    phi = np.array([5.0, 40.0, 0.0])
    shape = Shaping(a, phi, 0.5)
    replay = PopulationReplay(1, 40, 1, 1, (), np.int64, prioritized=False, seed=0, n_steps=n_steps, gamma=0.5,
                              shaping=shape)
    plain = PopulationReplay(1, 40, 1, 1, (), np.int64, prioritized=False, seed=0, n_steps=n_steps, gamma=0.5)
    # an episode: no label, the wood (w 0 -> 1), no label, the factory (1 -> 2: accepted, terminal)
    for t, (w, sigma) in enumerate([(0, 0), (0, 1), (1, 0), (1, 2)]):
        for r in (replay, plain):
            r.add(np.full((1, 1, 1), t, np.float32), np.full((1, 1, 1), t + 1, np.float32), np.zeros((1, 1)),
                  np.full((1, 1), float(t)), np.full((1, 1), float(t == 3)), np.full((1, 1), w), np.full((1, 1), sigma),
                  np.full((1, 1), t == 3))
    got, want = replay.sample(64), plain.sample(64)
    assert (got.observations == want.observations).all()  # the same draws: only the rewards differ
    for b in range(64):
        t = int(got.observations[0, b, 0])
        last = int(got.next_observations[0, b, 0]) - 1
        after = a.delta[[0, 0, 1, 1][last], [0, 1, 0, 2][last]]
        discount = 0.5 if got.discounts is None else got.discounts[0, b]
        expected = want.rewards[0, b] + discount * (1 - got.terminals[0, b]) * phi[after] - phi[[0, 0, 1, 1][t]]
        assert got.rewards[0, b] == pytest.approx(expected)


def test_shaping_rows_train_in_the_population_engine_and_save_as_their_method(tmp_path):
    from craftsuite.agents.factory import load_agent

    table = static_distillation(resolve_task("FirstTool").automaton, completion_reward=100.0).save(tmp_path / "t.npz")
    tiny = {"learning_starts": 100, "batch_size": 16, "policy_kwargs": {"net_arch": [16]}, "n_steps": 3}
    runs = [run for method in ("rs", "dynamic-rs") for run in train_population(
        [StudentConfig(task="FirstTool", method=method, world="Grid7", steps=300, eval_every=150, eval_episodes=1,
                       engine="population", hyperparameters=tiny,
                       table=str(table) if METHODS[method].needs_table else None)], tmp_path / "runs", progress=False)]
    assert all((r / "result.json").exists() for r in runs)
    assert [load_agent(r / "model.zip").n_steps for r in runs] == [3, 3]


def test_a_shaping_row_is_a_method_of_its_own():
    with pytest.raises(MethodError, match="shaping is a method of its own"):
        Method("x", "Grid", "dqn", True, "static", shaping="static")
    with pytest.raises(MethodError, match="shaping must be one of"):
        Method("x", "Grid", "dqn", True, shaping="learned")
    assert METHODS["dynamic-rs"].needs_table and not METHODS["rs"].needs_table
    assert "shaping" not in METHODS["dqn"].settings() and METHODS["td3-rs"].settings()["shaping"] == "static"


def test_the_potentials_sign_is_a_rows_and_only_a_shaping_rows():
    with pytest.raises(MethodError, match="potential_sign is 1 or -1"):
        Method("x", "Cont", "td3", True, shaping="static", potential_sign=0)
    with pytest.raises(MethodError, match="-1 only with shaping"):
        Method("x", "Cont", "td3", True, potential_sign=-1)
    with pytest.raises(MethodError, match="potential_sign is 1 or -1"):
        Method("x", "Cont", "td3", True, shaping="static", potential_sign=-1.0)
    negated = Method("x", "Cont", "td3", True, shaping="static", potential_sign=-1)
    # a row with Phi = -V records it (its runs are keyed apart); Phi = V rows record what they always did
    assert negated.settings()["potential_sign"] == -1 and "potential_sign" not in METHODS["td3-rs"].settings()
    # and it reaches a spawned worker whole (rows from outside the package travel as data)
    from craftsuite.methods import external_rows, register_method

    register_method(negated)
    (shipped,) = [row for row in external_rows() if row["name"] == "x"]
    assert Method(**shipped) == negated


def test_the_engine_shapes_with_the_rows_sign(tmp_path, monkeypatch):
    from craftsuite.methods import register_method
    from craftsuite.population import engine

    made = []
    monkeypatch.setattr(engine, "Shaping", lambda automaton, phi, gamma: made.append(phi) or Shaping(automaton, phi,
                                                                                                     gamma))
    register_method(Method("rs-negated", "Grid", "dqn", True, shaping="static", potential_sign=-1))
    tiny = {"learning_starts": 100, "batch_size": 16, "policy_kwargs": {"net_arch": [16]}}
    for method in ("rs", "rs-negated"):
        train_population([StudentConfig(task="FirstTool", method=method, world="Grid7", steps=200, eval_every=200,
                                        eval_episodes=1, engine="population", hyperparameters=tiny)],
                         tmp_path / method, progress=False)
    assert made[0][0] > 0 and np.array_equal(made[1], -made[0])
