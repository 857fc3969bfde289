"""The residual CNN of the paper's grid students for K members at once.

``StackedResidualCNN`` computes, for each member, what ``agents.networks.ResidualCNN``
computes for one: the grid's planes ``(C, H, W)`` through a 3x3 convolution and residual
blocks of two 3x3 convolutions (batch norm, leaky ReLU), flattened, with the rest of the
observation appended. The members' convolutions run as one grouped convolution (``groups
= K``: member k's filters read only member k's planes), and its batch norm normalises each
member's channels over that member's own minibatch, so each member moves as its own network
would. Every parameter and statistic keeps a leading member axis, as ``StackedMLP``'s do,
so a member's checkpoint and optimizer moments are one index.

``StackedQNetwork`` is features, then a ``StackedMLP`` head: what SB3's ``QNetwork`` is for
one member.
"""

from __future__ import annotations

import math

import torch as th
import torch.nn.functional as F
from torch import nn

from .nets import StackedMLP

BN_EPS, BN_MOMENTUM, LEAKY_SLOPE = 1e-5, 0.1, 0.01  # nn.BatchNorm2d's and nn.LeakyReLU's defaults


class StackedResidualCNN(nn.Module):
    """K residual CNNs over the first ``C * H * W`` entries of ``(K, B, D)`` observations;
    the other ``D - C * H * W`` entries pass through. Its output is ``(K, B, features_dim)``.

    In training mode the batch norms read their minibatch's statistics and move their
    running ones (momentum 0.1), in evaluation mode they read the running ones, as
    ``nn.BatchNorm2d`` does."""

    def __init__(self, members: int, obs_dim: int, planes: tuple[int, int, int], filters: int = 32,
                 blocks: int = 3, device=None):
        super().__init__()
        channels, height, width = planes
        self.members, self.planes, self.filters = members, tuple(planes), filters
        self.n_plane = channels * height * width
        rest = obs_dim - self.n_plane
        if rest < 0:
            raise ValueError(f"residual-cnn: planes {tuple(planes)} need {self.n_plane} observation entries, "
                             f"the observation has {obs_dim}")
        self.features_dim = filters * height * width + rest
        self.conv_weights, self.conv_biases = nn.ParameterList(), nn.ParameterList()
        self.bn_weights, self.bn_biases = nn.ParameterList(), nn.ParameterList()
        for i in range(1 + 2 * blocks):
            fan_in = (channels if i == 0 else filters) * 9
            bound = 1 / math.sqrt(fan_in)  # nn.Conv2d's default: kaiming_uniform(a=sqrt(5)) and its bias bound
            shape = (members, filters, channels if i == 0 else filters, 3, 3)
            self.conv_weights.append(nn.Parameter(th.empty(shape, device=device).uniform_(-bound, bound)))
            self.conv_biases.append(nn.Parameter(th.empty(members, filters, device=device).uniform_(-bound, bound)))
            self.bn_weights.append(nn.Parameter(th.ones(members, filters, device=device)))
            self.bn_biases.append(nn.Parameter(th.zeros(members, filters, device=device)))
            self.register_buffer(f"running_mean_{i}", th.zeros(members, filters, device=device))
            self.register_buffer(f"running_var_{i}", th.ones(members, filters, device=device))
        self.blocks = blocks

    def _layer(self, i: int, x: th.Tensor) -> th.Tensor:
        """Convolution ``i`` and its batch norm over ``x`` ``(B, K * channels, H, W)``."""
        w = self.conv_weights[i]
        x = F.conv2d(x, w.reshape(-1, *w.shape[2:]), self.conv_biases[i].reshape(-1), padding=1,
                     groups=self.members)
        # the running statistics are views of the (K, filters) buffers: batch_norm moves them in place
        return F.batch_norm(x, getattr(self, f"running_mean_{i}").view(-1), getattr(self, f"running_var_{i}").view(-1),
                            self.bn_weights[i].reshape(-1), self.bn_biases[i].reshape(-1), self.training,
                            BN_MOMENTUM, BN_EPS)

    def forward(self, observations: th.Tensor) -> th.Tensor:
        K, B, _ = observations.shape
        channels, height, width = self.planes
        grid = observations[..., :self.n_plane].reshape(K, B, channels, height, width)
        x = grid.transpose(0, 1).reshape(B, K * channels, height, width)
        x = F.leaky_relu(self._layer(0, x), LEAKY_SLOPE)
        for b in range(self.blocks):
            inner = F.leaky_relu(self._layer(1 + 2 * b, x), LEAKY_SLOPE)
            x = F.leaky_relu(x + self._layer(2 + 2 * b, inner), LEAKY_SLOPE)
        maps = x.reshape(B, K, -1).transpose(0, 1)  # member k's maps flattened as nn.Flatten does
        return th.cat([maps, observations[..., self.n_plane:]], dim=-1)

    def drop_bias_gradients(self) -> None:
        """Zero the convolutions' bias gradients. Each convolution feeds a batch norm, which
        subtracts its channels' mean: a bias there has no gradient but rounding noise, which
        Adam would scale to steps of about the learning rate in random directions (SB3's
        network drifts so). Held fixed, it computes the same, and the same on every machine."""
        for bias in self.conv_biases:
            if bias.grad is not None:
                bias.grad.zero_()

    def running_stats(self) -> list[th.Tensor]:
        """The batch norms' running means and variances (a target network copies them)."""
        return [b for name, b in self.named_buffers() if name.startswith("running_")]

    # -- members as SB3 modules --------------------------------------------------------------
    def _modules_of(self, extractor: nn.Module) -> list[tuple[nn.Conv2d, nn.BatchNorm2d]]:
        convs = [m for m in extractor.modules() if isinstance(m, nn.Conv2d)]
        norms = [m for m in extractor.modules() if isinstance(m, nn.BatchNorm2d)]
        if len(convs) != len(self.conv_weights) or len(norms) != len(convs) \
                or any(c.weight.shape != w.shape[1:] for c, w in zip(convs, self.conv_weights)):
            raise ValueError(f"{type(extractor).__name__} is not a member of a population of residual CNNs with "
                             f"{self.blocks} blocks of {self.filters} filters over planes {self.planes}")
        return list(zip(convs, norms))

    def load_member(self, k: int, extractor: nn.Module) -> None:
        """Member ``k``'s weights and running statistics from an SB3 ``ResidualCNN``."""
        with th.no_grad():
            for i, (conv, norm) in enumerate(self._modules_of(extractor)):
                self.conv_weights[i][k].copy_(conv.weight)
                self.conv_biases[i][k].copy_(conv.bias)
                self.bn_weights[i][k].copy_(norm.weight)
                self.bn_biases[i][k].copy_(norm.bias)
                getattr(self, f"running_mean_{i}")[k].copy_(norm.running_mean)
                getattr(self, f"running_var_{i}")[k].copy_(norm.running_var)

    def store_member(self, k: int, extractor: nn.Module) -> None:
        """Member ``k``'s weights and running statistics into an SB3 ``ResidualCNN``."""
        with th.no_grad():
            for i, (conv, norm) in enumerate(self._modules_of(extractor)):
                conv.weight.copy_(self.conv_weights[i][k])
                conv.bias.copy_(self.conv_biases[i][k])
                norm.weight.copy_(self.bn_weights[i][k])
                norm.bias.copy_(self.bn_biases[i][k])
                norm.running_mean.copy_(getattr(self, f"running_mean_{i}")[k])
                norm.running_var.copy_(getattr(self, f"running_var_{i}")[k])


class StackedQNetwork(nn.Module):
    """K Q-networks: ``features`` (a ``StackedResidualCNN``), then ``head`` (a ``StackedMLP``)."""

    def __init__(self, features: StackedResidualCNN, head: StackedMLP):
        super().__init__()
        self.features, self.head = features, head

    def forward(self, observations: th.Tensor) -> th.Tensor:
        return self.head(self.features(observations))
