"""The status strip a world can draw under its frames: inventory and automaton state.

Worlds draw it only when asked (``status_panel=True``, for videos people watch): a frame
that shows the automaton state would hand it to an agent that learns from pixels.
"""

from __future__ import annotations

import cv2
import numpy as np

_FONT = cv2.FONT_HERSHEY_SIMPLEX
PANEL_HEIGHT = 40  # rows the strip adds under a frame


def hex_to_rgb(color: str) -> tuple[int, int, int]:
    return tuple(int(color[i:i + 2], 16) for i in (1, 3, 5))


def status_panel(width: int, inventory: dict[str, int], automaton_state: int,
                 n_states: int, flag: str = "", height: int = PANEL_HEIGHT) -> np.ndarray:
    """An RGB strip: ``name count`` for held inventory, then ``q <state>/<n>`` and a flag."""
    strip = np.full((height, width, 3), 245, dtype=np.uint8)
    held = [f"{name} {count}" for name, count in inventory.items() if count]
    text = "  ".join(held) if held else "(empty-handed)"
    scale = 0.4 if width >= 200 else 0.3
    cv2.putText(strip, text, (4, 15), _FONT, scale, (30, 30, 30), 1, cv2.LINE_AA)
    state = f"automaton q{automaton_state}/{n_states}" + (f"  {flag}" if flag else "")
    color = {"accepted": (20, 130, 40), "violated": (190, 30, 30)}.get(flag, (30, 30, 30))
    cv2.putText(strip, state, (4, 33), _FONT, scale, color, 1, cv2.LINE_AA)
    return strip


def add_status_panel(frame: np.ndarray, world) -> np.ndarray:
    """``frame`` with ``world``'s status strip (a CraftSuite world: inventory, automaton
    state and its flag) under it: ``PANEL_HEIGHT`` more rows, as wide as the frame."""
    strip = status_panel(frame.shape[1], world.inventory, world.automaton_state,
                         world.automaton.n_states, world.tracker.flag)
    return np.concatenate([frame, strip], axis=0)
