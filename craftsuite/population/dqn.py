"""DQN for K members in one set of stacked networks: CraftSuite's one DQN update
(the dueling head, the double-DQN target, Huber or squared loss weighted by importance
weights, each member's gradient clipped to its own norm, the hard target update counted in
transitions or gradient steps, the distilled target), computed for every member at once.
With ``features_extractor="residual-cnn"`` each member's Q-network reads the grid's planes
through the paper's residual CNN (``cnn.py``); its batch norms are in training mode only
for the update's own Q-values, as SB3's DQN has them (the greedy actions, the double-DQN
argmax and the target network read the running statistics)."""

from __future__ import annotations

import contextlib

import numpy as np
import torch as th
import torch.nn.functional as F
from stable_baselines3.common.utils import polyak_update  # elementwise: stacked members too

from .cnn import StackedQNetwork, StackedResidualCNN
from .nets import StackedMLP, activation_of, clip_grad_norm_per_member, hidden_widths
from .replay import Batch, SparseRows
from .targets import MemberTargets, discount


class PopulationDQN:
    """K DQN learners. ``settings`` are a run's effective DQN settings
    (``hyperparameters.algorithm_settings("dqn", ...)``); ``targets`` the members' distilled targets."""

    algorithm = "dqn"

    def __init__(self, members: int, obs_dim: int, n_actions: int, settings: dict,
                 targets: MemberTargets | None = None, device: str | th.device = "cpu",
                 planes: tuple[int, int, int] | None = None):
        import torch.nn as nn

        self.members, self.device, self.n_actions, self.obs_dim = members, th.device(device), n_actions, obs_dim
        policy_kwargs = settings.get("policy_kwargs") or {}
        hidden, _ = hidden_widths(policy_kwargs, "dqn", [64, 64])
        act = activation_of(policy_kwargs.get("activation_fn", nn.ReLU))
        self.dueling = bool(settings.get("dueling", True))
        outputs = n_actions + 1 if self.dueling else n_actions  # column 0 is V, as agents.dqn's head
        layer_norm = bool(settings.get("layer_norm", False))  # in the hidden layers, as agents.dqn's policies
        self.cnn = settings.get("features_extractor", "flatten") == "residual-cnn"
        if self.cnn and planes is None:
            raise ValueError("a residual CNN reads the grid's planes: give planes (the world's observation_layout)")

        def network():
            if not self.cnn:
                return StackedMLP(members, [obs_dim, *hidden, outputs], act, device=self.device, layer_norm=layer_norm)
            features = StackedResidualCNN(members, obs_dim, planes, device=self.device)
            return StackedQNetwork(features, StackedMLP(members, [features.features_dim, *hidden, outputs], act,
                                                        device=self.device, layer_norm=layer_norm))

        self.q_net, self.q_net_target = network(), network()
        self.q_net_target.load_state_dict(self.q_net.state_dict())
        self.q_net_target.eval()  # a CNN's target reads its running statistics, as SB3's
        optimizer_kwargs = {**(policy_kwargs.get("optimizer_kwargs") or {})}
        self.optimizer = th.optim.Adam(self.q_net.parameters(), lr=float(settings["learning_rate"]),
                                       **optimizer_kwargs)
        self.gamma, self.tau = float(settings["gamma"]), float(settings.get("tau", 1.0))  # SB3's hard update
        self.double = bool(settings.get("double", True))
        self.loss = settings.get("loss", "huber")
        self.max_grad_norm = float(settings.get("max_grad_norm", 10.0))
        self.prioritized = bool(settings.get("prioritized", True))
        self.target_update_unit = settings.get("target_update_unit", "transitions")
        self.target_update_interval = int(settings["target_update_interval"])
        self.targets = targets
        self.n_updates = 0

    def q_values(self, net: StackedMLP, observations: th.Tensor) -> th.Tensor:
        out = net(observations)
        if not self.dueling:
            return out
        advantage = out[..., 1:]
        return out[..., :1] + advantage - advantage.mean(dim=-1, keepdim=True)

    def inputs(self, observations):
        """A minibatch's observations as the networks take them: a tensor, or the
        ``(index, value)`` tensors of ``SparseRows`` (for a CNN, which reads whole planes,
        the dense tensor they stand for: the replay stays sparse)."""
        if isinstance(observations, SparseRows):
            index = th.as_tensor(observations.index, device=self.device)
            value = th.as_tensor(observations.value, device=self.device)
            if not self.cnn:
                return index, value
            dense = th.zeros((*index.shape[:-1], self.obs_dim), dtype=value.dtype, device=self.device)
            return dense.scatter_add_(-1, index, value)  # the padding adds zeros at index 0
        return th.as_tensor(observations, device=self.device)

    # what ``act``'s second array holds, for the engine's message when it is not finite
    OUTPUTS = "Q-values"

    def act(self, observations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Greedy actions ``(K, n)`` for observations ``(K, n, obs_dim)``, and each state's sum of
        Q-values, finite exactly when all its Q-values are (an argmax of NaN is still an action)."""
        with th.no_grad(), self.evaluating():
            q = self.q_values(self.q_net, th.as_tensor(observations, device=self.device))
            both = th.stack((q.argmax(dim=-1).to(q.dtype), q.sum(dim=-1))).cpu().numpy()  # one copy off the device
            return both[0].astype(np.int64), both[1]

    def evaluating(self):
        """A context in which the online network's batch norms (a CNN's) read their running
        statistics and leave them as they are; nothing to switch for an MLP."""
        if not self.cnn:
            return contextlib.nullcontext()
        return _eval_mode(self.q_net)

    def td_target(self, batch: Batch, next_obs) -> th.Tensor:
        """The one DQN target rule, ``(K, B, 1)``: r + gamma * Q_target(s', a*), a* the online
        network's argmax when double (else the target's max), then the distilled mix where there is one."""
        K, B = batch.rewards.shape
        with th.no_grad():
            next_q = self.q_values(self.q_net_target, next_obs)
            if self.double:
                with self.evaluating():  # a CNN's statistics move once per update, as agents.dqn's
                    best = self.q_values(self.q_net, next_obs).argmax(dim=-1, keepdim=True)
                next_q = th.gather(next_q, dim=-1, index=best)
            else:
                next_q = next_q.max(dim=-1, keepdim=True)[0]
            rewards = th.as_tensor(batch.rewards, device=self.device).reshape(K, B, 1)
            terminals = th.as_tensor(batch.terminals, device=self.device).reshape(K, B, 1)
            target = rewards + (1 - terminals) * discount(batch, self.gamma, self.device) * next_q
            if self.targets is not None:  # (w, sigma): the first step's, at n steps too (targets.py)
                target = self.targets(batch.w, batch.sigma, target)
        return target

    def update(self, batch: Batch) -> np.ndarray:
        """One gradient step of every member; returns the TD errors ``(K, B)``."""
        K, B = batch.rewards.shape
        target = self.td_target(batch, self.inputs(batch.next_observations))
        obs = self.inputs(batch.observations)
        actions = th.as_tensor(batch.actions, device=self.device).reshape(K, B, 1).long()
        current = th.gather(self.q_values(self.q_net, obs), dim=-1, index=actions)
        loss_fn = F.smooth_l1_loss if self.loss == "huber" else F.mse_loss
        elementwise = loss_fn(current, target, reduction="none")
        if self.prioritized:
            elementwise = th.as_tensor(batch.weights, device=self.device).reshape(K, B, 1) * elementwise
        per_member = elementwise.mean(dim=(1, 2))
        self.optimizer.zero_grad()
        per_member.sum().backward()
        if self.cnn:
            self.q_net.features.drop_bias_gradients()
        clip_grad_norm_per_member(self.q_net.parameters(), self.max_grad_norm)
        self.optimizer.step()
        self.n_updates += 1
        if self.target_update_unit == "gradient_steps" and self.n_updates % self.target_update_interval == 0:
            self.update_target()
        return (current - target).detach().reshape(K, B).cpu().numpy()

    def update_target(self) -> None:
        polyak_update(self.q_net.parameters(), self.q_net_target.parameters(), self.tau)
        if self.cnn:  # and the running statistics, copied as SB3's DQN copies them
            polyak_update(self.q_net.features.running_stats(), self.q_net_target.features.running_stats(), 1.0)

    # -- members as SB3 agents ---------------------------------------------------------------------
    def _sequential(self, q_network):
        return q_network.q_net.net if self.dueling else q_network.q_net

    def _pairs(self, agent):
        """(stacked network, SB3 network) for the online and the target network."""
        return ((self.q_net, agent.policy.q_net), (self.q_net_target, agent.policy.q_net_target))

    def load_member(self, k: int, agent) -> None:
        """Member ``k``'s networks from an ``AutomatonDQN`` (online and target)."""
        for stacked, q_network in self._pairs(agent):
            if self.cnn:
                stacked.features.load_member(k, q_network.features_extractor)
            (stacked.head if self.cnn else stacked).load_member(k, self._sequential(q_network))

    def store_member(self, k: int, agent) -> None:
        for stacked, q_network in self._pairs(agent):
            if self.cnn:
                stacked.features.store_member(k, q_network.features_extractor)
            (stacked.head if self.cnn else stacked).store_member(k, self._sequential(q_network))

    def modules(self) -> dict:
        return {"q_net": self.q_net, "q_net_target": self.q_net_target}

    def optimizers(self) -> dict:
        return {"optimizer": self.optimizer}



@contextlib.contextmanager
def _eval_mode(module):
    """``module`` in evaluation mode inside the context, its mode before restored after."""
    training = module.training
    module.eval()
    try:
        yield
    finally:
        module.train(training)
