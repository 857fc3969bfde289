"""The one rollout loop: the same episodes whether played one after another or side by side."""

from __future__ import annotations

import gymnasium as gym
import numpy as np

from craftsuite.episodes import rollout

ENV_ID = "CraftSuite/DungeonQuest-Grid7-v0"


def pick(obs) -> int:
    """An action that depends on the observation, so that a mixed-up batch shows."""
    return int(np.asarray(obs, dtype=float).sum() * 7) % 4


def records(played):
    return [(e.seed, round(e.total_reward, 9), e.length, e.success) for e in played]


def test_side_by_side_plays_the_same_episodes_as_one_after_another():
    one = gym.make(ENV_ID, max_episode_steps=30)
    sequential = rollout(one, pick, 5, seed=11)
    for n_envs in (5, 2):  # one episode each; and envs that play several (0, 2, 4 and 1, 3)
        envs = [gym.make(ENV_ID, max_episode_steps=30) for _ in range(n_envs)]
        batches = []

        def batched(obs):
            batches.append(len(obs))
            return [pick(o) for o in obs]

        assert records(rollout(envs, batched, 5, seed=11)) == records(sequential)
        assert batches[0] == n_envs  # one call per decision for all envs still playing
    assert [e.seed for e in sequential] == [11, 12, 13, 14, 15]
    assert all(e.length == 30 or e.success or e.info["violation"] for e in sequential)


def test_callbacks_see_every_reset_and_step_and_max_steps_ends_an_episode():
    env = gym.make(ENV_ID)
    env.reset(seed=4)  # seed=None goes on from the env's generator: seeded here, the layouts are fixed
    resets, steps = [], []
    played = rollout(env, pick, 3, seed=None, max_steps=7, on_reset=resets.append,
                     on_step=lambda episode, reward, info: steps.append((episode, reward)))
    assert resets == [0, 1, 2] and [e.seed for e in played] == [None] * 3
    # an episode ends at max_steps unless the task ended it first
    assert all(e.length == 7 or e.success or e.info["violation"] for e in played)
    assert 7 in [e.length for e in played] and len(steps) == sum(e.length for e in played)
    for k, episode in enumerate(played):
        assert np.isclose(episode.total_reward, sum(r for e, r in steps if e == k))
