"""Drawing a grid world: RGB frames and ANSI text.

The cell codes (``EMPTY``, ``WALL``) belong to the world (``craftsuite.envs.cells``).
"""

from __future__ import annotations

import cv2
import numpy as np

from ..envs.cells import EMPTY, WALL
from .panel import hex_to_rgb

TILE = 32  # pixels per cell side: a grid of size n draws as an (n*TILE, n*TILE, 3) frame
_FONT = cv2.FONT_HERSHEY_SIMPLEX


def _text_color(rgb) -> tuple[int, int, int]:
    return (0, 0, 0) if sum(rgb) > 380 else (255, 255, 255)


def draw_grid(size: int, cells: list[int], agent: int, objects, is_place) -> np.ndarray:
    """RGB frame of the grid alone, ``(size*TILE, size*TILE, 3)``: tiles, objects (items as
    discs, places as squares) and the agent.

    Args:
        cells: kind per cell (row-major), EMPTY or WALL.
        agent: the agent's cell.
        objects: spec objects by kind (colour and symbol).
        is_place: kind -> bool.
    """
    px = size * TILE
    img = np.full((px, px, 3), 235, dtype=np.uint8)
    img[::TILE, :] = 200
    img[:, ::TILE] = 200
    for cell, kind in enumerate(cells):
        y, x = divmod(cell, size)
        x0, y0 = x * TILE, y * TILE
        if kind == WALL:
            cv2.rectangle(img, (x0, y0), (x0 + TILE - 1, y0 + TILE - 1), (60, 90, 150), -1)
            continue
        if kind == EMPTY:
            continue
        obj = objects[kind]
        rgb = hex_to_rgb(obj.color)
        if is_place(kind):
            cv2.rectangle(img, (x0 + 2, y0 + 2), (x0 + TILE - 3, y0 + TILE - 3), rgb, -1)
        else:
            cv2.circle(img, (x0 + TILE // 2, y0 + TILE // 2), TILE // 2 - 5, rgb, -1, cv2.LINE_AA)
        cv2.putText(img, obj.symbol, (x0 + TILE // 2 - 5, y0 + TILE // 2 + 5), _FONT, 0.45,
                    _text_color(rgb), 1, cv2.LINE_AA)
    y, x = divmod(agent, size)
    x0, y0 = x * TILE, y * TILE
    cv2.rectangle(img, (x0 + 7, y0 + 7), (x0 + TILE - 8, y0 + TILE - 8), (20, 20, 20), -1)
    cv2.rectangle(img, (x0 + 7, y0 + 7), (x0 + TILE - 8, y0 + TILE - 8), (255, 255, 255), 2)
    return img


def grid_text(size: int, cells: list[int], agent: int, objects) -> str:
    """One character per cell: '@' agent, '#' wall, '.' empty, else the object's symbol."""
    rows = []
    for y in range(size):
        row = []
        for x in range(size):
            cell = y * size + x
            kind = cells[cell]
            row.append("@" if cell == agent else "#" if kind == WALL else
                       "." if kind == EMPTY else objects[kind].symbol)
        rows.append(" ".join(row))
    return "\n".join(rows)
