"""Grid worlds: one environment class for every task spec and grid size."""

from __future__ import annotations

import gymnasium as gym
import numpy as np

from ..rendering.grid import TILE, draw_grid, grid_text
from ..rendering.panel import PANEL_HEIGHT, add_status_panel
from ..spec import TaskSpec
from .base import CraftWorld
from .cells import ACTION_NAMES, EMPTY, MOVES, WALL


def layout_kwargs(layout_seed: int | None) -> dict:
    """``gymnasium.make`` keywords for grid instance ``layout_seed`` ({} for a new layout
    every episode); raises ValueError for anything but None or an integer >= 0."""
    if layout_seed is None:
        return {}
    if not isinstance(layout_seed, int) or isinstance(layout_seed, bool) or layout_seed < 0:
        raise ValueError(f"layout_seed must be a non-negative integer or None, got {layout_seed!r}")
    return {"layout_seed": layout_seed}


class GridWorldEnv(CraftWorld):
    """A CraftSuite task on a square grid, with its LTLf objective tracked as a DFA.

    ## Description
    The agent walks on a ``size`` x ``size`` grid. Items (wood, key, gold, ...) are picked
    up by stepping on their tile, places (factory, home, chest, dragon) act when the agent
    enters them; what they do comes from the task spec in ``tasks/`` (see
    ``craftsuite.spec``). Each step is labelled with the task's atomic propositions and the
    objective's automaton advances on that label. The layout is drawn anew from the seed
    given to ``reset``.

    ## Action Space
    ``Discrete(4)``: 0 up, 1 right, 2 down, 3 left. Moving into the border or an obstacle
    leaves the agent where it is.

    ## Observation Space
    ``Box(0, 1, (C*size*size + n_inventory,), float32)``: one binary plane per channel
    (agent, obstacle, then one per object kind in spec order), row-major, followed by the
    inventory counts divided by their largest possible value. ``observation_layout``
    describes the slices; reshape the first part to ``(C, size, size)`` for a CNN. With
    ``product=True`` (``gymnasium.make`` keyword) the automaton state's one-hot follows.

    ## Rewards
    From the spec: the step reward (-0.1) every step, each item's reward on pickup (+1 by
    default, 0 for iron), and the completion reward (+100) when the automaton accepts.

    ## Starting State
    Objects, then the agent, on distinct random free cells ("corner" places on the
    top-left cell); empty inventory; the automaton in its initial state. With
    ``layout_seed=K`` (``gymnasium.make`` keyword) the objects are the same in every
    episode (one fixed instance, as the paper's teachers and students had) and only the
    agent's start is drawn from the episode's seed.

    ## Episode End
    Terminated when the automaton accepts (``info["is_success"]``) or falls into its
    rejecting sink (``info["violation"]``: the objective can no longer be met; no
    completion reward). Truncated at the spec's ``grid.max_steps`` (TimeLimit).

    ## Info
    ``labels`` (names of the true propositions), ``label_mask`` (their bitmask, bit i =
    ``automaton.propositions[i]``), ``automaton_state`` (after the step),
    ``automaton_transition`` ``(w, sigma, w')``, ``is_success``, ``violation``.

    ## Rendering
    ``rgb_array``: the grid alone, ``(32*size, 32*size, 3)`` uint8 (32-pixel tiles;
    ``frame_shape`` says it). With ``status_panel=True`` (``gymnasium.make`` keyword, for
    videos people watch) a 40-row strip with the inventory and the automaton state is added
    below, ``(32*size + 40, 32*size, 3)``; it is off by default because a frame showing the
    automaton state would hand it to an agent that learns from pixels. ``ansi``: one line
    of text per grid row, plus a line with the inventory and automaton state when
    ``status_panel=True``.

    ## Registered Configurations
    ``CraftSuite/<Task>-Grid<size>-v0`` for every spec in ``tasks/`` and each of its grid
    sizes (every built-in task, BlindCraftsmanObstacles included: 7 and 10).
    ``craftsuite tasks`` lists them.
    """

    metadata = {"render_modes": ["rgb_array", "ansi"], "render_fps": 8}

    def __init__(self, task: str | TaskSpec = "BlindCraftsman", size: int = 7,
                 render_mode: str | None = None, layout_seed: int | None = None,
                 status_panel: bool = False):
        super().__init__(task, render_mode, status_panel)
        layout_kwargs(layout_seed)  # validates
        self.layout_seed = layout_seed
        if not isinstance(size, int) or size < 2:
            raise ValueError(f"size must be an integer >= 2, got {size!r}")
        self.size = size
        spec = self.task
        self._objects = spec.objects
        self.obstacles = sorted({y * size + x for x, y in spec.grid.obstacles})
        n_cells = size * size
        free = n_cells - len(self.obstacles) - 1
        n_objects = sum(o.count for o in self._objects)
        if n_objects > free:
            raise ValueError(f"{spec.name}: {n_objects} objects do not fit a {size}x{size} grid")
        if any(not (0 <= x < size and 0 <= y < size) for x, y in spec.grid.obstacles):
            raise ValueError(f"{spec.name}: obstacles {spec.grid.obstacles} lie outside a {size}x{size} grid")

        self._n_channels = 2 + len(self._objects)
        self.inv_offset = self._n_channels * n_cells
        n_obs = self.inv_offset + len(self.rules.inventory_names)
        self.observation_space = gym.spaces.Box(0.0, 1.0, (n_obs,), dtype=np.float32)
        self.action_space = gym.spaces.Discrete(4)
        self.inv_scale = self.rules.scale
        self._step_reward = spec.step_reward
        self._cells: list[int] = []
        self._obs = np.zeros(n_obs, dtype=np.float32)
        self._agent = 0

    # -- public views --------------------------------------------------------------------------
    @property
    def observation_layout(self) -> dict:
        """Where things are in the observation vector."""
        return {
            "planes": (self._n_channels, self.size, self.size),
            "plane_names": ("agent", "obstacle") + tuple(o.name for o in self._objects),
            "inventory": slice(self.inv_offset, self.inv_offset + len(self.inventory_counts)),
            "inventory_names": self.rules.inventory_names,
            "inventory_scale": tuple(self.inv_scale),
        }

    @property
    def frame_shape(self) -> tuple[int, int, int]:
        """Shape of an ``rgb_array`` frame: ``(rows, columns, 3)``."""
        side = self.size * TILE
        return (side + (PANEL_HEIGHT if self.status_panel else 0), side, 3)

    @property
    def agent_position(self) -> tuple[int, int]:
        y, x = divmod(self._agent, self.size)
        return x, y

    @property
    def cells(self) -> tuple[int, ...]:
        """What each cell holds now, row-major (cell ``y * size + x``): an object kind (an
        index into ``task.objects``), ``envs.cells.EMPTY`` or ``envs.cells.WALL``."""
        return tuple(self._cells)

    def remaining_counts(self) -> list[int]:
        """Objects of each kind still on the map (places are never used up)."""
        counts = [0] * len(self._objects)
        for kind in self._cells:
            if kind >= 0:
                counts[kind] += 1
        return counts

    def object_positions(self) -> dict[str, list[tuple[int, int]]]:
        """Cells ``(x, y)`` of the objects still on the map, by object name."""
        out: dict[str, list[tuple[int, int]]] = {o.name: [] for o in self._objects}
        for cell, kind in enumerate(self._cells):
            if kind >= 0:
                y, x = divmod(cell, self.size)
                out[self._objects[kind].name].append((x, y))
        return out

    # -- gymnasium API -----------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        n_cells = self.size * self.size
        cells = [EMPTY] * n_cells
        for c in self.obstacles:
            cells[c] = WALL
        corner = [k for k, o in enumerate(self._objects) if getattr(o, "placement", "") == "corner"]
        for k in corner:
            cells[0] = k
        free = [c for c in range(n_cells) if cells[c] == EMPTY]
        # a fixed instance draws its objects from layout_seed, the agent's start from the episode
        layout_rng = np.random.default_rng(self.layout_seed) if self.layout_seed is not None else self.np_random
        order = layout_rng.permutation(len(free)).tolist()
        i = 0
        for k, obj in enumerate(self._objects):
            if k in corner:
                continue
            for _ in range(obj.count):
                cells[free[order[i]]] = k
                i += 1
        if self.layout_seed is None:
            self._agent = free[order[i]]
        else:
            empty = [c for c in free if cells[c] == EMPTY]
            self._agent = empty[int(self.np_random.integers(len(empty)))]
        self._cells = cells

        obs = self._obs
        obs[:] = 0.0
        obs[self._agent] = 1.0
        for c in self.obstacles:
            obs[n_cells + c] = 1.0
        for c, k in enumerate(cells):
            if k >= 0:
                obs[(2 + k) * n_cells + c] = 1.0
        self.inventory_counts = self.rules.new_inventory()
        self._level_mask = self.labeller.levels(self.inventory_counts)
        return obs.copy(), self.tracker.reset()

    def step(self, action):
        try:
            dx, dy = MOVES[action]
        except (KeyError, TypeError):
            # a 0-d integer array (what SB3's predict returns) is a valid Discrete action
            if isinstance(action, np.ndarray) and action.shape == () and action.dtype.kind in "iu" \
                    and int(action) in MOVES:
                dx, dy = MOVES[int(action)]
            else:
                raise ValueError(
                    f"invalid action {action!r} for {self.task.name}: expected an integer in [0, 4) "
                    f"({', '.join(f'{i} {n}' for i, n in enumerate(ACTION_NAMES))})"
                ) from None
        if not self._cells:
            raise RuntimeError("call reset() before step()")
        size = self.size
        y, x = divmod(self._agent, size)
        nx, ny = x + dx, y + dy
        moved = False
        obs = self._obs
        if 0 <= nx < size and 0 <= ny < size:
            cell = ny * size + nx
            if self._cells[cell] != WALL:
                obs[self._agent] = 0.0
                obs[cell] = 1.0
                self._agent = cell
                moved = True

        reward = self._step_reward
        mask = self._level_mask
        kind = self._cells[self._agent]
        if kind >= 0:
            inv = self.inventory_counts
            outcome = self.rules.touch(inv, kind, moved)
            arrived = kind if moved and kind >= self.rules.n_items else -1
            if outcome is not None:
                reward += outcome.reward
                if outcome.consumed:
                    self._cells[self._agent] = EMPTY
                    obs[(2 + kind) * size * size + self._agent] = 0.0
                off, scale = self.inv_offset, self.inv_scale
                for s, count in enumerate(inv):
                    obs[off + s] = count / scale[s]
                self._level_mask = self.labeller.levels(inv)
                mask = self.labeller(inv, outcome.gained, arrived)
            elif arrived >= 0:
                mask = self.labeller(inv, 0, arrived)

        bonus, done, info = self.tracker.advance(mask)
        return obs.copy(), reward + bonus, done, False, info

    def render(self):
        if not self._can_render(bool(self._cells)):
            return None
        if self.render_mode == "ansi":
            text = grid_text(self.size, self._cells, self._agent, self._objects)
            if not self.status_panel:
                return f"{text}\n"
            held = ", ".join(f"{k} {v}" for k, v in self.inventory.items() if v) or "nothing"
            return f"{text}\ninventory: {held}; automaton state {self.automaton_state}\n"
        frame = draw_grid(self.size, self._cells, self._agent, self._objects, self.rules.is_place)
        return add_status_panel(frame, self) if self.status_panel else frame
