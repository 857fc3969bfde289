"""DQN teachers and students: SB3's DQN with a dueling head, the double-DQN target,
prioritized replay and, for students, the distilled target.

Where this differs from SB3's DQN, and nowhere else:
* ``DuelingQNetwork``: Q = V + A - mean(A) on SB3's MLP trunk (a policy class).
* ``AutomatonDQN._td_target``: the one seam for the target (double DQN, then the distilled
  mix when a ``DistilledTarget`` is given).
* ``AutomatonDQN.train``: SB3's loop, with the loss weighted by importance weights and
  the priorities updated from the TD errors; the loss Huber (SB3's) or squared error
  (the paper's authors'); the target network's hard update counted in transitions (SB3's
  ``target_update_interval``) or in gradient steps (the authors').
* ``features_extractor``: SB3's flattening, or a residual CNN over the grid's planes
  (``agents/networks.py``).
* ``layer_norm``: LayerNorm after each hidden Linear layer of the Q-network and its target
  (``LayerNormDQNPolicy``; the dueling policy takes it too).
"""

from __future__ import annotations

import numpy as np
import torch as th
import torch.nn.functional as F
from stable_baselines3 import DQN
from stable_baselines3.common.utils import polyak_update
from stable_baselines3.dqn.policies import DQNPolicy, QNetwork
from torch import nn

from ..hyperparameters import DQN_CHOICES
from .distillation import DistilledTarget
from .networks import features_policy_kwargs, value_mlp
from .base import AutomatonAlgorithm
from .replay import AutomatonReplayBuffer, AutomatonSamples, automaton_buffer_kwargs


LOSSES, TARGET_UPDATE_UNITS = DQN_CHOICES["loss"], DQN_CHOICES["target_update_unit"]


class _DuelingHead(nn.Module):
    """MLP trunk, then one linear layer giving V (column 0) and A (the rest) together:
    fewer small ops than two heads, which is what costs time for small nets on a CPU."""

    def __init__(self, in_dim: int, n_actions: int, net_arch: list[int], activation_fn, layer_norm: bool = False):
        super().__init__()
        self.net = value_mlp(in_dim, n_actions + 1, net_arch, activation_fn, layer_norm)

    def forward(self, x: th.Tensor) -> th.Tensor:
        out = self.net(x)
        a = out[:, 1:]
        return out[:, :1] + a - a.mean(dim=1, keepdim=True)


class DuelingQNetwork(QNetwork):
    """SB3's QNetwork with its MLP replaced by a dueling head (same trunk sizes), its hidden
    layers with LayerNorm when ``layer_norm``."""

    def __init__(self, *args, layer_norm: bool = False, **kwargs):
        super().__init__(*args, **kwargs)
        self.q_net = _DuelingHead(self.features_dim, int(self.action_space.n), self.net_arch, self.activation_fn,
                                  layer_norm)


class LayerNormQNetwork(QNetwork):
    """SB3's QNetwork with LayerNorm after each hidden Linear layer (same sizes)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.q_net = value_mlp(self.features_dim, int(self.action_space.n), self.net_arch, self.activation_fn,
                               layer_norm=True)


class LayerNormDQNPolicy(DQNPolicy):
    """SB3's DQN policy whose Q-network and target have LayerNorm in their hidden layers
    when ``layer_norm`` (a policy keyword, so a saved model rebuilds them); SB3's otherwise."""

    def __init__(self, *args, layer_norm: bool = False, **kwargs):
        self.layer_norm = layer_norm  # before DQNPolicy's __init__, which builds the nets
        super().__init__(*args, **kwargs)

    def make_q_net(self) -> QNetwork:
        net_args = self._update_features_extractor(self.net_args, features_extractor=None)
        return (LayerNormQNetwork if self.layer_norm else QNetwork)(**net_args).to(self.device)

    def _get_constructor_parameters(self) -> dict:
        return {**super()._get_constructor_parameters(), "layer_norm": self.layer_norm}


class DuelingDQNPolicy(LayerNormDQNPolicy):
    """The dueling head's policy (``DuelingQNetwork``), with ``layer_norm`` as its base's."""

    def make_q_net(self) -> DuelingQNetwork:
        net_args = self._update_features_extractor(self.net_args, features_extractor=None)
        return DuelingQNetwork(**net_args, layer_norm=self.layer_norm).to(self.device)


class AutomatonDQN(AutomatonAlgorithm, DQN):
    """DQN for CraftSuite worlds: dueling, double, prioritized, optionally distilled.

    Args (beyond SB3's DQN):
        double: use the double-DQN target (online argmax, target-network value).
        dueling: with ``policy="MlpPolicy"``, use ``DuelingDQNPolicy``.
        prioritized: prioritized replay (``AutomatonReplayBuffer``), else uniform.
        distill: a ``DistilledTarget`` for students; None for teachers and baselines.
        n_steps: n-step returns from the replay buffer (1: the one-step target); SB3's own
            setting, so ``model.n_steps`` is what the buffer uses.
        loss: ``"huber"`` (SB3's smooth L1) or ``"mse"`` (squared TD error).
        target_update_unit: what ``target_update_interval`` counts: ``"transitions"`` (SB3's
            meaning: env steps over all envs) or ``"gradient_steps"``.
        features_extractor: ``"flatten"`` (SB3's) or ``"residual-cnn"`` (grid worlds).
        layer_norm: LayerNorm after each hidden Linear layer of the Q-network and its
            target, before the activation (with ``policy="MlpPolicy"``; a policy keyword).

    ``algorithm`` (``"dqn"``) is saved with the model, so that ``load_agent`` knows its class.
    """

    def __init__(self, policy, env, *, double: bool = True, dueling: bool = True, prioritized: bool = True,
                 distill: DistilledTarget | None = None, n_steps: int = 1, loss: str = "huber",
                 target_update_unit: str = "transitions", features_extractor: str = "flatten",
                 layer_norm: bool = False, replay_buffer_kwargs: dict | None = None, **kwargs):
        if loss not in LOSSES:
            raise ValueError(f"loss must be one of {list(LOSSES)}, got {loss!r}")
        if target_update_unit not in TARGET_UPDATE_UNITS:
            raise ValueError(f"target_update_unit must be one of {list(TARGET_UPDATE_UNITS)}, "
                             f"got {target_update_unit!r}")
        if env is not None:  # None when SB3 loads a saved agent: its policy_kwargs hold the extractor already
            kwargs["policy_kwargs"] = features_policy_kwargs(features_extractor, env, kwargs.get("policy_kwargs"))
        self.loss, self.target_update_unit, self.features_extractor = loss, target_update_unit, features_extractor
        if policy == "MlpPolicy" and (dueling or layer_norm):
            policy = DuelingDQNPolicy if dueling else LayerNormDQNPolicy
        if layer_norm:  # a policy keyword, saved with the model's policy_kwargs; off, they stay SB3's
            kwargs["policy_kwargs"] = {**(kwargs.get("policy_kwargs") or {}), "layer_norm": True}
        self.layer_norm = layer_norm
        kwargs.setdefault("replay_buffer_class", AutomatonReplayBuffer)
        replay_buffer_kwargs = automaton_buffer_kwargs(prioritized, n_steps, kwargs.get("gamma", 0.99),
                                                       replay_buffer_kwargs)
        self.algorithm = "dqn"
        self.double = double
        self.distill = distill
        super().__init__(policy, env, replay_buffer_kwargs=replay_buffer_kwargs, n_steps=n_steps, **kwargs)

    def _td_target(self, data: AutomatonSamples) -> th.Tensor:
        """r + gamma * Q_target(s', a*), a* from the online net when double; then distilled."""
        with th.no_grad():
            next_q = self.q_net_target(data.next_observations)
            if self.double:
                # a CNN's batch-norm statistics move once per gradient step, not twice (an MLP has none:
                # no mode switch on the hot path)
                training = self.q_net.training
                if self.batch_norm_stats:
                    self.q_net.set_training_mode(False)
                best = self.q_net(data.next_observations).argmax(dim=1, keepdim=True)
                if self.batch_norm_stats:
                    self.q_net.set_training_mode(training)
                next_q = th.gather(next_q, dim=1, index=best)
            else:
                next_q = next_q.max(dim=1, keepdim=True)[0]
            discount = self.gamma if data.discounts is None else data.discounts  # gamma ** k after k rewards
            target = data.rewards + (1 - data.dones) * discount * next_q
            if self.distill is not None:
                target = self.distill(data.w, data.sigma, target)
        return target

    def _on_step(self) -> None:
        if self.target_update_unit == "transitions":
            return super()._on_step()  # SB3's: the target's update by transitions, then epsilon
        self._n_calls += 1
        self.exploration_rate = self.exploration_schedule(self._current_progress_remaining)
        self.logger.record("rollout/exploration_rate", self.exploration_rate)

    def _update_target(self) -> None:
        polyak_update(self.q_net.parameters(), self.q_net_target.parameters(), self.tau)
        polyak_update(self.batch_norm_stats, self.batch_norm_stats_target, 1.0)  # a CNN's running stats, as SB3

    def train(self, gradient_steps: int, batch_size: int = 100) -> None:
        self.policy.set_training_mode(True)
        self._update_learning_rate(self.policy.optimizer)
        losses = []
        for step in range(gradient_steps):
            data = self.replay_buffer.sample(batch_size, env=self._vec_normalize_env)
            target = self._td_target(data)
            current = th.gather(self.q_net(data.observations), dim=1, index=data.actions.long())
            loss_fn = F.smooth_l1_loss if self.loss == "huber" else F.mse_loss
            if self.replay_buffer.prioritized:
                loss = (data.weights * loss_fn(current, target, reduction="none")).mean()
            else:  # uniform replay: SB3's loss exactly
                loss = loss_fn(current, target)
            losses.append(loss.item())
            self.policy.optimizer.zero_grad()
            loss.backward()
            th.nn.utils.clip_grad_norm_(self.policy.parameters(), self.max_grad_norm)
            self.policy.optimizer.step()
            if self.replay_buffer.prioritized:
                self.replay_buffer.update_priorities(data.indices, (current - target).detach().cpu().numpy())
            counted = self._n_updates + step + 1
            if self.target_update_unit == "gradient_steps" and counted % self.target_update_interval == 0:
                self._update_target()
        self._n_updates += gradient_steps
        self.logger.record("train/n_updates", self._n_updates, exclude="tensorboard")
        self.logger.record("train/loss", np.mean(losses))
        if self.distill is not None:
            self.logger.record("train/teacher_weight", self.distill.last_weight)

    def q_values(self, observations: np.ndarray) -> np.ndarray:
        """Q(s, .) of the online network for a batch of observations, in evaluation mode (a
        CNN's batch norm reads its running statistics and leaves them as they are), as the
        greedy policy acts; the network's mode is restored after."""
        training = self.q_net.training
        self.q_net.set_training_mode(False)
        try:
            with th.no_grad():
                obs = th.as_tensor(np.asarray(observations), device=self.device, dtype=th.float32)
                return self.q_net(obs).cpu().numpy()
        finally:
            self.q_net.set_training_mode(training)
