"""td3_reach.py with the agent's velocity zeroed in the observation.

Usage: python experiments/blind-craftsman-500k/no_velocity.py [td3_reach.py's arguments]

At frame skip 10 the velocity is nearly the last action, a way for a limit cycle to feed
itself; this runs ``td3_reach.main()`` (its usual arguments, e.g. ``--scenes craftsman
--frame-skips 10 --noises persistent --resample 0.1 --seeds 0 1 2 3 --steps 20000``)
with the MuJoCo world's observation patched so that its velocity entries read 0. The
workers inherit the patch by fork (Linux's default start method).
"""

from __future__ import annotations

import _tools  # noqa: F401  (td3_reach lives with the calibration experiment)

VELOCITY = slice(2, 4)  # the observation's agent velocity, after its position


def patch_out_velocity() -> None:
    from craftsuite.envs.continuous import ContinuousWorldEnv

    write = ContinuousWorldEnv._write_observation

    def without_velocity(self, offsets):
        write(self, offsets)
        self._obs[VELOCITY] = 0.0

    ContinuousWorldEnv._write_observation = without_velocity


def main() -> None:
    import td3_reach

    patch_out_velocity()
    td3_reach.main()


if __name__ == "__main__":
    main()
