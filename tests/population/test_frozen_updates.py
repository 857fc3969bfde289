"""Frozen updates: every learning rule computes today what it computed when its fixture
was frozen (``frozen/<case>.npz``, made by ``frozen/make.py``, whose docstring says what a
case runs, what a fixture holds and when regenerating one is right).

The fixtures are the population engine's (the implementation that stays). Where the SB3
stack (``craftsuite.agents``) implements the same rule, it is driven on the same inputs
(the same replay contents, the same sampling draws, the same torch seeds, the same initial
networks) and must reproduce the same fixture; n-step CRM and reward shaping only the
population engine implements. Run end to end, the two stacks are only statistically
equal: the SB3 buffer samples from numpy's global stream, a population from its replay's
own ``Generator``, and their networks are initialised from other torch draws; so here the
SB3 stack is handed the population's draws and initial weights. Also: the grid students'
sparse replay, and member 0 of a population of three, reproduce the one-member fixture.
"""

from __future__ import annotations

import functools

import gymnasium as gym
import numpy as np
import pytest
import torch as th
from stable_baselines3.common.logger import Logger
from stable_baselines3.common.vec_env import DummyVecEnv

from craftsuite.agents.crm import CRMReplayBuffer
from craftsuite.agents.distillation import DistilledTarget, static_distillation
from craftsuite.agents.dqn import AutomatonDQN
from craftsuite.agents.td3 import AutomatonTD3
from craftsuite.methods import METHODS

from .frozen import make

SB3_CASES = [name for name, case in make.CASES.items() if case.sb3]
# Both stacks are held to one tolerance: rtol 1e-5, atol 1e-6 times the array's largest
# magnitude. The SB3 stack computes with other kernels (nn.Linear, not baddbmm), so it is
# not bitwise equal: when frozen, its largest difference from a fixture was 1.8e-7 of the
# array's scale (a loss), 3e-8 on parameters, over eight updates
RTOL, ATOL = 1e-5, 1e-6


@pytest.fixture(autouse=True)
def _one_thread():
    """One torch thread and deterministic kernels: the fixtures were made so."""
    threads, deterministic = th.get_num_threads(), th.are_deterministic_algorithms_enabled()
    th.set_num_threads(1)
    th.use_deterministic_algorithms(True)
    yield
    th.set_num_threads(threads)
    th.use_deterministic_algorithms(deterministic)


@functools.cache
def _fixture(name: str) -> dict:
    with np.load(make.path(name), allow_pickle=False) as f:
        return {k: f[k] for k in f.files if k != "about"}


@functools.cache
def _population(name: str, sparse: bool = False, members: int = 1) -> dict:
    return make.run(name, sparse=sparse, members=members)


def _differences(got: dict, want: dict, rtol: float = RTOL, atol: float = ATOL, keys=None) -> list[str]:
    """What of ``want`` ``got`` does not reproduce, one line each: integers and booleans
    exactly, floats to ``rtol`` and ``atol`` times the array's largest magnitude (at least 1)."""
    out = []
    for key in keys if keys is not None else want:
        if key not in got:
            out.append(f"{key}: missing")
            continue
        a, b = np.asarray(got[key]), np.asarray(want[key])
        if a.shape != b.shape:
            out.append(f"{key}: shape {a.shape}, frozen {b.shape}")
        elif b.dtype.kind in "biu":
            wrong = a != b
            if wrong.any():
                out.append(f"{key}: {int(wrong.sum())} of {a.size} differ{_from(wrong)}")
        else:
            scale = max(1.0, float(np.abs(b).max(initial=0.0)))
            wrong = ~np.isclose(a, b, rtol=rtol, atol=atol * scale)
            if wrong.any():
                worst = np.abs(a.astype(np.float64) - b).max()
                out.append(f"{key}: largest difference {worst:.3g} (scale {scale:.3g}){_from(wrong)}")
    return out


def _from(wrong: np.ndarray) -> str:
    """For a per-update array ``(UPDATES, ...)``: the first update it differs at."""
    if wrong.ndim < 2 or wrong.shape[0] != make.UPDATES:
        return ""
    return f", from update {int(wrong.reshape(make.UPDATES, -1).any(axis=1).argmax())}"


def _report(differences: list[str], name: str, who: str) -> str:
    return (f"{who} no longer reproduces frozen case {name!r} ({make.CASES[name]}):\n  " + "\n  ".join(differences)
            + "\n(inputs first: automaton_*/input_digest/init_digest differ when the inputs changed, not a rule; "
              "batch_* when sampling, n-step returns, CRM or shaping did; targets/td/losses when the target or "
              "loss did. Regenerate only for a deliberate change of a learning rule: frozen/make.py)")


def test_every_case_has_a_small_fixture():
    sizes = {name: make.path(name).stat().st_size for name in make.CASES}
    assert sum(sizes.values()) < 400_000, sizes


@pytest.mark.parametrize("name", list(make.CASES))
def test_the_population_engine_reproduces_the_frozen_update(name):
    want = _fixture(name)
    differences = _differences(_population(name), want)
    assert not differences, _report(differences, name, "the population engine")


@pytest.mark.parametrize("name", ["dqn", "crm-n3", "crm-edges", "dqn-residual-cnn"])
def test_a_sparse_replay_reproduces_the_dense_fixture(name):
    """The grid students' replay (observations as their nonzero entries, the first layer a
    sum of weight rows, or planes made whole again for a CNN; CRM's one-hot moved in them)
    learns as the dense one."""
    differences = _differences(_population(name, sparse=True), _fixture(name))
    assert not differences, _report(differences, name, "the sparse replay")


@pytest.mark.parametrize("name", ["dqn", "dqn-transitions", "crm-edges-n3", "td3", "td3-dynamic",
                                  "dqn-residual-cnn"])
def test_member_zero_of_a_population_of_three_reproduces_the_fixture(name):
    """Members learn apart: member 0, beside two members with other minibatches (their own
    counts, gradient norms, priorities), learns as the one-member population did."""
    want = {k: v for k, v in _fixture(name).items() if not k.endswith("losses")}  # summed over members
    differences = _differences(_population(name, members=3), want)
    assert not differences, _report(differences, name, "member 0 of three")


# -- the SB3 stack, on the same inputs ------------------------------------------------------------
class _Spaces(gym.Env):
    """An env with the case's spaces only: the SB3 agent is built on it, never stepped."""

    def __init__(self, observation_space, action_space):
        self.observation_space, self.action_space = observation_space, action_space

    def reset(self, *, seed=None, options=None):
        return np.zeros(self.observation_space.shape, np.float32), {}

    def step(self, action):
        raise AssertionError("the frozen cases never step an env")


def _sb3_agent(name: str, pop, inputs):
    """The SB3 agent of case ``name`` as ``agents.factory.make_agent`` wires it (CRM's
    buffer, the distilled target with the row's keywords), on ``pop``'s initial networks and
    counts, its replay filled with the same stream."""
    case = make.CASES[name]
    row = METHODS[case.method]
    automaton, completion = inputs["automaton"], inputs["completion"]
    obs_dim = make.FEATURES[case.algorithm] + automaton.n_states
    obs_space = gym.spaces.Box(-np.inf, np.inf, (obs_dim,), np.float32)
    act_space = gym.spaces.Discrete(make.N_ACTIONS) if case.algorithm == "dqn" else \
        gym.spaces.Box(-1.0, 1.0, (make.ACT_DIM,), np.float32)
    env = DummyVecEnv([lambda: _Spaces(obs_space, act_space)] * make.N_ENVS)
    kwargs = {k: v for k, v in case.effective().items() if k != "action_noise"}
    if row.crm:
        kwargs["replay_buffer_class"] = CRMReplayBuffer
        kwargs["replay_buffer_kwargs"] = {"automaton": automaton, "completion_reward": completion}
    if row.distill is not None:
        table = inputs["table"] if row.distill == "dynamic" else static_distillation(automaton,
                                                                                     completion_reward=completion)
        kwargs["distill"] = DistilledTarget(table, automaton, **row.target_kwargs())
    agent = (AutomatonDQN if case.algorithm == "dqn" else AutomatonTD3)("MlpPolicy", env, seed=0, **kwargs)
    agent.set_logger(Logger(folder=None, output_formats=[]))
    pop.learner.store_member(0, agent)
    if agent.distill is not None:
        agent.distill.student_counts[...] = inputs["counts"].reshape(agent.distill.student_counts.shape)
    for s in inputs["steps"][:make.STEPS]:
        _observe(agent, s)
    return agent


def _observe(agent, s: dict) -> None:
    """One vector step of the stream, as SB3's ``collect_rollouts`` takes it: stored, counted,
    then ``_on_step`` (DQN's target update by transitions)."""
    infos = [{"automaton_transition": (int(s["w"][e]), int(s["sigma"][e]), int(s["w_next"][e])),
              "TimeLimit.truncated": bool(s["truncated"][e])} for e in range(make.N_ENVS)]
    agent.replay_buffer.add(s["obs"], s["next_obs"], s["actions"], s["rewards"], s["terminated"] | s["truncated"],
                            infos)
    agent.num_timesteps += make.N_ENVS
    agent._on_step()


class _Draws:
    """``np.random``'s ``random`` and ``randint`` as the SB3 buffer calls them, giving the
    draws the population's replay made (its one member's), in order."""

    def __init__(self, draws):
        self.draws = list(draws)

    def _next(self, kind):
        assert self.draws, "the SB3 buffer draws more than the population's replay did"
        got, bounds, out = self.draws.pop(0)
        assert got == kind, f"the SB3 buffer draws {kind}, the population's replay drew {got}"
        return bounds, np.asarray(out).reshape(-1)

    def random(self, size=None):
        _, out = self._next("random")
        assert out.shape == (size,)
        return out

    def randint(self, low, high=None, size=None):
        bounds, out = self._next("integers")
        assert bounds == (low, high) and out.shape == (size,), (bounds, low, high)
        return out


def _sb3_run(name: str, monkeypatch) -> dict:
    """Case ``name`` on the SB3 stack: the record ``make.run`` keeps, as far as SB3 shows it."""
    case = make.CASES[name]
    pop, inputs = make.build(name)
    agent = _sb3_agent(name, pop, inputs)
    draws = _population(name)["_draws"]
    buffer, obs_dim = agent.replay_buffer, pop.learner.q_net.sizes[0] if pop.discrete else pop.learner.actor.sizes[0]
    samples, targets, tds, losses = [], [], [], []
    sample, td_target, update_priorities = buffer.sample, agent._td_target, buffer.update_priorities

    def spy_sample(*args, **kwargs):
        samples.append(sample(*args, **kwargs))
        return samples[-1]

    def spy_target(data):
        out = td_target(data)
        targets.append(out[:, 0].numpy().copy())
        return out

    def spy_priorities(indices, td_errors):
        tds.append(np.asarray(td_errors).reshape(-1).copy())
        return update_priorities(indices, td_errors)

    monkeypatch.setattr(buffer, "sample", spy_sample)
    monkeypatch.setattr(agent, "_td_target", spy_target)
    monkeypatch.setattr(buffer, "update_priorities", spy_priorities)
    for i in range(make.UPDATES):
        if case.interleave:
            _observe(agent, inputs["steps"][make.STEPS + i])
        fake = _Draws(draws[i])
        with monkeypatch.context() as m:
            m.setattr(np.random, "random", fake.random)
            m.setattr(np.random, "randint", fake.randint)
            scalars = []
            th.manual_seed(make.torch_seed(i))
            with make.losses_backpropagated(scalars):
                agent.train(gradient_steps=1, batch_size=make.BATCH)
        assert not fake.draws, "the SB3 buffer drew less than the population's replay did"
        losses.append(scalars)

    def stacked(get):
        return np.stack([np.asarray(get(s)).reshape(-1) for s in samples])

    record = {"batch_rewards": stacked(lambda s: s.rewards.numpy()),
              "batch_terminals": stacked(lambda s: s.dones.numpy()),
              "batch_weights": stacked(lambda s: s.weights.numpy()),
              "batch_leaves": stacked(lambda s: s.indices).astype(np.int32),
              "batch_w": stacked(lambda s: s.w).astype(np.int8),
              "batch_sigma": stacked(lambda s: s.sigma).astype(np.int8),
              "batch_obs": stacked(lambda s: make.observation_digest(s.observations.numpy(), obs_dim)),
              "batch_next_obs": stacked(lambda s: make.observation_digest(s.next_observations.numpy(), obs_dim)),
              "targets": np.stack(targets)}
    if samples[0].discounts is not None:
        record["batch_discounts"] = stacked(lambda s: s.discounts.numpy())
    if tds:  # prioritized: the TD errors the priorities were updated from
        record["td"] = np.stack(tds)
    if pop.discrete:
        record["losses"] = np.array([s[0] for s in losses])
    else:
        record["critic_losses"] = np.array([s[0] for s in losses])
        record["actor_losses"] = np.array([s[1] for s in losses if len(s) > 1])
    after, _ = make.build(name)
    after.learner.load_member(0, agent)  # the agent's networks, read as a member's
    record.update(make.parameters(after.learner))
    if buffer.tree is not None:
        filled = (buffer.buffer_size if buffer.full else buffer.pos) * buffer.n_envs
        record["priorities"] = buffer.tree.tree[buffer.tree.leaves:buffer.tree.leaves + filled].copy()
        record["max_priority"] = buffer.max_priority
    if agent.distill is not None:
        record["counts"] = agent.distill.student_counts.reshape(-1).copy()
    assert agent.n_updates == make.UPDATES
    return record


@pytest.mark.parametrize("name", SB3_CASES)
def test_the_sb3_stack_reproduces_the_frozen_update(name, monkeypatch):
    want = _fixture(name)
    keys = [k for k in want if not (k.startswith(("automaton_", "completion_", "input_", "init_"))
                                    or (k == "td" and not make.CASES[name].effective().get("prioritized", True)))]
    differences = _differences(_sb3_run(name, monkeypatch), want, keys=keys)
    assert not differences, _report(differences, name, "the SB3 stack")
