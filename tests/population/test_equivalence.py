"""The population engine's update is the SB3 agents' update: with one member, the same
initial weights and the same minibatch, one gradient step leaves the same parameters."""

import numpy as np
import pytest
import torch as th

import craftsuite  # noqa: F401
from craftsuite.agents.factory import make_agent
from craftsuite.population.dqn import PopulationDQN
from craftsuite.population.replay import Batch, sparse_rows
from craftsuite.population.targets import MemberTargets
from craftsuite.population.td3 import PopulationTD3


def _filled(method, env_id, **settings):
    agent = make_agent(method, env_id, seed=3, n_envs=2, learning_starts=10**6, buffer_size=2_000, **settings)
    agent.learn(400)  # random collection only: learning_starts is never reached
    return agent


def _batch(samples) -> Batch:
    """An SB3 minibatch (``AutomatonSamples``) as the engine's, for one member."""
    def one(t):
        return np.asarray(t.cpu().numpy() if hasattr(t, "cpu") else t)[None]
    dones = one(samples.dones)[..., 0]
    return Batch(one(samples.observations), one(samples.actions), one(samples.next_observations),
                 one(samples.rewards)[..., 0], dones, one(samples.weights)[..., 0], one(samples.indices),
                 one(samples.w).astype(np.int64), one(samples.sigma).astype(np.int64))


def _same_sample(agent, samples):
    agent.replay_buffer.sample = lambda *args, **kwargs: samples


def _close(a: th.Tensor, b: th.Tensor):
    assert th.allclose(a, b, atol=1e-6, rtol=1e-5), (a - b).abs().max()


@pytest.mark.parametrize("prioritized,layer_norm", [(True, False), (False, False), (True, True)])
def test_td3_update_matches_automaton_td3(prioritized, layer_norm):
    """``layer_norm``: the critics' LayerNorms (each member's own affine) learn as SB3's."""
    agent = _filled("td3-static", "CraftSuite/FirstTool-Kinematic-v0", batch_size=32, policy_delay=1,
                    prioritized=prioritized, policy_kwargs={"net_arch": [32, 24]}, layer_norm=layer_norm)
    settings = agent_settings(agent, "td3", prioritized=prioritized, policy_kwargs={"net_arch": [32, 24]},
                              layer_norm=layer_norm)
    obs_dim = agent.observation_space.shape[0]
    pop = PopulationTD3(1, obs_dim, 2, settings, MemberTargets(agent.distill, 1))
    pop.targets.counts[0] = agent.distill.student_counts.reshape(-1)
    pop.load_member(0, agent)
    for step in range(3):  # the actor and targets move on each (delay 1); the teacher's weight fades
        samples = agent.replay_buffer.sample(32)
        _same_sample(agent, samples)
        th.manual_seed(step)
        agent.train(gradient_steps=1, batch_size=32)
        th.manual_seed(step)
        td = pop.update(_batch(samples), delay=1)
    assert np.abs(td).sum() > 0
    mine = _fresh_td3(agent, layer_norm)
    pop.store_member(0, mine)
    for name in ("actor", "actor_target", "critic", "critic_target"):
        for a, b in zip(getattr(agent.policy, name).parameters(), getattr(mine.policy, name).parameters()):
            _close(a, b)
    np.testing.assert_array_equal(pop.targets.counts[0], agent.distill.student_counts.reshape(-1))


@pytest.mark.parametrize("loss,prioritized,sparse,layer_norm", [
    ("huber", True, False, False), ("mse", False, False, False), ("huber", True, True, False),
    ("huber", True, True, True)])
def test_dqn_update_matches_automaton_dqn(loss, prioritized, sparse, layer_norm):
    """``sparse``: the minibatch's observations as their nonzero entries, as the grid
    students' replay stores them (the first layer a sum of weight rows). ``layer_norm``:
    the Q-network's LayerNorms learn (and are clipped) as SB3's."""
    agent = _filled("static", "CraftSuite/FirstTool-Grid7-v0", batch_size=32, loss=loss, prioritized=prioritized,
                    target_update_interval=2, target_update_unit="gradient_steps", max_grad_norm=0.05,
                    layer_norm=layer_norm)
    settings = agent_settings(agent, "dqn", loss=loss, prioritized=prioritized, target_update_interval=2,
                              target_update_unit="gradient_steps", max_grad_norm=0.05, layer_norm=layer_norm)
    pop = PopulationDQN(1, agent.observation_space.shape[0], 4, settings, MemberTargets(agent.distill, 1))
    pop.targets.counts[0] = agent.distill.student_counts.reshape(-1)
    pop.load_member(0, agent)
    _train_both(agent, pop, 32, sparse)  # the target network is copied after the second; clipping bites (0.05)
    mine = make_agent("static", "CraftSuite/FirstTool-Grid7-v0", seed=9, buffer_size=16, layer_norm=layer_norm)
    pop.store_member(0, mine)
    for name in ("q_net", "q_net_target"):
        for a, b in zip(getattr(agent.policy, name).parameters(), getattr(mine.policy, name).parameters()):
            _close(a, b)


@pytest.mark.parametrize("dueling,sparse", [(True, True), (False, False)])
def test_the_residual_cnn_learns_as_automaton_dqns(dueling, sparse):
    """The paper's residual CNN (``features_extractor="residual-cnn"``): one member's
    updates move its weights and batch-norm statistics as SB3's, its target copies both, and
    its greedy Q-values read the running statistics as SB3's ``predict`` does. ``sparse``:
    the minibatch as the grid replay stores it (nonzero entries), made whole planes again.

    A convolution's bias before a batch norm has no gradient but rounding noise (the norm
    subtracts the mean), which Adam scales to steps of about the learning rate either way in
    SB3's network; the engine holds those biases fixed: they (and the running means that
    follow them) agree only to a few steps' size; the Q-values they give agree."""
    cnn = {"features_extractor": "residual-cnn", "policy_kwargs": {"net_arch": [32]}, "dueling": dueling,
           "target_update_interval": 2, "target_update_unit": "gradient_steps"}
    agent = _filled("product-dqn", "CraftSuite/FirstTool-Grid7-v0", batch_size=16, **cnn)
    settings = agent_settings(agent, "dqn", **cnn)
    planes = agent.get_env().envs[0].unwrapped.observation_layout["planes"]
    pop = PopulationDQN(1, agent.observation_space.shape[0], 4, settings, planes=planes)
    pop.load_member(0, agent)
    _train_both(agent, pop, 16, sparse)  # the target (weights and running statistics) is copied after the second
    mine = make_agent("product-dqn", "CraftSuite/FirstTool-Grid7-v0", seed=9, buffer_size=16, **cnn)
    pop.store_member(0, mine)
    noise = 0.01  # a few of Adam's steps (5e-4 each), against weights of about 0.1
    for name in ("q_net", "q_net_target"):
        theirs, ours = getattr(agent.policy, name), getattr(mine.policy, name)
        conv_biases = {id(m.bias) for m in theirs.modules() if isinstance(m, th.nn.Conv2d)}
        for a, b in zip(theirs.parameters(), ours.parameters()):
            if id(a) in conv_biases:
                assert (a - b).abs().max() <= noise
            else:  # the noise reaches the weights through the next updates' activations, a little
                assert th.allclose(a, b, atol=1e-5, rtol=1e-4), (a - b).abs().max()
        for (key, a), b in zip(theirs.named_buffers(), ours.buffers()):
            if "running" in key:
                assert a.abs().sum() > 0 and th.allclose(a, b, atol=noise), (key, (a - b).abs().max())
    obs = th.as_tensor(agent.replay_buffer.observations[:50, 0])
    agent.policy.set_training_mode(False)
    with th.no_grad(), pop.evaluating():
        q_sb3, q_pop = agent.q_net(obs), pop.q_values(pop.q_net, obs[None])[0]
    assert th.allclose(q_sb3, q_pop, atol=1e-2), (q_sb3 - q_pop).abs().max()


def _train_both(agent, pop, batch_size: int, sparse: bool, updates: int = 3) -> None:
    """``updates`` DQN updates of the SB3 agent and of the population on the same minibatches
    (``sparse``: the population's as the grid replay stores them, their nonzero entries)."""
    for _ in range(updates):
        samples = agent.replay_buffer.sample(batch_size)
        _same_sample(agent, samples)
        agent.train(gradient_steps=1, batch_size=batch_size)
        batch = _batch(samples)
        if sparse:
            width = int((batch.observations != 0).sum(axis=-1).max())
            batch = batch._replace(observations=sparse_rows(batch.observations, width),
                                   next_observations=sparse_rows(batch.next_observations, width))
        pop.update(batch)


def agent_settings(agent, algorithm, **overrides) -> dict:
    from craftsuite.hyperparameters import algorithm_settings

    return algorithm_settings(algorithm, overrides)


def _fresh_td3(like, layer_norm=False):
    return make_agent("td3-static", "CraftSuite/FirstTool-Kinematic-v0", seed=11, buffer_size=16,
                      policy_kwargs={"net_arch": [32, 24]}, layer_norm=layer_norm)
