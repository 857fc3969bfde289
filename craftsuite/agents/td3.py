"""TD3 students as saved: SB3's TD3 class that holds a trained member of the population
engine (``craftsuite.population``), so that ``TD3.load`` and ``load_agent`` open it and it
acts. It does not learn: its settings say what the population engine trained (the prioritized
replay, the actor's delay schedule, the distilled target), and ``learn`` names the trainer.

* ``layer_norm``: LayerNorm after each hidden Linear layer of the critics and their
  targets (``LayerNormTD3Policy``, a policy keyword, so a saved model rebuilds them); the
  actor is SB3's.
"""

from __future__ import annotations

from stable_baselines3 import TD3
from stable_baselines3.common.policies import ContinuousCritic
from stable_baselines3.common.preprocessing import get_action_dim
from stable_baselines3.td3.policies import TD3Policy
from torch import nn

from ..population.td3 import delay_at, delay_schedule as check_delay_schedule
from .distillation import DistilledTarget
from .base import AutomatonAlgorithm
from .networks import value_mlp
from .replay import AutomatonReplayBuffer, automaton_buffer_kwargs


class LayerNormCritic(ContinuousCritic):
    """SB3's TD3 critics with LayerNorm after each hidden Linear layer (same sizes)."""

    def __init__(self, observation_space, action_space, net_arch: list[int], features_extractor, features_dim: int,
                 activation_fn=nn.ReLU, **kwargs):
        super().__init__(observation_space, action_space, net_arch, features_extractor, features_dim,
                         activation_fn, **kwargs)
        in_dim = features_dim + get_action_dim(self.action_space)
        for idx in range(self.n_critics):  # each replaces SB3's MLP under its name (qf0, qf1, ...)
            q_net = value_mlp(in_dim, 1, net_arch, activation_fn, layer_norm=True)
            self.add_module(f"qf{idx}", q_net)
            self.q_networks[idx] = q_net


class LayerNormTD3Policy(TD3Policy):
    """SB3's TD3 policy whose critics and their targets have LayerNorm in their hidden
    layers when ``layer_norm`` (a policy keyword, so a saved model rebuilds them); the actor
    is SB3's either way."""

    def __init__(self, *args, layer_norm: bool = False, **kwargs):
        self.layer_norm = layer_norm  # before TD3Policy's __init__, which builds the nets
        super().__init__(*args, **kwargs)

    def make_critic(self, features_extractor=None) -> ContinuousCritic:
        if not self.layer_norm:
            return super().make_critic(features_extractor)
        critic_kwargs = self._update_features_extractor(self.critic_kwargs, features_extractor)
        return LayerNormCritic(**critic_kwargs).to(self.device)

    def _get_constructor_parameters(self) -> dict:
        return {**super()._get_constructor_parameters(), "layer_norm": self.layer_norm}


class AutomatonTD3(AutomatonAlgorithm, TD3):
    """TD3 for CraftSuite worlds, as a trained member is saved: prioritized, delay-scheduled,
    optionally distilled (its training is ``craftsuite.population``'s).

    Args (beyond SB3's TD3):
        prioritized: prioritized replay (``AutomatonReplayBuffer``), else uniform.
        distill: a ``DistilledTarget``; None for TD3 from scratch and product TD3.
        delay_schedule: ``((until_step, delay), ..., (None, delay))``: the actor's delay
            by step (default: ``hyperparameters.TD3_DELAY_SCHEDULE``).
        policy_delay: a constant delay, as in SB3's TD3: the schedule ``((None, policy_delay),)``
            (give this or ``delay_schedule``); ``policy_delay_at(step)`` reads the schedule.
        n_steps: the length of the TD targets it was trained with (1: one-step); SB3's own
            setting, so ``model.n_steps`` says it.
        layer_norm: LayerNorm after each hidden Linear layer of the critics and their
            targets, before the activation (with ``policy="MlpPolicy"``; a policy keyword).

    ``algorithm`` (``"td3"``) is saved with the model, so that ``load_agent`` knows its class.
    """

    def __init__(self, policy, env, *, prioritized: bool = True, distill: DistilledTarget | None = None,
                 delay_schedule=None, policy_delay: int | None = None, n_steps: int = 1,
                 layer_norm: bool = False, replay_buffer_kwargs: dict | None = None, **kwargs):
        if layer_norm:  # a policy keyword, saved with the model's policy_kwargs; off, all stays SB3's
            policy = LayerNormTD3Policy if policy == "MlpPolicy" else policy
            kwargs["policy_kwargs"] = {**(kwargs.get("policy_kwargs") or {}), "layer_norm": True}
        self.layer_norm = layer_norm
        kwargs.setdefault("replay_buffer_class", AutomatonReplayBuffer)
        replay_buffer_kwargs = automaton_buffer_kwargs(prioritized, n_steps, kwargs.get("gamma", 0.99),
                                                       replay_buffer_kwargs)
        self.algorithm = "td3"
        self.distill = distill
        self.delay_schedule = check_delay_schedule(delay_schedule, policy_delay)
        super().__init__(policy, env, replay_buffer_kwargs=replay_buffer_kwargs, n_steps=n_steps,
                         policy_delay=self.policy_delay_at(0), **kwargs)

    def policy_delay_at(self, step: int) -> int:
        """The actor's delay the schedule sets at ``step``."""
        return delay_at(self.delay_schedule, step)
