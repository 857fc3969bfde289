"""What ``AutomatonDQN`` and ``AutomatonTD3`` add to SB3's algorithm classes alike."""

from __future__ import annotations

import warnings

from .replay import AutomatonReplayBuffer

RETIRED = ("{cls} holds a CraftSuite model and does not learn: CraftSuite's learning rules live "
           "in the population engine; train with craftsuite.population.train_population (or `craftsuite "
           "student`), or load the model (not CRM models) with SB3's own class to train it with SB3's rule")


class AutomatonAlgorithm:
    """Mixin of ``AutomatonDQN`` and ``AutomatonTD3`` (before SB3's class). They hold what
    the population engine trained, saved as SB3 zips: each learning rule has one
    implementation, the engine's, so ``learn`` and ``train`` refuse and name it. SB3's
    ``n_steps`` attribute is the one setting of n-step returns, and the
    ``AutomatonReplayBuffer`` reads it from its keywords (``replay_buffer_kwargs``);
    ``n_updates`` is the public count of the gradient updates taken."""

    def _setup_model(self) -> None:
        with warnings.catch_warnings():
            if isinstance(self.replay_buffer_class, type) and issubclass(self.replay_buffer_class,
                                                                          AutomatonReplayBuffer):
                # SB3 warns that n_steps is ignored with a buffer class of one's own; ours takes it
                warnings.filterwarnings("ignore", message=r"`n_steps=\d+` is ignored")
            super()._setup_model()

    def learn(self, *args, **kwargs):
        raise RuntimeError(RETIRED.format(cls=type(self).__name__))

    def train(self, *args, **kwargs) -> None:
        raise RuntimeError(RETIRED.format(cls=type(self).__name__))

    @property
    def n_updates(self) -> int:
        """The gradient updates taken so far (SB3 counts them in a private attribute)."""
        return self._n_updates

    @n_updates.setter
    def n_updates(self, value: int) -> None:
        self._n_updates = int(value)
