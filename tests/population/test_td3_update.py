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


def test_the_actor_and_the_critics_take_their_own_widths_and_a_malformed_one_is_refused_by_the_engine_first():
    """``{"pi": [...], "qf": [...]}`` builds each network from its own list; what the networks
    cannot build, the engine's check refuses with their own message, before anything runs."""
    from craftsuite.population.engine import EngineError, check_supported

    arch = {"pi": [8], "qf": [5, 3]}
    population = PopulationTD3(K, OBS, ACT, algorithm_settings("td3", {"policy_kwargs": {"net_arch": arch}}))
    assert [net.sizes for net in (population.actor, *population.critics)] == [
        [OBS, 8, ACT], [OBS + ACT, 5, 3, 1], [OBS + ACT, 5, 3, 1]]
    for bad in ({"pi": [8]}, {"pi": [8], "qf": [0]}, [8, "wide"], (8, 8)):  # a tuple: SB3's TD3 saves no such
        settings = algorithm_settings("td3", {"policy_kwargs": {"net_arch": bad}})
        with pytest.raises(ValueError) as built:
            PopulationTD3(K, OBS, ACT, settings)
        with pytest.raises(EngineError, match="does not support net_arch") as checked:
            check_supported("td3", settings)
        assert str(built.value) in str(checked.value)

