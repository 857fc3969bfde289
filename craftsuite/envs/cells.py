"""What a grid cell holds and how the grid agent moves: the grid world's own vocabulary.

A grid's cells are a row-major list of ints: an object kind (``>= 0``, an index into the
task spec's objects) or one of the codes below. Drawing, the scripted policy and the
world itself all read these; they are defined here, with the world, and nowhere else.
"""

from __future__ import annotations

EMPTY = -1  # nothing on the cell
WALL = -2  # an obstacle: the agent cannot enter it

# action -> (dx, dy); y grows downwards (row 0 is the top row)
MOVES = {0: (0, -1), 1: (1, 0), 2: (0, 1), 3: (-1, 0)}
ACTION_NAMES = ("up", "right", "down", "left")
