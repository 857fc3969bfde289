"""The ``layer_norm`` setting: LayerNorm after each hidden Linear layer of the value networks
(TD3's critics, DQN's Q-network; their targets too), the same in both engines. A population
member with it computes what the SB3 agent it is saved as computes, the saved model loads as
an ordinary SB3 zip, and without it every network is as it was."""

import numpy as np
import pytest
import torch as th
from stable_baselines3 import DQN, TD3
from torch import nn

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.agents.factory import load_agent, make_agent
from craftsuite.configs import StudentConfig
from craftsuite.hyperparameters import algorithm_settings
from craftsuite.population import train_population
from craftsuite.population.dqn import PopulationDQN
from craftsuite.population.nets import StackedMLP
from craftsuite.population.td3 import PopulationTD3

CONT, GRID = "CraftSuite/Reach-Cont-v0", "CraftSuite/Reach-Grid7-v0"
ARCH = {"net_arch": [16, 8]}


def _td3(**settings):
    return make_agent("td3", CONT, buffer_size=64, policy_kwargs=ARCH, **settings)


def _dqn(**settings):
    return make_agent("dqn", GRID, buffer_size=64, policy_kwargs=ARCH, **settings)


def _norms(module: nn.Module) -> list[nn.LayerNorm]:
    return [m for m in module.modules() if isinstance(m, nn.LayerNorm)]


def _jitter(stacked: StackedMLP, seed: int) -> None:
    """Every LayerNorm affine away from its ones and zeros, so that copying it shows."""
    gen = th.Generator().manual_seed(seed)
    with th.no_grad():
        for p in [*stacked.norm_weights, *stacked.norm_biases]:
            p.add_(th.randn(p.shape, generator=gen))


def _close(a: th.Tensor, b: th.Tensor):
    assert th.allclose(a, b, atol=1e-6, rtol=0), (a - b).abs().max()


# -- (1) a member computes what its SB3 agent computes ------------------------------------------
def test_a_td3_members_critics_are_its_agents_after_store_member():
    agent = _td3(layer_norm=True)
    obs_dim, act_dim = agent.observation_space.shape[0], agent.action_space.shape[0]
    pop = PopulationTD3(2, obs_dim, act_dim, algorithm_settings("td3", {"policy_kwargs": ARCH, "layer_norm": True}))
    for i, critic in enumerate([*pop.critics, *pop.critics_target]):
        _jitter(critic, i)
    assert not _norms(agent.actor) and not pop.actor.layer_norm  # the actor is unchanged
    pop.store_member(1, agent)
    obs = th.randn(2, 32, obs_dim)
    actions = th.rand(2, 32, act_dim) * 2 - 1
    joint = th.cat([obs, actions], dim=2)
    with th.no_grad():
        for mine, theirs in ((pop.critics, agent.critic), (pop.critics_target, agent.critic_target)):
            assert len(_norms(theirs)) == 2 * 2  # two critics of two hidden layers
            for q, sb3_q in zip(mine, theirs(obs[1], actions[1])):
                _close(q(joint)[1], sb3_q)
    other = PopulationTD3(2, obs_dim, act_dim, algorithm_settings("td3", {"policy_kwargs": ARCH, "layer_norm": True}))
    other.load_member(0, agent)  # and back: the affine comes with the weights
    for a, b in zip(other.critics.parameters(), pop.critics.parameters()):
        _close(a[0], b[1])


@pytest.mark.parametrize("dueling", [True, False])
def test_a_dqn_members_q_net_is_its_agents_after_store_member(dueling):
    agent = _dqn(layer_norm=True, dueling=dueling)
    obs_dim, n_actions = agent.observation_space.shape[0], int(agent.action_space.n)
    settings = algorithm_settings("dqn", {"policy_kwargs": ARCH, "layer_norm": True, "dueling": dueling})
    pop = PopulationDQN(2, obs_dim, n_actions, settings)
    _jitter(pop.q_net, 0)
    _jitter(pop.q_net_target, 1)
    pop.store_member(0, agent)
    obs = th.rand(2, 32, obs_dim)
    with th.no_grad():
        for mine, theirs in ((pop.q_net, agent.q_net), (pop.q_net_target, agent.q_net_target)):
            assert len(_norms(theirs)) == 2
            _close(pop.q_values(mine, obs)[0], theirs(obs[0]))


# -- (2) a saved model is an ordinary SB3 zip ---------------------------------------------------
@pytest.mark.parametrize("algorithm", ["td3", "dqn"])
def test_a_saved_layer_norm_model_loads_and_predicts(algorithm, tmp_path):
    agent = _td3(layer_norm=True) if algorithm == "td3" else _dqn(layer_norm=True)
    value = (lambda a: a.critic) if algorithm == "td3" else (lambda a: a.q_net)
    with th.no_grad():
        for norm in _norms(value(agent)):  # saved as trained, not as initialised
            norm.weight.mul_(1.5)
    agent.save(tmp_path / "model.zip")
    obs = np.stack([agent.observation_space.sample() for _ in range(5)])
    expected = agent.predict(obs, deterministic=True)[0]
    for load in ((TD3 if algorithm == "td3" else DQN).load, load_agent):
        loaded = load(tmp_path / "model.zip")
        assert len(_norms(value(loaded))) == len(_norms(value(agent))) > 0
        for a, b in zip(value(agent).parameters(), value(loaded).parameters()):
            _close(a, b)
        np.testing.assert_array_equal(loaded.predict(obs, deterministic=True)[0], expected)
    assert type(load_agent(tmp_path / "model.zip")).__name__ == ("AutomatonTD3" if algorithm == "td3"
                                                                  else "AutomatonDQN")


# -- (3) off, the networks are as they were ------------------------------------------------------
def _mlp_parameters(sizes: list[int]) -> int:
    return sum(i * o + o for i, o in zip(sizes[:-1], sizes[1:]))


@pytest.mark.parametrize("algorithm", ["td3", "dqn"])
def test_without_layer_norm_the_nets_are_as_before(algorithm):
    for agent in ((_td3(), _td3(layer_norm=False)) if algorithm == "td3" else (_dqn(), _dqn(layer_norm=False))):
        assert not _norms(agent.policy) and "layer_norm" not in agent.policy_kwargs
        obs_dim = agent.observation_space.shape[0]
        if algorithm == "td3":
            assert type(agent.policy).__name__ == "TD3Policy"  # SB3's own
            critic = _mlp_parameters([obs_dim + agent.action_space.shape[0], 16, 8, 1])
            assert sum(p.numel() for p in agent.critic.parameters()) == 2 * critic
        else:
            assert type(agent.policy).__name__ == "DuelingDQNPolicy"
            q_net = _mlp_parameters([obs_dim, 16, 8, int(agent.action_space.n) + 1])
            assert sum(p.numel() for p in agent.q_net.parameters()) == q_net
    plain = StackedMLP(3, [5, 16, 8, 2])
    assert not plain.layer_norm and set(plain.state_dict()) == {f"{n}.{i}" for n in ("weights", "biases")
                                                                 for i in range(3)}
    assert sum(p.numel() for p in plain.parameters()) == 3 * _mlp_parameters([5, 16, 8, 2])
    normed = StackedMLP(3, [5, 16, 8, 2], layer_norm=True)
    assert sum(p.numel() for p in normed.parameters()) == 3 * (_mlp_parameters([5, 16, 8, 2]) + 2 * (16 + 8))


def test_a_member_and_an_agent_must_agree_on_layer_norm():
    settings = algorithm_settings("dqn", {"policy_kwargs": ARCH, "layer_norm": True})
    agent = _dqn()
    pop = PopulationDQN(1, agent.observation_space.shape[0], int(agent.action_space.n), settings)
    with pytest.raises(ValueError, match=r"LayerNorms of widths \[\] .* same layer_norm setting"):
        pop.store_member(0, agent)


# -- (4) a population with layer_norm trains and saves loadable members -----------------------------
@pytest.mark.parametrize("method,world,task", [("dqn", "Grid7", "FirstTool"), ("td3", "Kinematic", "Reach")])
def test_a_layer_norm_population_trains_and_its_models_load(method, world, task, tmp_path):
    hyper = {"batch_size": 16, "learning_starts": 100, "policy_kwargs": {"net_arch": [16, 16]}, "layer_norm": True}
    kw = {"layout_seed": 0} if world == "Grid7" else {}
    configs = [StudentConfig(task=task, method=method, world=world, seed=s, steps=300, eval_every=300,
                             eval_episodes=1, hyperparameters=hyper, n_envs=2, engine="population", **kw)
               for s in (0, 1)]
    paths = train_population(configs, tmp_path, progress=False)
    for path in paths:
        agent = load_agent(path / "model.zip")
        value = agent.critic if method == "td3" else agent.q_net
        assert len(_norms(value)) == (4 if method == "td3" else 2) and agent.num_timesteps == 300
        assert any((n.weight != 1).any() for n in _norms(value))  # trained, then stored
        obs = np.stack([agent.observation_space.sample() for _ in range(3)])
        assert agent.predict(obs, deterministic=True)[0].shape[0] == 3


def test_a_killed_layer_norm_population_resumes_with_its_norms(tmp_path, monkeypatch):
    from craftsuite.population import train as population_train

    from .test_runs import _killed_at_the_second_evaluation

    hyper = {"batch_size": 16, "learning_starts": 100, "policy_kwargs": {"net_arch": [16, 16]}, "layer_norm": True}
    configs = [StudentConfig(task="Reach", method="td3", world="Kinematic", seed=s, steps=600, eval_every=200,
                             eval_episodes=1, hyperparameters=hyper, n_envs=2, engine="population")
               for s in (0, 1)]
    _killed_at_the_second_evaluation(configs, tmp_path, monkeypatch)
    seen = {}
    load = population_train.Population.load_states

    def spy(self, states):
        load(self, states)
        seen["saved"] = [s["modules"]["critics"]["0.norm_weights.0"] for s in states]
        seen["loaded"] = self.learner.critics[0].norm_weights[0].detach().clone()

    monkeypatch.setattr(population_train.Population, "load_states", spy)
    paths = train_population(configs, tmp_path, progress=False)
    assert (seen["saved"][0] != 1).any()  # the affine had moved before the kill
    for k, saved in enumerate(seen["saved"]):
        assert th.equal(seen["loaded"][k], saved)
    assert all(len(_norms(load_agent(p / "model.zip").critic)) == 4 for p in paths)
