"""Agents and automaton distillation on top of stable-baselines3."""

from .distillation import (AutomatonQTable, DistillationError, DistilledTarget, dynamic_distillation,
                           static_distillation)
from .replay import AutomatonReplayBuffer, AutomatonSamples

__all__ = [
    "AutomatonQTable", "AutomatonReplayBuffer", "AutomatonSamples", "DistillationError",
    "DistilledTarget", "dynamic_distillation", "static_distillation",
]
