"""TD3 students for the MuJoCo worlds: SB3's TD3 with prioritized replay, an actor delay
schedule and, for distilled students, the distilled target.

Where this differs from SB3's TD3, and nowhere else:
* ``AutomatonTD3._td_target``: the one seam for the target (clipped double-Q with target
  policy smoothing, as SB3, after n rewards when ``n_steps`` > 1; then the distilled mix
  when a ``DistilledTarget`` is given).
* ``AutomatonTD3.train``: SB3's loop, with the critic loss weighted by importance weights,
  priorities updated from the first critic's TD errors, and the actor delayed by
  ``policy_delay_at(num_timesteps)`` (by default ``hyperparameters.TD3_DELAY_SCHEDULE``), which it
  sets as SB3's ``policy_delay`` for each call, so that attribute says the delay in force.
* ``layer_norm``: LayerNorm after each hidden Linear layer of the critics and their
  targets (``LayerNormTD3Policy``); the actor is SB3's.
"""

from __future__ import annotations

import numpy as np
import torch as th
import torch.nn.functional as F
from stable_baselines3 import TD3
from stable_baselines3.common.policies import ContinuousCritic
from stable_baselines3.common.preprocessing import get_action_dim
from stable_baselines3.common.utils import polyak_update
from stable_baselines3.td3.policies import TD3Policy
from torch import nn

from ..hyperparameters import TD3_DELAY_SCHEDULE
from .distillation import DistilledTarget
from .base import AutomatonAlgorithm
from .networks import value_mlp
from .replay import AutomatonReplayBuffer, AutomatonSamples, automaton_buffer_kwargs


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
    """TD3 for CraftSuite worlds: prioritized, delay-scheduled, optionally distilled.

    Args (beyond SB3's TD3):
        prioritized: prioritized replay (``AutomatonReplayBuffer``), else uniform.
        distill: a ``DistilledTarget``; None for TD3 from scratch and product TD3.
        delay_schedule: ``((until_step, delay), ..., (None, delay))``: the actor's delay
            by step (default: ``hyperparameters.TD3_DELAY_SCHEDULE``).
        policy_delay: a constant delay, as in SB3's TD3: the schedule ``((None, policy_delay),)``
            (give this or ``delay_schedule``). ``model.policy_delay`` is always the delay in
            force: the schedule's at the last training call.
        n_steps: n-step returns from the replay buffer (1: SB3's one-step target); SB3's own
            setting, so ``model.n_steps`` is what the buffer uses.
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
        self.delay_schedule = _delay_schedule(delay_schedule, policy_delay)
        super().__init__(policy, env, replay_buffer_kwargs=replay_buffer_kwargs, n_steps=n_steps,
                         policy_delay=self.policy_delay_at(0), **kwargs)

    def policy_delay_at(self, step: int) -> int:
        return delay_at(self.delay_schedule, step)

    def _td_target(self, data: AutomatonSamples) -> th.Tensor:
        with th.no_grad():
            noise = data.actions.clone().data.normal_(0, self.target_policy_noise)
            noise = noise.clamp(-self.target_noise_clip, self.target_noise_clip)
            next_actions = (self.actor_target(data.next_observations) + noise).clamp(-1, 1)
            next_q = th.cat(self.critic_target(data.next_observations, next_actions), dim=1)
            next_q = th.min(next_q, dim=1, keepdim=True)[0]
            discount = self.gamma if data.discounts is None else data.discounts  # gamma ** k after k rewards
            target = data.rewards + (1 - data.dones) * discount * next_q
            if self.distill is not None:
                target = self.distill(data.w, data.sigma, target)
        return target

    def train(self, gradient_steps: int, batch_size: int = 100) -> None:
        self.policy.set_training_mode(True)
        self._update_learning_rate([self.actor.optimizer, self.critic.optimizer])
        self.policy_delay = delay = self.policy_delay_at(self.num_timesteps)  # SB3's attribute tells the truth
        actor_losses, critic_losses = [], []
        for _ in range(gradient_steps):
            self._n_updates += 1
            data = self.replay_buffer.sample(batch_size, env=self._vec_normalize_env)
            target = self._td_target(data)
            current = self.critic(data.observations, data.actions)
            if self.replay_buffer.prioritized:
                critic_loss = sum((data.weights * (q - target) ** 2).mean() for q in current)
            else:  # uniform replay: SB3's loss exactly
                critic_loss = sum(F.mse_loss(q, target) for q in current)
            critic_losses.append(critic_loss.item())
            self.critic.optimizer.zero_grad()
            critic_loss.backward()
            self.critic.optimizer.step()
            if self.replay_buffer.prioritized:
                self.replay_buffer.update_priorities(data.indices, (current[0] - target).detach().cpu().numpy())

            if self._n_updates % delay == 0:
                actor_loss = -self.critic.q1_forward(data.observations, self.actor(data.observations)).mean()
                actor_losses.append(actor_loss.item())
                self.actor.optimizer.zero_grad()
                actor_loss.backward()
                self.actor.optimizer.step()
                polyak_update(self.critic.parameters(), self.critic_target.parameters(), self.tau)
                polyak_update(self.actor.parameters(), self.actor_target.parameters(), self.tau)
                polyak_update(self.critic_batch_norm_stats, self.critic_batch_norm_stats_target, 1.0)
                polyak_update(self.actor_batch_norm_stats, self.actor_batch_norm_stats_target, 1.0)

        self.logger.record("train/n_updates", self._n_updates, exclude="tensorboard")
        self.logger.record("train/policy_delay", delay)
        if actor_losses:
            self.logger.record("train/actor_loss", np.mean(actor_losses))
        self.logger.record("train/critic_loss", np.mean(critic_losses))
        if self.distill is not None:
            self.logger.record("train/teacher_weight", self.distill.last_weight)


def delay_at(schedule: tuple, step: int) -> int:
    """The actor's delay in force at ``step`` under a ``_delay_schedule``."""
    for until, delay in schedule:
        if until is None or step < until:
            return delay
    return schedule[-1][1]


def _delay_schedule(schedule, policy_delay) -> tuple:
    """The actor's delay schedule from ``delay_schedule`` or a constant ``policy_delay``."""
    if schedule is not None and policy_delay is not None:
        raise ValueError("give delay_schedule or policy_delay (a constant delay), not both")
    if policy_delay is not None:
        schedule = ((None, policy_delay),)
    elif schedule is None:
        schedule = TD3_DELAY_SCHEDULE
    schedule = tuple(tuple(row) for row in schedule)
    for i, row in enumerate(schedule):
        last = i == len(schedule) - 1
        ok = (len(row) == 2 and isinstance(row[1], int) and not isinstance(row[1], bool) and row[1] >= 1
              and ((row[0] is None) if last else (isinstance(row[0], int) and not isinstance(row[0], bool))))
        if not ok:
            raise ValueError(f"delay_schedule must be ((until_step, delay), ..., (None, delay)) with delays of at "
                             f"least 1, got {schedule!r}")
    return schedule
