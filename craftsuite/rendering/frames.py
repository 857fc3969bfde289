"""Frame sizes the continuous worlds accept, checked before any drawing (MuJoCo or numpy)."""

from __future__ import annotations

import numbers

# Largest frame side: MuJoCo's off-screen framebuffer is grown to the frame asked for, and
# software GL (OSMesa) renders 8192 x 8192 but cannot allocate a 16384-pixel framebuffer.
# The kinematic world, drawn with numpy, keeps the same bound so both worlds take the same
# ``width``/``height``.
MAX_FRAME_SIDE = 8192


def frame_side(name: str, value) -> int:
    """``value`` if it is a whole number of pixels in [1, MAX_FRAME_SIDE]; else a ValueError
    naming the argument (checked before any OpenGL work, whose errors would not say so)."""
    if not isinstance(value, numbers.Integral) or isinstance(value, bool) or not 1 <= value <= MAX_FRAME_SIDE:
        raise ValueError(f"{name} must be a whole number of pixels in [1, {MAX_FRAME_SIDE}], got {value!r}")
    return int(value)
