"""Episodes of a policy in an env: the one rollout loop every caller shares (training's
evaluation, the reference scores, the scripted policy's episodes, the ``scripted`` command
and the videos); what a caller measures beyond an episode's record, or draws, it sees
through the loop's callbacks.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Episode(NamedTuple):
    """One episode's record."""
    seed: int | None  # the reset seed
    total_reward: float  # the episode's return (undiscounted)
    length: int  # decisions
    success: bool  # the task completed (``info["is_success"]`` of the last step)
    info: dict  # the last step's info (``violation``, the automaton's transition, ...)


def rollout(env, policy, episodes: int = 1, seed: int | None = 0, *, max_steps: int | None = None,
            on_reset=None, on_step=None) -> list[Episode]:
    """Play ``episodes`` episodes of ``policy`` on reset seeds ``seed``, ``seed + 1``, ...
    (all None when ``seed`` is None); their records, in seed order.

    ``env`` is one env, which plays the episodes one after another with ``policy(obs) ->
    action``; or a list of envs, which play them side by side (env ``j`` episodes ``j``,
    ``j + len(env)``, ...) with ``policy(batch) -> actions``, called once per decision on
    the stacked observations of the envs still playing, in env order (so that a network
    sees one batch per decision, not one call per env). An episode ends when the env
    terminates or truncates it, or after ``max_steps`` decisions. ``on_reset(episode)``
    and ``on_step(episode, reward, info)``, if given, see every reset and step (for
    measures beyond an ``Episode``'s, or frames: the env holds the state they show)."""
    envs, batched = (list(env), True) if isinstance(env, (list, tuple)) else ([env], False)
    if batched:
        act = lambda obs: policy(np.stack(obs))  # noqa: E731
    else:
        act = lambda obs: [policy(obs[0])]  # noqa: E731
    seeds = [None if seed is None else seed + e for e in range(episodes)]
    records: list[Episode | None] = [None] * episodes
    queues = [list(range(j, episodes, len(envs))) for j in range(len(envs))]  # each env's episodes, in order
    playing: dict[int, list] = {}  # env -> [episode, obs, total reward, length]

    def start(j: int) -> None:
        if queues[j]:
            episode = queues[j].pop(0)
            obs, _ = envs[j].reset(seed=seeds[episode])
            playing[j] = [episode, obs, 0.0, 0]
            if on_reset is not None:
                on_reset(episode)

    for j in range(len(envs)):
        start(j)
    while playing:
        live = sorted(playing)
        actions = act([playing[j][1] for j in live])
        for j, action in zip(live, actions):
            state = playing[j]
            state[1], reward, terminated, truncated, info = envs[j].step(action)
            state[2] += float(reward)
            state[3] += 1
            if on_step is not None:
                on_step(state[0], float(reward), info)
            if terminated or truncated or state[3] == max_steps:
                episode = state[0]
                records[episode] = Episode(seeds[episode], state[2], state[3], bool(info.get("is_success")), info)
                del playing[j]
                start(j)
    return records
