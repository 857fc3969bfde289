"""What one TD3 update of a population computes, beyond its numbers (``test_frozen_updates``
holds those): the actor step differentiates into the actor alone."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import torch as th

from craftsuite.hyperparameters import algorithm_settings
from craftsuite.population.replay import Batch
from craftsuite.population.td3 import PopulationTD3

K, OBS, ACT, B = 2, 6, 2, 16


def _batch() -> Batch:
    rng, f = np.random.default_rng(0), np.float32
    return Batch(rng.standard_normal((K, B, OBS)).astype(f), rng.uniform(-1, 1, (K, B, ACT)).astype(f),
                 rng.standard_normal((K, B, OBS)).astype(f), rng.standard_normal((K, B)).astype(f),
                 np.zeros((K, B), f), np.ones((K, B), f), np.zeros((K, B), np.int64),
                 np.zeros((K, B), np.int64), np.zeros((K, B), np.int64))


@pytest.mark.parametrize("layer_norm", [False, True])
def test_the_actor_step_leaves_the_critics_gradients_as_the_critic_step_left_them(layer_norm):
    """The actor's loss runs through the first critic; that critic's parameter gradients
    would be computed only for the next critic step to clear them, so the actor step
    computes none (its input gradients carry the loss back to the actor)."""
    th.manual_seed(0)
    settings = {"batch_size": B, "prioritized": False, "policy_kwargs": {"net_arch": [8]}, "layer_norm": layer_norm}
    with_actor = PopulationTD3(K, OBS, ACT, algorithm_settings("td3", settings))
    critic_only = copy.deepcopy(with_actor)
    th.manual_seed(1)  # the target policy's smoothing noise: the same draws for both
    with_actor.update(_batch(), delay=1)  # a critic step, then an actor step
    th.manual_seed(1)
    critic_only.update(_batch(), delay=2)  # the same critic step alone
    assert all(p.grad is not None for p in with_actor.actor.parameters())
    assert all(p.grad is None for p in critic_only.actor.parameters())
    for mine, theirs in zip(with_actor.critics.parameters(), critic_only.critics.parameters(), strict=True):
        assert th.equal(mine.grad, theirs.grad)
