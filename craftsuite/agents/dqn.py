"""DQN teachers and students as saved: SB3's DQN class that holds a trained member of the
population engine (``craftsuite.population``), so that ``DQN.load`` and ``load_agent`` open
it and it acts. It does not learn: its settings say what the population engine trained
(double DQN, prioritized replay, the loss, the target update's unit, the distilled
target), and ``learn`` names the trainer.

Its networks, which a saved model rebuilds (policy classes and keywords):
* ``DuelingQNetwork``: Q = V + A - mean(A) on SB3's MLP trunk.
* ``features_extractor``: SB3's flattening, or a residual CNN over the grid's planes
  (``agents/networks.py``).
* ``layer_norm``: LayerNorm after each hidden Linear layer of the Q-network and its target
  (``LayerNormDQNPolicy``; the dueling policy takes it too).
"""

from __future__ import annotations

import numpy as np
import torch as th
from stable_baselines3 import DQN
from stable_baselines3.dqn.policies import DQNPolicy, QNetwork
from torch import nn

from ..hyperparameters import DQN_CHOICES
from .distillation import DistilledTarget
from .networks import features_policy_kwargs, value_mlp
from .base import AutomatonAlgorithm
from .replay import AutomatonReplayBuffer, automaton_buffer_kwargs


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
    """DQN for CraftSuite worlds, as a trained member is saved: dueling, double, prioritized,
    optionally distilled (its training is ``craftsuite.population``'s).

    Args (beyond SB3's DQN):
        double: use the double-DQN target (online argmax, target-network value).
        dueling: with ``policy="MlpPolicy"``, use ``DuelingDQNPolicy``.
        prioritized: prioritized replay (``AutomatonReplayBuffer``), else uniform.
        distill: a ``DistilledTarget`` for students; None for teachers and baselines.
        n_steps: the length of the TD targets it was trained with (1: one-step); SB3's own
            setting, so ``model.n_steps`` says it.
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
            raise ValueError(f"loss must be one of {', '.join(LOSSES)}, got {loss!r}")
        if target_update_unit not in TARGET_UPDATE_UNITS:
            raise ValueError(f"target_update_unit must be one of {', '.join(TARGET_UPDATE_UNITS)}, "
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
