"""Agents as saved (SB3 classes that load and act) and automaton distillation; their
training is the population engine's (``craftsuite.population``)."""

from .distillation import (AutomatonQTable, DistillationError, DistilledTarget, dynamic_distillation,
                           static_distillation)
from .replay import AutomatonReplayBuffer

__all__ = [
    "AutomatonQTable", "AutomatonReplayBuffer", "DistillationError",
    "DistilledTarget", "dynamic_distillation", "static_distillation",
]
