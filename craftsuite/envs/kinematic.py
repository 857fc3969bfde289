"""The kinematic world: the authors' continuous toy (no physics, no MuJoCo), the same tasks,
rules, labels and automaton as the grids and the MuJoCo world.

The step follows the authors' discrete/lib/env/mineworldenv.py (``MineWorldEnvContinuous.step``,
repository adenm-10/Automaton_Distillation): the
position moves by ``3.0 * action`` on a 7 x 7 board ``[0, 7) x [0, 7)``; a move that would
leave the board is rejected (the agent stays, -0.1) and touches nothing; objects within 0.4
(strictly) of the new position are touched; objects sit on the board's integer points
except (0, 0) and the agent starts anywhere on the board. This module must not import
MuJoCo (nor dm_control): it is the continuous world for machines without it.
"""

from __future__ import annotations

import cv2
import numpy as np

from ..rendering.frames import frame_side
from ..rendering.panel import add_status_panel, hex_to_rgb
from ..spec import KINEMATIC, TaskSpec
from .planar import PlanarWorld, obstacle_boxes, within_boxes

# The authors' values (``spec.KinematicConfig``); the board side, pickup radius and
# off-board penalty are the spec's ``[continuous]`` values, which equal theirs (7, 0.4, -0.1).
STEP = KINEMATIC.step
MAX_STEPS = KINEMATIC.max_steps


class KinematicWorldEnv(PlanarWorld):
    """A CraftSuite task on the authors' kinematic board.

    ## Description
    A point agent on a square board ``[0, arena) x [0, arena)`` (7 x 7, the spec's
    ``continuous.arena``). Each action moves it by ``STEP`` (3.0) times the action, at once:
    no velocity, no inertia. A move whose end leaves the board (or, in obstacle variants,
    ends in an obstacle) is rejected: the agent stays and nothing is touched. After an
    accepted move, every object within ``pickup_radius`` (0.4, strictly less) of the agent
    is touched through the task's rules: items are picked up when the rules allow, places
    act on entering their zone.

    ## Action Space
    ``Box(-1, 1, (2,), float32)``: displacement along x and y over ``STEP``. Out-of-range
    values are clipped; NaN, infinite or wrongly shaped actions raise ``ValueError``.

    ## Observation Space
    ``Box(-1, 1, (2 + 3 * n_objects + n_inventory,), float32)``: the agent position mapped
    to [-1, 1); per object slot (spec order) its position relative to the agent divided by
    the board side and a present flag (0 once consumed, its offset then 0); inventory counts
    divided by their largest possible value. ``observation_layout`` gives the slices; the
    MuJoCo world's layout without the velocity. With ``product=True`` the automaton state's
    one-hot follows.

    ## Rewards
    The spec's step reward, item rewards, the completion reward on acceptance, and
    ``continuous.boundary_reward`` (-0.1) on a rejected move.

    ## Starting State
    Objects on distinct integer points of the board other than (0, 0) (and outside
    obstacles); the agent uniformly anywhere on the board outside obstacles.

    ## Episode End
    Terminated on acceptance (``is_success``) or violation; truncated at ``MAX_STEPS``
    (1000) steps by TimeLimit.

    ## Rendering
    ``rgb_array``: a top-down drawing of the board, ``(height, width, 3)`` uint8 (240 by
    default, each up to ``MAX_FRAME_SIDE``); ``status_panel=True`` adds the 40-row strip.

    ## Registered Configurations
    ``CraftSuite/<Task>-Kinematic-v0`` for every task.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 8}

    def __init__(self, task: str | TaskSpec = "BlindCraftsman", render_mode: str | None = None,
                 width: int = 240, height: int = 240, status_panel: bool = False):
        self.width, self.height = frame_side("width", width), frame_side("height", height)
        super().__init__(task, render_mode, status_panel)
        spec = self.task
        cfg = spec.continuous
        self.arena = float(cfg.arena)
        self.half = self.arena / 2
        self.radius = float(cfg.pickup_radius)
        self.step_size = STEP
        self._lay_out([kind for kind, obj in enumerate(spec.objects) for _ in range(obj.count)])
        n_obj = len(self._kinds)
        # the MuJoCo scene's boxes, moved from its centre origin to the board's corner
        self._obstacles = np.array(obstacle_boxes(spec), dtype=float).reshape(-1, 3) + [self.half, self.half, 0.0]
        # the authors' object sites: the board's integer points but (0, 0), here also clear
        # of obstacles by a pickup radius (so no object hides in a wall)
        axis = np.arange(int(np.ceil(self.arena)), dtype=float)
        sites = np.array([(x, y) for x in axis for y in axis if (x, y) != (0.0, 0.0)])
        self._sites = sites[~self._in_obstacle(sites, self.radius)]
        if len(self._sites) < n_obj:
            raise ValueError(f"{spec.name}: {n_obj} objects do not fit the kinematic board's "
                             f"{len(self._sites)} free integer points (arena {self.arena})")
        self._position = np.zeros(2)
        self._level_mask = 0

    def _in_obstacle(self, points: np.ndarray, margin: float = 0.0) -> np.ndarray:
        return within_boxes(points, self._obstacles, margin)

    def on_board(self, point) -> bool:
        """Whether the agent may stand at ``point``: on the half-open board (the authors'
        bounds, ``0 <= x < arena``), outside obstacles."""
        x, y = float(point[0]), float(point[1])
        return 0.0 <= x < self.arena and 0.0 <= y < self.arena and not self._in_obstacle(np.array([x, y]))[0]

    # -- public views --------------------------------------------------------------------------
    @property
    def agent_position(self) -> np.ndarray:
        """Board coordinates, ``[0, arena)`` on each axis."""
        return self._position.copy()

    # -- episodes ----------------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        rng = self.np_random
        n_obj = len(self._kinds)
        self._positions = self._sites[rng.permutation(len(self._sites))[:n_obj]].copy()
        for _ in range(1000):
            start = rng.uniform(0.0, self.arena, 2)
            if self.on_board(start):
                break
        else:  # a board (nearly) all obstacle: no spec shipped is one
            raise RuntimeError(f"{self.task.name}: no free start position on the kinematic board")
        self._position = start
        self._present[:] = True
        self._inside[:] = False
        self.inventory_counts = self.rules.new_inventory()
        self._level_mask = self.labeller.levels(self.inventory_counts)
        self._started = True
        self._obs[:] = 0.0
        self._write_observation()
        return self._obs.copy(), self.tracker.reset()

    def _write_observation(self):
        obs, n_obj = self._obs, len(self._kinds)
        obs[0:2] = self._position / self.half - 1.0
        view = obs[2:2 + 3 * n_obj].reshape(n_obj, 3)
        view[:, :2] = np.where(self._present[:, None], (self._positions - self._position) / self.arena, 0.0)
        view[:, 2] = self._present
        self._write_inventory()

    def step(self, action):
        x, y = self.planar_action(action, "displacement")
        target = self._position + self.step_size * np.array([x, y])
        reward = self._step_reward
        mask = self._level_mask
        if self.on_board(target):
            self._position = target
            offsets = self._positions - target
            inside = self._present & (np.einsum("ij,ij->i", offsets, offsets) < self.radius ** 2)
            if inside.any() or self._inside.any():
                mask, reward = self._touch(inside, mask, reward)
            self._inside = inside
        else:  # the authors reject the whole move: the agent stays and touches nothing
            reward += self._boundary_reward
        self._write_observation()
        bonus, done, info = self.tracker.advance(mask)
        return self._obs.copy(), reward + bonus, done, False, info

    # -- rendering -----------------------------------------------------------------------------------
    def world_to_pixel(self, x: float, y: float) -> tuple[int, int]:
        """(column, row) of a board point in the frame (y up, the board filling the frame)."""
        return int(x / self.arena * self.width), int((1.0 - y / self.arena) * self.height)

    def render(self):
        if not self._can_render(bool(self._started)):
            return None
        frame = np.full((self.height, self.width, 3), 235, dtype=np.uint8)
        sx, sy = self.width / self.arena, self.height / self.arena
        for x, y, h in self._obstacles:
            c0, r0 = self.world_to_pixel(x - h, y + h)
            c1, r1 = self.world_to_pixel(x + h, y - h)
            cv2.rectangle(frame, (c0, r0), (c1, r1), (61, 89, 150), -1)
        objects = self.task.objects
        for i, kind in enumerate(self._kinds):
            if not self._present[i]:
                continue
            col, row = self.world_to_pixel(*self._positions[i])
            color = hex_to_rgb(objects[kind].color)
            if self._is_item[i]:  # items small discs, places their pickup zone
                cv2.circle(frame, (col, row), max(1, int(0.2 * min(sx, sy))), color, -1, cv2.LINE_AA)
            else:
                cv2.ellipse(frame, (col, row), (max(1, int(self.radius * sx)), max(1, int(self.radius * sy))),
                            0, 0, 360, color, -1, cv2.LINE_AA)
        col, row = self.world_to_pixel(*self._position)
        cv2.circle(frame, (col, row), max(1, int(0.15 * min(sx, sy))), (20, 20, 20), -1, cv2.LINE_AA)
        return add_status_panel(frame, self) if self.status_panel else frame
