"""CRM: counterfactual experiences for reward machines (Toro Icarte et al., JAIR 2022).

For every real transition of the product MDP, one experience per non-terminal automaton
state u: the same world step, read by the automaton from u. The label sigma is a fact of
the world, so u' = delta(u, sigma); the reward swaps the real completion bonus for u's;
the experience ends where u' accepts or is the rejecting sink (or where the real step hit
the time limit, which stays a timeout). Observations carry the automaton one-hot in their
last ``n_states`` entries (``product=True``), which is rewritten for u and u'.
"""

from __future__ import annotations

import numpy as np

from ..automata import Automaton
from .replay import AutomatonReplayBuffer


def counterfactuals(automaton: Automaton, completion_reward: float, obs, next_obs, action, reward,
                    truncated: bool, w: int, sigma: int):
    """Experiences of one real transition (from automaton state ``w``, label ``sigma``) for
    every live automaton state: (u, u', obs, next_obs, actions, rewards, dones, timeouts)."""
    S = automaton.n_states
    live = np.flatnonzero(~(automaton.accepting | automaton.rejecting))
    u_next = automaton.delta[live, sigma].astype(np.int64)
    # the world's own reward (step, items) without the real completion bonus, then u's bonus
    base = reward - completion_reward * automaton.accepting[automaton.delta[w, sigma]]
    rewards = base + completion_reward * automaton.accepting[u_next]
    ends = automaton.accepting[u_next] | automaton.rejecting[u_next]
    obs_u = np.repeat(obs[None], len(live), axis=0)
    next_u = np.repeat(next_obs[None], len(live), axis=0)
    obs_u[:, -S:] = 0.0
    obs_u[np.arange(len(live)), obs.shape[0] - S + live] = 1.0
    next_u[:, -S:] = 0.0
    next_u[np.arange(len(live)), next_obs.shape[0] - S + u_next] = 1.0
    dones = ends | bool(truncated)
    timeouts = ~ends & bool(truncated)
    actions = np.repeat(np.asarray(action)[None], len(live), axis=0)
    return live, u_next, obs_u, next_u, actions, rewards, dones, timeouts


class CRMReplayBuffer(AutomatonReplayBuffer):
    """Stores, for each real transition, its counterfactuals for every live automaton state.

    Extra args: ``automaton`` and ``completion_reward`` of the task (the env's
    ``unwrapped.automaton`` and ``task.completion_reward``).
    """

    def __init__(self, buffer_size, observation_space, action_space, device="auto", n_envs: int = 1, *,
                 automaton: Automaton, completion_reward: float, **kwargs):
        # its columns are counterfactual states, not trajectories: it samples one-step
        # experiences only. An n-step CRM model (the population engine trains it) is built
        # with one to be saved, and refuses to sample
        self.n_steps_trained = kwargs.pop("n_steps", 1)
        self.automaton, self.completion_reward = automaton, completion_reward
        self.n_real_envs = n_envs
        self.n_live = int((~(automaton.accepting | automaton.rejecting)).sum())
        if observation_space.shape[0] < automaton.n_states:
            raise ValueError("CRM needs the product observation (make the env with product=True)")
        super().__init__(buffer_size * self.n_live, observation_space, action_space, device,
                         n_envs=n_envs * self.n_live, **kwargs)

    def sample(self, *args, **kwargs):
        if getattr(self, "n_steps_trained", 1) != 1:  # a pickle without it holds one-step CRM
            raise ValueError(f"n-step CRM (n_steps {self.n_steps_trained}) samples windows in the population "
                             "engine only: train it with --engine population")
        return super().sample(*args, **kwargs)

    def add(self, obs, next_obs, action, reward, done, infos) -> None:
        rows = [[] for _ in range(8)]
        cf_infos = []
        action = np.asarray(action).reshape(self.n_real_envs, -1)
        for e, info in enumerate(infos):
            w, sigma, _ = info["automaton_transition"]
            truncated = bool(info.get("TimeLimit.truncated", False))
            parts = counterfactuals(self.automaton, self.completion_reward, np.asarray(obs[e]),
                                    np.asarray(next_obs[e]), action[e], float(reward[e]), truncated, w, sigma)
            for store, part in zip(rows, parts):
                store.append(part)
            live, u_next = parts[0], parts[1]
            cf_infos += [{"automaton_transition": (int(u), int(sigma), int(v)),
                          "TimeLimit.truncated": bool(t)} for u, v, t in zip(live, u_next, parts[7])]
        _, _, obs_u, next_u, actions, rewards, dones, _ = (np.concatenate(r) for r in rows)
        super().add(obs_u, next_u, actions, rewards, dones, cf_infos)
