"""td3_reach.py with the agent's velocity zeroed in the observation.

Usage: python experiments/blind-craftsman-500k/no_velocity.py [td3_reach.py's arguments]

At frame skip 10 the velocity is nearly the last action, a way for a limit cycle to feed
itself; this runs ``td3_reach.main()`` (its usual arguments, e.g. ``--scenes craftsman
--frame-skips 10 --noises persistent --resample 0.1 --seeds 0 1 2 3 --steps 20000``)
with the MuJoCo world's observation wrapped so that its velocity entries read 0
(``WithoutVelocity``, made by the task's MuJoCo id: for training and evaluation alike).
The workers find the wrapper in this script, which they inherit by fork (Linux's default
start method).
"""

from __future__ import annotations

import _tools  # noqa: F401  (td3_reach lives with the calibration experiment)
import gymnasium as gym


class WithoutVelocity(gym.ObservationWrapper):
    """The MuJoCo world's observation with the agent's velocity (``agent_velocity``) at 0."""

    def __init__(self, env: gym.Env):
        super().__init__(env)
        self.velocity = env.unwrapped.observation_layout["agent_velocity"]

    def observation(self, observation):
        observation[self.velocity] = 0.0  # the world hands out a copy of its buffer
        return observation


def make_without_velocity(**kwargs) -> gym.Env:
    """The MuJoCo ids' entry point (the same keywords), its world wrapped in ``WithoutVelocity``."""
    from craftsuite.registration import make_continuous

    return WithoutVelocity(make_continuous(**kwargs))


def main() -> None:
    import td3_reach

    td3_reach.main(entry_point=f"{__name__}:make_without_velocity")


if __name__ == "__main__":
    main()
