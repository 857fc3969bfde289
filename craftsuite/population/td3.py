"""TD3 for K members in one set of stacked networks: CraftSuite's one TD3 update (clipped
double-Q with target policy smoothing, importance-weighted critic loss with prioritized
replay, the actor delayed by a schedule (``delay_schedule``), Polyak averaging, the
distilled target), computed for every member in the same tensor operations. One optimizer
steps all members: Adam is elementwise, so each member's parameters move exactly as its
own Adam would move them. A member is saved as an ``agents.td3.AutomatonTD3``."""

from __future__ import annotations


import numpy as np
import torch as th
from stable_baselines3.common.utils import polyak_update  # elementwise: stacked members too

from ..hyperparameters import TD3_DELAY_SCHEDULE
from .nets import StackedMLP, activation_of, hidden_widths
from .replay import Batch
from .targets import MemberTargets, discount


class PopulationTD3:
    """K TD3 learners. ``settings`` are a run's effective TD3 settings
    (``hyperparameters.algorithm_settings("td3", ...)``); ``targets`` the members' distilled targets
    (None from scratch)."""

    algorithm = "td3"

    def __init__(self, members: int, obs_dim: int, act_dim: int, settings: dict,
                 targets: MemberTargets | None = None, device: str | th.device = "cpu"):
        import torch.nn as nn

        self.members, self.device = members, th.device(device)
        policy_kwargs = settings.get("policy_kwargs") or {}
        pi, qf = hidden_widths(policy_kwargs, "td3", [400, 300])
        act = activation_of(policy_kwargs.get("activation_fn", nn.ReLU))
        n_critics = policy_kwargs.get("n_critics", 2)
        layer_norm = bool(settings.get("layer_norm", False))  # the critics' only, as agents.td3's policy

        def critics():
            return nn.ModuleList(StackedMLP(members, [obs_dim + act_dim, *qf, 1], act, device=self.device,
                                            layer_norm=layer_norm) for _ in range(n_critics))

        self.actor = StackedMLP(members, [obs_dim, *pi, act_dim], act, th.tanh, device=self.device)
        self.critics = critics()
        self.actor_target = StackedMLP(members, [obs_dim, *pi, act_dim], act, th.tanh, device=self.device)
        self.critics_target = critics()
        self.actor_target.load_state_dict(self.actor.state_dict())
        self.critics_target.load_state_dict(self.critics.state_dict())
        optimizer_kwargs = {**(policy_kwargs.get("optimizer_kwargs") or {})}
        if self.device.type not in ("cpu", "cuda"):
            optimizer_kwargs.pop("fused", None)
        lr = float(settings["learning_rate"])
        self.actor_optimizer = th.optim.Adam(self.actor.parameters(), lr=lr, **optimizer_kwargs)
        self.critic_optimizer = th.optim.Adam(self.critics.parameters(), lr=lr, **optimizer_kwargs)
        self.gamma, self.tau = float(settings["gamma"]), float(settings["tau"])
        self.policy_noise, self.noise_clip = (float(settings["target_policy_noise"]),
                                              float(settings["target_noise_clip"]))
        self.prioritized = bool(settings.get("prioritized", True))
        self.targets = targets
        self.n_updates = 0

    # -- acting ------------------------------------------------------------------------------------
    # what ``act``'s second array holds, for the engine's message when it is not finite
    OUTPUTS = "actor's actions"

    def act(self, observations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Greedy actions ``(K, n, act_dim)`` for observations ``(K, n, obs_dim)``, twice: as the
        actions and as the outputs whose finiteness says the actor has not diverged."""
        with th.no_grad():
            actions = self.actor(th.as_tensor(observations, device=self.device)).cpu().numpy()
        return actions, actions

    # -- learning ----------------------------------------------------------------------------------
    def _tensor(self, array, shape=None) -> th.Tensor:
        t = th.as_tensor(array, device=self.device)
        return t if shape is None else t.reshape(shape)

    def td_target(self, batch: Batch, next_obs: th.Tensor, actions: th.Tensor) -> th.Tensor:
        """The one TD3 target rule, ``(K, B, 1)``: clipped double-Q with target policy
        smoothing after the sample's rewards, then the distilled mix where there is one."""
        K, B = batch.rewards.shape
        with th.no_grad():
            noise = actions.clone().data.normal_(0, self.policy_noise).clamp(-self.noise_clip, self.noise_clip)
            next_actions = (self.actor_target(next_obs) + noise).clamp(-1, 1)
            joint = th.cat([next_obs, next_actions], dim=2)
            next_q = th.min(th.cat([q(joint) for q in self.critics_target], dim=2), dim=2, keepdim=True)[0]
            target = (self._tensor(batch.rewards, (K, B, 1))
                      + (1 - self._tensor(batch.terminals, (K, B, 1))) * discount(batch, self.gamma, self.device)
                      * next_q)
            if self.targets is not None:  # (w, sigma): the first step's, at n steps too (targets.py)
                target = self.targets(batch.w, batch.sigma, target)
        return target

    def update(self, batch: Batch, delay: int) -> np.ndarray:
        """One gradient step of every member on its minibatch; returns each sample's TD
        error of the first critic ``(K, B)`` (for the priorities)."""
        K, B = batch.rewards.shape
        obs = self._tensor(batch.observations)
        actions = self._tensor(batch.actions)
        target = self.td_target(batch, self._tensor(batch.next_observations), actions)
        joint = th.cat([obs, actions], dim=2)
        current = [q(joint) for q in self.critics]
        if self.prioritized:
            weights = self._tensor(batch.weights, (K, B, 1))
            per_member = sum((weights * (q - target) ** 2).mean(dim=(1, 2)) for q in current)
        else:  # uniform replay: the mean squared error, as SB3
            per_member = sum(((q - target) ** 2).mean(dim=(1, 2)) for q in current)
        self.critic_optimizer.zero_grad()
        per_member.sum().backward()  # members' losses are independent: each gets its own gradient
        self.critic_optimizer.step()
        td_errors = (current[0] - target).detach().reshape(K, B).cpu().numpy()

        self.n_updates += 1
        if self.n_updates % delay == 0:
            actor_loss = -self.critics[0](th.cat([obs, self.actor(obs)], dim=2)).mean(dim=(1, 2))
            self.actor_optimizer.zero_grad()
            # the actor's gradients only: the first critic's parameter gradients (half of its
            # backward: the weight products) would be computed only for the next critic step to clear
            actor_loss.sum().backward(inputs=list(self.actor.parameters()))
            self.actor_optimizer.step()
            polyak_update(self.critics.parameters(), self.critics_target.parameters(), self.tau)
            polyak_update(self.actor.parameters(), self.actor_target.parameters(), self.tau)
        return td_errors

    # -- members as SB3 agents ---------------------------------------------------------------------
    def _pairs(self, agent) -> list:
        """Each stacked network beside its SB3 counterpart in an ``AutomatonTD3``."""
        policy = agent.policy
        return [(self.actor, policy.actor.mu), (self.actor_target, policy.actor_target.mu),
                *zip(self.critics, policy.critic.q_networks),
                *zip(self.critics_target, policy.critic_target.q_networks)]

    def load_member(self, k: int, agent) -> None:
        """Member ``k``'s networks from an ``AutomatonTD3`` (its actor, critics and targets)."""
        for mine, theirs in self._pairs(agent):
            mine.load_member(k, theirs)

    def store_member(self, k: int, agent) -> None:
        """Member ``k``'s networks into an ``AutomatonTD3`` of the same shape."""
        for mine, theirs in self._pairs(agent):
            mine.store_member(k, theirs)

    def modules(self) -> dict:
        return {"actor": self.actor, "actor_target": self.actor_target, "critics": self.critics,
                "critics_target": self.critics_target}

    def optimizers(self) -> dict:
        return {"actor_optimizer": self.actor_optimizer, "critic_optimizer": self.critic_optimizer}


def delay_at(schedule: tuple, step: int) -> int:
    """The actor's delay in force at ``step`` under a ``delay_schedule``."""
    for until, delay in schedule:
        if until is None or step < until:
            return delay
    return schedule[-1][1]


def delay_schedule(schedule, policy_delay) -> tuple:
    """The actor's delay schedule ``((until_step, delay), ..., (None, delay))`` from a run's
    ``delay_schedule`` or a constant ``policy_delay`` (default: ``TD3_DELAY_SCHEDULE``)."""
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
