"""A member whose learning diverged is named by its seed the moment its greedy actions are
asked for, in training and in evaluation alike: a TD3 actor's NaN thrust would be refused by
the world naming neither seed nor cause, and a DQN would go on acting on an argmax of NaN."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import torch as th

from craftsuite.hyperparameters import algorithm_settings
from craftsuite.population import Diverged, Population
from craftsuite.task_registry import resolve_task

OBS, ACT = 6, 2
CASES = {  # method: (action space, the network whose second member is broken, what the message names)
    "td3": (gym.spaces.Box(-1, 1, (ACT,)), "actor", "actor's actions"),
    "dqn": (gym.spaces.Discrete(4), "q_net", "Q-values"),
}


@pytest.mark.parametrize("method", CASES)
def test_a_member_that_diverged_is_named_by_its_seed(method):
    space, network, outputs = CASES[method]
    spec = resolve_task("Reach")
    settings = algorithm_settings(method, {"learning_starts": 0, "policy_kwargs": {"net_arch": [8, 8]}})
    population = Population(method, settings, [4, 7], 1, OBS, space, spec.automaton, spec.completion_reward, 100)
    obs = np.zeros((2, 1, OBS), dtype=np.float32)
    for act in (population.actions, population.greedy):
        assert np.isfinite(act(obs)).all()  # healthy members act
    with th.no_grad():
        for p in getattr(population.learner, network).parameters():
            p[1:] = float("nan")  # the second member's share of each stacked weight
    for act in (population.actions, population.greedy):  # in training and in evaluation
        with pytest.raises(Diverged, match=rf"^{method} seed 7: its {outputs} are not finite after 0 transitions, "
                                           r"so its learning diverged; run it with a smaller learning_rate"):
            act(obs)
