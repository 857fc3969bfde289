"""Features extractors of the grid students, by name (a run's settings are data).

``flatten`` is SB3's default: the whole observation vector into the MLP. ``residual-cnn``
reads the grid's planes as an image, as the paper's authors' network did: a 3x3
convolution and three residual blocks of two 3x3 convolutions (32 filters, batch norm,
leaky ReLU), flattened; the rest of the vector (inventory, and the automaton state's
one-hot for product methods) joins the flattened maps before the MLP head.

``value_mlp`` is the value networks' MLP (TD3's critics, DQN's Q-network), with the
``layer_norm`` setting's LayerNorm after each hidden Linear layer when asked.
"""

from __future__ import annotations

import gymnasium as gym
import torch as th
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor, create_mlp
from torch import nn

from ..hyperparameters import DQN_CHOICES

FEATURES_EXTRACTORS = DQN_CHOICES["features_extractor"]


def value_mlp(in_dim: int, out_dim: int, net_arch: list[int], activation_fn, layer_norm: bool) -> nn.Sequential:
    """SB3's MLP ``in_dim -> net_arch -> out_dim``; with ``layer_norm``, Linear -> LayerNorm ->
    activation in each hidden layer (SB3's ``post_linear_modules``), none after the output."""
    return nn.Sequential(*create_mlp(in_dim, out_dim, net_arch, activation_fn,
                                     post_linear_modules=[nn.LayerNorm] if layer_norm else None))


class _Residual(nn.Module):
    def __init__(self, filters: int):
        super().__init__()
        self.inner = nn.Sequential(
            nn.Conv2d(filters, filters, 3, padding=1), nn.BatchNorm2d(filters), nn.LeakyReLU(),
            nn.Conv2d(filters, filters, 3, padding=1), nn.BatchNorm2d(filters))
        self.out = nn.LeakyReLU()

    def forward(self, x: th.Tensor) -> th.Tensor:
        return self.out(x + self.inner(x))


class ResidualCNN(BaseFeaturesExtractor):
    """The grid planes ``(C, H, W)`` (the first C*H*W entries of the observation, as
    ``GridWorldEnv.observation_layout`` says) through a residual convolution stack; the
    entries after them pass through unchanged."""

    def __init__(self, observation_space: gym.spaces.Box, planes: tuple[int, int, int], filters: int = 32,
                 blocks: int = 3):
        channels, height, width = planes
        self.planes, self.n_plane = tuple(planes), channels * height * width
        rest = int(observation_space.shape[0]) - self.n_plane
        if rest < 0:
            raise ValueError(f"residual-cnn: planes {tuple(planes)} need {self.n_plane} observation entries, "
                             f"the observation has {observation_space.shape[0]}")
        super().__init__(observation_space, features_dim=filters * height * width + rest)
        self.net = nn.Sequential(nn.Conv2d(channels, filters, 3, padding=1), nn.BatchNorm2d(filters), nn.LeakyReLU(),
                                 *(_Residual(filters) for _ in range(blocks)), nn.Flatten())

    def forward(self, observations: th.Tensor) -> th.Tensor:
        grid = observations[:, :self.n_plane].reshape(-1, *self.planes)
        return th.cat([self.net(grid), observations[:, self.n_plane:]], dim=1)


def features_policy_kwargs(name: str, env, policy_kwargs: dict | None) -> dict:
    """``policy_kwargs`` with the features extractor ``name`` (one of ``FEATURES_EXTRACTORS``)
    for ``env``'s world (a gymnasium env or a VecEnv); ``residual-cnn`` needs a grid world."""
    from stable_baselines3.common.vec_env import VecEnv

    policy_kwargs = dict(policy_kwargs or {})
    if name == "flatten":
        return policy_kwargs
    if name not in FEATURES_EXTRACTORS:
        raise ValueError(f"features_extractor must be one of {', '.join(FEATURES_EXTRACTORS)}, got {name!r}")
    base = env.get_attr("unwrapped", [0])[0] if isinstance(env, VecEnv) else env.unwrapped
    layout = getattr(base, "observation_layout", None)
    if not isinstance(layout, dict) or "planes" not in layout:
        raise ValueError(f"features_extractor {name!r} reads grid planes; {type(base).__name__} has none "
                         "(it is for the grid worlds)")
    policy_kwargs["features_extractor_class"] = ResidualCNN
    policy_kwargs["features_extractor_kwargs"] = {"planes": tuple(layout["planes"]),
                                                  **policy_kwargs.get("features_extractor_kwargs", {})}
    return policy_kwargs
