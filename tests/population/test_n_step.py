"""n-step returns in the population engine: its replay samples them (by hand on tiny
replays; the learning rule on them: the frozen ``*-n3`` cases), its distilled target mixes
the teacher in at the first step's automaton pair, a population trains with them, and with
CRM (n-step CRM) too."""

import json

import gymnasium as gym
import numpy as np
import pytest
import torch as th

import craftsuite  # noqa: F401
from craftsuite.agents import AutomatonQTable, DistilledTarget
from craftsuite.agents.distillation import static_distillation
from craftsuite.agents.factory import load_agent
from craftsuite.configs import StudentConfig
from craftsuite.hyperparameters import algorithm_settings
from craftsuite.population import Population, train_population
from craftsuite.population.dqn import PopulationDQN
from craftsuite.population.replay import Batch, CounterfactualView, PopulationReplay
from craftsuite.population.targets import MemberTargets
from craftsuite.population.td3 import PopulationTD3
from craftsuite.runs import read_csv
from craftsuite.task_registry import resolve_task


def _replay(members, steps, n_envs, rewards, ended, terminated, n_steps=3, gamma=0.5):
    """A uniform replay of ``steps`` vector-step slots holding, for t = 0, 1, ...: member k's
    env e observing 10 e + t, next 10 e + t + 0.5, reward ``rewards[k][e][t]``, automaton
    pair (w, sigma) = (t, e); an episode ends after the steps in ``ended[k][e]``, by a
    terminal state where also in ``terminated[k][e]`` (else by the time limit)."""
    replay = PopulationReplay(members, steps * n_envs, n_envs, 1, (), np.int64, prioritized=False, seed=0,
                              n_steps=n_steps, gamma=gamma)
    for t in range(len(rewards[0][0])):
        obs = np.broadcast_to((10 * np.arange(n_envs) + t)[None, :, None], (members, n_envs, 1)).astype(np.float32)
        def at(table):
            return np.array([[t in table[k][e] for e in range(n_envs)] for k in range(members)])
        replay.add(obs, obs + 0.5, np.zeros((members, n_envs)), np.array([[r[t] for r in m] for m in rewards]),
                   at(terminated).astype(np.float32), np.full((members, n_envs), t),
                   np.broadcast_to(np.arange(n_envs), (members, n_envs)), at(ended))
    return replay


def _sampled(replay, member):
    """Every position member ``member`` sampled, as {(t of the window's first step, env):
    (return, discount, terminal, next observation)}; and the first step's pair checked."""
    batch = replay.sample(512)
    got = {}
    for b in range(512):
        env = int(batch.observations[member, b, 0] // 10)
        t = int(batch.observations[member, b, 0] % 10)
        assert (batch.w[member, b], batch.sigma[member, b]) == (t, env)  # the first step's pair, as SB3's
        got[(t, env)] = (float(batch.rewards[member, b]), float(batch.discounts[member, b]),
                         float(batch.terminals[member, b]), float(batch.next_observations[member, b, 0]))
    return got


def test_n_step_samples_stop_at_episode_ends_and_the_newest_step_per_env_and_member():
    # member 0: env 0 terminated after t = 2, env 1 cut by the time limit after t = 1;
    # member 1: no episode ends, rewards negated. t = 4 is the newest step; 10 slots, 5 written.
    r0, r1 = [1, 2, 4, 8, 16], [100, 200, 400, 800, 1600]
    replay = _replay(2, 10, 2, [[r0, r1], [[-r for r in r0], [-r for r in r1]]],
                     ended=[[{2}, {1}], [set(), set()]], terminated=[[{2}, set()], [set(), set()]])
    assert _sampled(replay, 0) == {
        (0, 0): (1 + 0.5 * 2 + 0.25 * 4, 0.125, 1.0, 2.5),  # three rewards, the last terminal
        (1, 0): (2 + 0.5 * 4, 0.25, 1.0, 2.5),
        (2, 0): (4, 0.5, 1.0, 2.5),
        (3, 0): (8 + 0.5 * 16, 0.25, 0.0, 4.5),  # stops at the newest step: t = 5 is not written
        (4, 0): (16, 0.5, 0.0, 4.5),
        (0, 1): (100 + 0.5 * 200, 0.25, 0.0, 11.5),  # the time limit: bootstrapped from its last observation
        (1, 1): (200, 0.5, 0.0, 11.5),
        (2, 1): (400 + 0.5 * 800 + 0.25 * 1600, 0.125, 0.0, 14.5),  # env 1's own steps, not env 0's
        (3, 1): (800 + 0.5 * 1600, 0.25, 0.0, 14.5),
        (4, 1): (1600, 0.5, 0.0, 14.5),
    }
    assert _sampled(replay, 1) == {
        (0, 0): (-(1 + 1 + 1), 0.125, 0.0, 2.5), (1, 0): (-(2 + 2 + 2), 0.125, 0.0, 3.5),
        (2, 0): (-(4 + 4 + 4), 0.125, 0.0, 4.5), (3, 0): (-(8 + 8), 0.25, 0.0, 4.5), (4, 0): (-16, 0.5, 0.0, 4.5),
        (0, 1): (-300, 0.125, 0.0, 12.5), (1, 1): (-600, 0.125, 0.0, 13.5), (2, 1): (-1200, 0.125, 0.0, 14.5),
        (3, 1): (-1600, 0.25, 0.0, 14.5), (4, 1): (-1600, 0.5, 0.0, 14.5),
    }


def test_n_step_windows_never_run_from_the_newest_step_into_the_oldest():
    # four slots, six steps: slots hold t = 4, 5, 2, 3; slot 1 (t = 5) is the newest
    r0 = [1, 2, 4, 8, 16, 32]
    replay = _replay(1, 4, 2, [[r0, [10 * r for r in r0]]], ended=[[set(), set()]], terminated=[[set(), set()]])
    assert replay.full and replay.pos == 4
    got = _sampled(replay, 0)
    assert {key: value for key, value in got.items() if key[1] == 0} == {
        (2, 0): (4 + 0.5 * 8 + 0.25 * 16, 0.125, 0.0, 4.5),  # t = 2, 3, 4 across the wrap
        (3, 0): (8 + 0.5 * 16 + 0.25 * 32, 0.125, 0.0, 5.5),
        (4, 0): (16 + 0.5 * 32, 0.25, 0.0, 5.5),  # stops at the newest step, not on into t = 2
        (5, 0): (32, 0.5, 0.0, 5.5),
    }
    assert got[(4, 1)] == (160 + 0.5 * 320, 0.25, 0.0, 15.5)


def test_the_distilled_target_mixes_in_the_first_steps_automaton_pair():
    """The n-step target, then the teacher's value of the
    window's first (w, sigma), whose count goes up, not the k-th step's."""
    spec = resolve_task("Reach")
    automaton = spec.automaton
    q = np.arange(automaton.delta.size, dtype=np.float64).reshape(automaton.delta.shape) * 10 + 5
    table = AutomatonQTable(q, np.ones_like(q, dtype=np.int64), automaton.fingerprint, automaton.propositions,
                            "dynamic")
    states, labels = automaton.delta.shape
    pairs = [(t % states, (t + 1) % labels) for t in range(5)]  # a different pair at each step
    replay = PopulationReplay(1, 10, 1, 3, (), np.int64, prioritized=False, n_steps=3, gamma=0.5)
    for t, (w, sigma) in enumerate(pairs):
        replay.add(np.full((1, 1, 3), t), np.full((1, 1, 3), t + 0.5), np.zeros((1, 1)), np.array([[1.0]]),
                   np.zeros((1, 1)), np.array([[w]]), np.array([[sigma]]), np.array([[False]]))
    settings = algorithm_settings("dqn", {"policy_kwargs": {"net_arch": [8]}})
    th.manual_seed(0)
    plain = PopulationDQN(1, 3, 4, settings)
    distilled = PopulationDQN(1, 3, 4, settings,
                              MemberTargets(DistilledTarget(table, automaton, rho=0.5, self_loops=True), 1))
    distilled.q_net.load_state_dict(plain.q_net.state_dict())
    distilled.q_net_target.load_state_dict(plain.q_net_target.state_dict())
    batch = replay.sample(64)
    first = np.array([pairs[int(t)] for t in batch.observations[0, :, 0]])
    assert (batch.discounts < 0.2).any()  # some windows run three steps, ending at another pair
    flat = first[:, 0] * labels + first[:, 1]
    distilled.targets.counts[0, flat] = 1  # beta = rho ** 1 = 0.5 on every sampled pair
    own = plain.td_target(batch, plain.inputs(batch.next_observations))[0, :, 0].numpy()
    mixed = distilled.td_target(batch, distilled.inputs(batch.next_observations))[0, :, 0].numpy()
    np.testing.assert_allclose(mixed, own + 0.5 * (q.reshape(-1)[flat] - own), rtol=1e-6)
    expected_counts = np.zeros(automaton.delta.size, dtype=np.int64)
    expected_counts[flat] = 1
    np.add.at(expected_counts, flat, 1)
    np.testing.assert_array_equal(distilled.targets.counts[0], expected_counts)


@pytest.mark.parametrize("algorithm", ["dqn", "td3"])
def test_n_step_targets_bootstrap_with_each_samples_discount(algorithm):
    """r + (1 - terminal) * gamma ** k * Q'(s_k): the sample's discount, not the learner's gamma."""
    rng = np.random.default_rng(0)
    K, B, obs_dim = 2, 4, 3
    discounts = np.array([[0.5, 0.25, 0.125, 0.9], [0.9, 0.81, 0.5, 0.25]], dtype=np.float32)
    terminals = np.array([[0, 0, 1, 0], [0, 1, 0, 0]], dtype=np.float32)
    rewards = rng.normal(size=(K, B)).astype(np.float32)
    next_obs = rng.normal(size=(K, B, obs_dim)).astype(np.float32)
    actions = rng.uniform(-1, 1, size=(K, B, 2)).astype(np.float32) if algorithm == "td3" \
        else rng.integers(4, size=(K, B))
    batch = Batch(next_obs, actions, next_obs, rewards, terminals, np.ones((K, B), np.float32),
                  np.zeros((K, B), np.int64), np.zeros((K, B), np.int64), np.zeros((K, B), np.int64), discounts)
    th.manual_seed(0)
    with th.no_grad():
        if algorithm == "dqn":
            settings = algorithm_settings("dqn", {"policy_kwargs": {"net_arch": [8]}})
            learner = PopulationDQN(K, obs_dim, 4, settings)
            other = PopulationDQN(K, obs_dim, 4, settings).q_net  # a target unlike the online net: double DQN shows
            learner.q_net_target.load_state_dict(other.state_dict())
            x = th.as_tensor(next_obs)
            best = learner.q_values(learner.q_net, x).argmax(dim=-1, keepdim=True)
            next_q = th.gather(learner.q_values(learner.q_net_target, x), -1, best)[..., 0].numpy()
            target = learner.td_target(batch, x)
        else:
            learner = PopulationTD3(K, obs_dim, 2, algorithm_settings("td3", {
                "target_policy_noise": 0.0, "policy_kwargs": {"net_arch": [8]}}))
            x = th.as_tensor(next_obs)
            joint = th.cat([x, learner.actor_target(x)], dim=2)
            next_q = th.min(th.cat([q(joint) for q in learner.critics_target], dim=2), dim=2)[0].numpy()
            target = learner.td_target(batch, x, th.as_tensor(actions))
    np.testing.assert_allclose(target[..., 0].numpy(), rewards + (1 - terminals) * discounts * next_q, rtol=1e-6)


def test_one_step_replays_keep_no_episode_ends_and_sample_one_step():
    replay = _replay(1, 10, 2, [[[1, 2, 4], [8, 16, 32]]], ended=[[{0}, set()]], terminated=[[{0}, set()]],
                     n_steps=1)
    assert replay.ended is None and "ended" not in replay.member_state(0)
    batch = replay.sample(64)
    assert batch.discounts is None
    t, env = batch.observations[0, :, 0] % 10, batch.observations[0, :, 0] // 10
    np.testing.assert_array_equal(batch.rewards[0], np.array([[1, 2, 4], [8, 16, 32]])[env.astype(int),
                                                                                        t.astype(int)])
    n_step = _replay(1, 10, 2, [[[1, 2, 4], [8, 16, 32]]], ended=[[{0}, set()]], terminated=[[{0}, set()]])
    state = n_step.member_state(0)
    np.testing.assert_array_equal(state["ended"], [True, False, False, False, False, False])
    again = PopulationReplay(1, 20, 2, 1, (), np.int64, prioritized=False, n_steps=3, gamma=0.5)
    again.load_member(0, state)
    np.testing.assert_array_equal(again.ended[0, :4], n_step.ended[0, :4])
    assert again.ended[0, 4:6].all()  # resumed: the newest step ends every env's stream


def test_a_resumed_replay_cuts_each_envs_stream_at_its_newest_step():
    """Resumed, the envs start fresh episodes: no window runs from the steps saved into them."""
    saved = _replay(1, 10, 2, [[[1, 2, 4], [8, 16, 32]]], ended=[[set(), set()]], terminated=[[set(), set()]])
    resumed = PopulationReplay(1, 20, 2, 1, (), np.int64, prioritized=False, seed=0, n_steps=3, gamma=0.5)
    resumed.load_member(0, saved.member_state(0))
    for t in (3, 4):  # the new episodes' first steps
        obs = (10 * np.arange(2) + t)[None, :, None].astype(np.float32)
        resumed.add(obs, obs + 0.5, np.zeros((1, 2)), np.array([[64, 128]]) * 4 ** (t - 3), np.zeros((1, 2)),
                    np.full((1, 2), t), np.arange(2)[None], np.zeros((1, 2), dtype=bool))
    got = _sampled(resumed, 0)
    assert got[(1, 0)] == (2 + 0.5 * 4, 0.25, 0.0, 2.5)  # stops at the saved newest step, t = 2
    assert got[(2, 1)] == (32, 0.5, 0.0, 12.5)
    assert got[(3, 0)] == (64 + 0.5 * 256, 0.25, 0.0, 4.5)  # the new episode's own steps


def test_bad_n_steps_are_refused():
    for bad in (0, 2.5, True):
        with pytest.raises(ValueError, match="n_steps must be a positive integer"):
            PopulationReplay(1, 10, 1, 3, (), n_steps=bad)
    replay = PopulationReplay(1, 10, 1, 3, (), n_steps=2)
    with pytest.raises(ValueError, match="needs to know where episodes ended"):
        replay.add(*(np.zeros((1, 1, 3)),) * 2, *(np.zeros((1, 1)),) * 5)


def _crm_reference(automaton, completion, rewards, sigma, real_end, u, n, gamma):
    """One n-step CRM sample by hand: the automaton from ``u`` through the stored labels."""
    ret, state = 0.0, u
    for t in range(n):
        state = int(automaton.delta[state, sigma[t]])
        ret += gamma ** t * (rewards[t] + completion * automaton.accepting[state])
        ends = bool(automaton.accepting[state] or automaton.rejecting[state])
        if ends or real_end[t] or t == n - 1:
            return ret, gamma ** (t + 1), float(ends), state, t


@pytest.mark.parametrize("n_steps", [1, 3])
def test_n_step_crm_carries_each_counterfactual_state_through_the_window(n_steps):
    """Every sample of an n-step CRM replay equals the automaton run by hand from its live
    state through the stored labels: rewards with that state's completion bonuses, the end
    where it accepts or is rejecting (or where the real stream stops), the one-hots of u and
    of the state after the window; n = 1 is one-step CRM's relabelling."""
    spec = resolve_task("KeySwordDragon")  # live states 0, 1, 3; 4 accepts, 2 rejects
    a, n_envs, steps, gamma = spec.automaton, 2, 12, 0.5
    base = 2
    view = CounterfactualView(a, spec.completion_reward, base + a.n_states)
    replay = PopulationReplay(1, steps * n_envs, n_envs, base + a.n_states, (), np.int64, prioritized=False,
                              crm=view, seed=0, n_steps=n_steps, gamma=gamma)
    rng = np.random.default_rng(3)
    labels = rng.integers(0, a.delta.shape[1], (steps, n_envs))
    world = rng.normal(size=(steps, n_envs)).round(2)
    ended = rng.random((steps, n_envs)) < 0.2
    for t in range(steps - 2):  # not full: the newest step stops windows too
        obs = np.zeros((1, n_envs, base + a.n_states), dtype=np.float32)
        obs[0, :, 0], obs[0, :, 1] = t, np.arange(n_envs)
        w = np.zeros((1, n_envs), dtype=np.int64)  # the real automaton's pair: its bonus is taken out on add
        replay.add(obs, obs.copy(), np.zeros((1, n_envs)), world[t][None] + spec.completion_reward * a.accepting[
            a.delta[w, labels[t][None]]], np.zeros((1, n_envs)), w, labels[t][None], ended[t][None])
    batch = replay.sample(400)
    newest = steps - 3
    for b in range(400):
        t, env = int(batch.observations[0, b, 0]), int(batch.observations[0, b, 1])
        u = int(batch.w[0, b])
        span = range(t, min(t + n_steps, newest + 1))
        real_end = [bool(ended[s, env]) or s == newest for s in span]
        ret, disc, term, after, last = _crm_reference(a, spec.completion_reward, world[list(span), env],
                                                      labels[list(span), env], real_end, u, len(span), gamma)
        assert batch.rewards[0, b] == pytest.approx(ret, abs=1e-4)
        assert batch.discounts is None if n_steps == 1 else batch.discounts[0, b] == pytest.approx(disc)
        assert batch.terminals[0, b] == term
        assert int(batch.next_observations[0, b, 0]) == t + last  # the window's last step's
        assert batch.observations[0, b, base + u] == 1 and batch.next_observations[0, b, base + after] == 1
        assert batch.sigma[0, b] == labels[t, env]
    assert {int(u) for u in batch.w[0]} == set(view.live.tolist())  # every live state read


def test_n_step_crm_trains_in_the_population_engine_and_saves_its_return_length(tmp_path):
    settings = algorithm_settings("dqn", {"n_steps": 3})
    spec = resolve_task("Reach")
    Population("crm", settings, [0], 1, spec.automaton.n_states + 300, gym.spaces.Discrete(4), spec.automaton,
               spec.completion_reward, 100)  # accepted by the engine
    [run] = train_population([StudentConfig(task="FirstTool", method="crm", world="Grid7", steps=400, eval_every=200,
                                            eval_episodes=1, engine="population", hyperparameters={
                                                **DQN, "learning_starts": 100})], tmp_path, progress=False)
    agent = load_agent(run / "model.zip")  # saved as an SB3 agent, which says what it was trained with
    assert agent.n_steps == agent.replay_buffer.n_steps == 3


DQN = {"batch_size": 32, "learning_starts": 200, "policy_kwargs": {"net_arch": [16, 16]}, "gradient_steps": 2,
       "n_steps": 3}


@pytest.fixture(scope="module")
def reach_table(tmp_path_factory):
    """A teacher's table for Reach (the statically solved values, as a dynamic table)."""
    spec = resolve_task("Reach")
    solved = static_distillation(spec.automaton, completion_reward=spec.completion_reward)
    table = AutomatonQTable(solved.q, solved.counts, solved.fingerprint, solved.propositions, "dynamic")
    return str(table.save(tmp_path_factory.mktemp("teacher") / "table.npz"))


@pytest.mark.parametrize("method", ["dqn", "dynamic"])
def test_a_population_trains_with_n_step_returns(method, reach_table, tmp_path, monkeypatch):
    sampled = []
    sample = PopulationReplay.sample

    def spy(self, batch_size):
        batch = sample(self, batch_size)
        sampled.append(batch.discounts)
        return batch

    monkeypatch.setattr(PopulationReplay, "sample", spy)
    configs = [StudentConfig(task="Reach", method=method, world="Grid7", seed=s, steps=1_000, eval_every=500,
                             eval_episodes=2, hyperparameters=DQN, n_envs=4, engine="population",
                             table=reach_table if method == "dynamic" else None) for s in (0, 1)]
    paths = train_population(configs, tmp_path, progress=False)
    discounts = np.concatenate([d.ravel() for d in sampled])
    k = np.log(discounts) / np.log(0.99)  # gamma ** k after k rewards
    assert np.allclose(k, np.round(k), atol=1e-3) and set(np.round(k)) <= {1, 2, 3} and (np.round(k) == 3).any()
    for config, path in zip(configs, paths):
        result = json.loads((path / "result.json").read_text())
        assert (result["engine"], result["seed"], result["steps"], result["updates"]) == \
            ("population", config.seed, 1_000, 2 * (1_000 - 200) // 4)
        assert json.loads((path / "config.json").read_text())["hyperparameters"]["n_steps"] == 3
        assert [int(r["step"]) for r in read_csv(path / "evals.csv")] == [500, 1000]
        agent = load_agent(path / "model.zip")
        assert agent.n_steps == 3 and agent.replay_buffer.n_steps == 3
