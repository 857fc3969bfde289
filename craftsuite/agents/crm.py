"""CRM's replay as a saved model names it: counterfactual experiences for reward machines
(Toro Icarte et al., JAIR 2022), one per live automaton state for every real transition.

A saved CRM model names ``CRMReplayBuffer`` and its keywords (the task's ``automaton`` and
``completion_reward``), so loading one builds it. The counterfactuals themselves are made
by the population engine's replay (``craftsuite.population.replay.CounterfactualView``).
"""

from __future__ import annotations

from ..automata import Automaton
from .replay import AutomatonReplayBuffer


class CRMReplayBuffer(AutomatonReplayBuffer):
    """The replay a saved CRM model is built with: one column per (env, live automaton state).

    Extra args: ``automaton`` and ``completion_reward`` of the task (the env's
    ``unwrapped.automaton`` and ``task.completion_reward``).
    """

    def __init__(self, buffer_size, observation_space, action_space, device="auto", n_envs: int = 1, *,
                 automaton: Automaton, completion_reward: float, **kwargs):
        self.automaton, self.completion_reward = automaton, completion_reward
        self.n_live = int((~(automaton.accepting | automaton.rejecting)).sum())
        if observation_space.shape[0] < automaton.n_states:
            raise ValueError("CRM needs the product observation (make the env with product=True)")
        super().__init__(buffer_size * self.n_live, observation_space, action_space, device,
                         n_envs=n_envs * self.n_live, **kwargs)

    def add(self, *args, **kwargs) -> None:
        raise RuntimeError("CRMReplayBuffer holds a saved CRM model's settings and does not collect: CRM's "
                           "counterfactuals are made by the population engine; train with "
                           "craftsuite.population.train_population (or `craftsuite student`)")
