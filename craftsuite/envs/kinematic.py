"""The kinematic world: the authors' continuous toy (no physics, no MuJoCo), their rules.

It follows the authors' ``MineWorldEnvContinuous`` (``discrete/lib/env/mineworldenv.py``,
adenm-10/Automaton_Distillation) and the labels their training loop gives it: the position
moves by ``3.0 * action`` on a ``size`` x ``size`` board ``[0, size)^2`` (7 or 10); a move
that would leave the board is rejected (the agent stays, -0.1) and touches nothing; objects
sit on the board's integer points, a ``corner`` place at (0, 0), the others anywhere but
(0, 0); the agent starts anywhere. What touching does is the board's own rules
(``envs/tiles.py``), not the grid and MuJoCo worlds': see ``KinematicWorldEnv``. The
automaton is the task's, shared with every world. This module must not import MuJoCo (nor
dm_control): it is the continuous world for machines without it.
"""

from __future__ import annotations

import cv2
import gymnasium as gym
import numpy as np

from ..rendering.frames import frame_side
from ..rendering.panel import add_status_panel, hex_to_rgb
from ..spec import KINEMATIC_CONFIG, TaskSpec
from .tiles import BoardRules
from .planar import PlanarWorld, obstacle_boxes, within_boxes

# The authors' values (``spec.KinematicConfig``); the pickup radius and off-board penalty
# are the spec's ``[continuous]`` values, which equal theirs (0.4, -0.1).
STEP = KINEMATIC_CONFIG.step
SIZES = (7, 10)  # the board sides the authors ran: 7 (their teachers, TD3) and 10 (their
# distilled Blind Craftsman student)
OBSERVATIONS = ("authors", "craftsuite")


class KinematicWorldEnv(PlanarWorld):
    """A CraftSuite task on the authors' kinematic board, with their rules.

    ## Description
    A point agent on a square board ``[0, size) x [0, size)`` (``size`` 7 or 10). Each
    action moves it by ``STEP`` (3.0) times the action, at once: no velocity, no inertia.
    A move whose end leaves the board (or, in obstacle variants, ends in an obstacle) is
    rejected: the agent stays, pays ``continuous.boundary_reward`` and touches nothing.
    After an accepted move, the first object (board order) within ``pickup_radius`` (0.4,
    strictly less) whose requirements the inventory meets acts, as the authors' tiles do
    (``envs/tiles.py``): once per step, on every step in reach; its inventory change is
    clipped to capacity (an item touched at capacity is used up all the same); it pays its
    reward (the spec's item reward, a place's ``kinematic.reward``), leaves the board if
    consumable and ends the episode if its ``kinematic.ends_episode`` says so.

    ## Labels
    As the authors' training loop computes them: an ``obtained`` proposition is true on the
    step a tile that gives the item acts (even if the count was clipped); ``arrived`` on
    the steps the place acts, or, for a place labelled by its cell (their ``at_home``),
    while the agent's position truncated to integers is the place's cell; ``at_least``,
    ``exactly`` while the counts hold.

    ## Action Space
    ``Box(-1, 1, (2,), float32)``: displacement along x and y over ``STEP``. Out-of-range
    values are clipped; NaN, infinite or wrongly shaped actions raise ``ValueError``.

    ## Observation Space
    ``observation="authors"`` (the default): the authors' 2 + n_objects + n_inventory
    values: the position over ``size``; per object slot (board order: the corner place
    first, then the spec's order) its distance over ``size``, 0 once consumed; the raw
    inventory counts. ``observation="craftsuite"``: the MuJoCo world's layout without the
    velocity (position in [-1, 1), per slot its offset over ``size`` and a present flag,
    inventory over its largest count). ``observation_layout`` gives the slices. With
    ``product=True`` the automaton state's one-hot follows.

    ## Rewards
    The spec's step reward (the authors' ``RewEveryStep`` wrapper), the tiles' rewards and
    the boundary penalty. A task with a tile that ends the episode (the authors' tasks) is
    paid by its tiles; otherwise acceptance ends the episode with the completion reward.

    ## Episode End
    Terminated when a tile that ends the episode acts (for tasks without one: on
    acceptance or violation); truncated at 1000 steps by TimeLimit. ``is_success`` says
    whether the task was completed as the board defines it: a tile that ends the episode
    acted and the automaton accepts (for tasks without such a tile: the automaton
    accepts). The automaton may accept before: a place labelled by its cell (Blind
    Craftsman's home, ``[0, 1)^2``) holds in the whole cell, where the tile acts only
    within ``pickup_radius``; ``info["automaton_state"]`` shows that acceptance.

    ## Rendering
    ``rgb_array``: a top-down drawing of the board, ``(height, width, 3)`` uint8 (240 by
    default, each up to ``MAX_FRAME_SIDE``); ``status_panel=True`` adds the 40-row strip.
    For videos, ``set_frames_per_decision(n)`` has ``step`` draw the agent gliding to where
    it jumps, and ``motion_frames()`` gives the decision's ``n`` pictures.

    ## Registered Configurations
    ``CraftSuite/<Task>-Kinematic-v0`` for every task; keywords ``size``, ``observation``.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 8}

    def __init__(self, task: str | TaskSpec = "BlindCraftsman", render_mode: str | None = None,
                 width: int = 240, height: int = 240, status_panel: bool = False, size: int = 7,
                 observation: str = "authors"):
        if size not in SIZES:
            raise ValueError(f"size={size!r}: the kinematic board is {' or '.join(map(str, SIZES))} units a side")
        if observation not in OBSERVATIONS:
            raise ValueError(f"observation={observation!r}: use one of {', '.join(map(repr, OBSERVATIONS))}")
        self.width, self.height = frame_side("width", width), frame_side("height", height)
        super().__init__(task, render_mode, status_panel)
        spec = self.task
        self.size, self.observation = int(size), observation
        self.arena = float(size)
        self.half = self.arena / 2
        self.radius = float(spec.continuous.pickup_radius)
        self.step_size = STEP
        self.board = BoardRules(spec)
        corner = {k for k, obj in enumerate(spec.objects) if getattr(obj, "placement", "") == "corner"}
        kinds = [k for k, obj in enumerate(spec.objects) for _ in range(obj.count)]
        self._lay_out(sorted(kinds, key=lambda k: k not in corner))  # stable: fixed tiles first
        n_obj = len(self.kinds)
        self._fixed = np.array([k in corner for k in self.kinds])
        if observation == "authors":
            n_obs = 2 + n_obj + len(self.rules.inventory_names)
            high = np.concatenate([[1.0, 1.0], np.full(n_obj, np.sqrt(2.0)), self.rules.scale]).astype(np.float32)
            self.observation_space = gym.spaces.Box(0.0, high, (n_obs,), dtype=np.float32)
            self._obs = np.zeros(n_obs, dtype=np.float32)
            self.inv_offset = 2 + n_obj
        # the MuJoCo scene's obstacle boxes, scaled to this board and moved to its corner origin
        scale = self.arena / spec.continuous.arena
        boxes = np.array(obstacle_boxes(spec), dtype=float).reshape(-1, 3) * scale
        self.obstacles = boxes + [self.half, self.half, 0.0]
        # the authors' object sites: the board's integer points but (0, 0), here also clear
        # of obstacles by a pickup radius (so no object hides in a wall)
        axis = np.arange(self.size, dtype=float)
        sites = np.array([(x, y) for x in axis for y in axis if (x, y) != (0.0, 0.0)])
        self._sites = sites[~self.in_obstacle(sites, self.radius)]
        if len(self._sites) < n_obj - int(self._fixed.sum()):
            raise ValueError(f"{spec.name}: {n_obj} objects do not fit the {self.size}x{self.size} kinematic "
                             f"board's {len(self._sites)} free integer points")
        # arrived propositions read from the agent's cell: (bit, slot) per slot of such a place
        self.cell_bits = [(self.labeller.arrived_bits(k), j) for j, k in enumerate(self.kinds)
                           if self.board.tiles[k].by_cell and self.labeller.arrived_bits(k)]
        self._position = np.zeros(2)
        self._level_mask = 0

    def in_obstacle(self, points: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """Which of the (n, 2) board points lie in an obstacle grown by ``margin``."""
        return within_boxes(points, self.obstacles, margin)

    def on_board(self, point) -> bool:
        """Whether the agent may stand at ``point``: on the half-open board (the authors'
        bounds, ``0 <= x < size``), outside obstacles."""
        x, y = float(point[0]), float(point[1])
        return 0.0 <= x < self.arena and 0.0 <= y < self.arena and not self.in_obstacle(np.array([x, y]))[0]

    @property
    def observation_layout(self) -> dict:
        if self.observation == "craftsuite":
            return super().observation_layout
        n_obj = len(self.kinds)
        return {"agent_position": slice(0, 2), "distances": slice(2, 2 + n_obj),
                "object_names": tuple(self.task.objects[k].name for k in self.kinds),
                "inventory": slice(2 + n_obj, 2 + n_obj + len(self.inventory_counts)),
                "inventory_names": self.rules.inventory_names}

    # -- public views --------------------------------------------------------------------------
    @property
    def agent_position(self) -> np.ndarray:
        """Board coordinates, ``[0, size)`` on each axis."""
        return self._position.copy()

    # -- episodes ----------------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        rng = self.np_random
        free = ~self._fixed
        self._positions[self._fixed] = 0.0
        self._positions[free] = self._sites[rng.permutation(len(self._sites))[:int(free.sum())]]
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
        self._write_inventory()
        return self._obs.copy(), self.tracker.reset()

    def _write_observation(self):
        obs, n_obj = self._obs, len(self.kinds)
        offsets = self._positions - self._position
        if self.observation == "authors":
            obs[0:2] = self._position / self.arena
            obs[2:2 + n_obj] = np.where(self._present, np.sqrt((offsets ** 2).sum(axis=1)) / self.arena, 0.0)
        else:
            obs[0:2] = self._position / self.half - 1.0
            view = obs[2:2 + 3 * n_obj].reshape(n_obj, 3)
            view[:, :2] = np.where(self._present[:, None], offsets / self.arena, 0.0)
            view[:, 2] = self._present

    def _write_inventory(self) -> None:
        if self.observation == "craftsuite":
            return super()._write_inventory()
        self._obs[self.inv_offset:] = self.inventory_counts

    def cell_mask(self) -> int:
        """The bits of the places labelled by their cell that hold at the agent's position."""
        cell = np.floor(self._position)
        mask = 0
        for bit, j in self.cell_bits:
            if self._present[j] and (np.floor(self._positions[j]) == cell).all():
                mask |= bit
        return mask

    def step(self, action):
        x, y = self.planar_action(action, "displacement")
        target = self._position + self.step_size * np.array([x, y])
        reward = self._step_reward
        mask, ended = self._level_mask, False
        accepted = self.on_board(target)
        if self._drawing_motion():  # drawn before the move's touches change the board
            self._motion = self._draw_motion(target if accepted else self._position)
        if accepted:
            self._position = target
            offsets = self._positions - target
            inside = self._present & (np.einsum("ij,ij->i", offsets, offsets) < self.radius ** 2)
            if inside.any():
                inv = self.inventory_counts
                j, outcome = self.board.first_acting(inv, [(j, self.kinds[j]) for j in np.flatnonzero(inside)])
                if outcome is not None:
                    reward += outcome.reward
                    ended = outcome.ends_episode
                    if outcome.consumed:
                        self._consume(j)
                        inside[j] = False
                    self._level_mask = self.labeller.levels(inv)
                    mask = self.labeller(inv, outcome.gained, outcome.arrived)
                    self._write_inventory()
            self._inside = inside
        else:  # the authors reject the whole move: the agent stays and touches nothing
            reward += self.boundary_reward
        if self.cell_bits:
            mask |= self.cell_mask()
        self._write_observation()
        bonus, done, info = self.tracker.advance(mask)
        if self.board.ends_by_tile:  # the tiles pay and end the episode, as the authors' do
            # success is completion: a tile ended the episode with the objective met. The
            # automaton alone accepts earlier where a place is labelled by its whole cell
            # (Blind Craftsman's home), a step that pays nothing and ends nothing here
            info["is_success"] = ended and info["is_success"]
            return self._obs.copy(), reward, ended, False, info
        return self._obs.copy(), reward + bonus, done or ended, False, info

    # -- rendering -----------------------------------------------------------------------------------
    def world_to_pixel(self, x: float, y: float) -> tuple[int, int]:
        """(column, row) of a board point in the frame (y up, the board filling the frame)."""
        return int(x / self.arena * self.width), int((1.0 - y / self.arena) * self.height)

    def render(self):
        if not self._can_render(bool(self._started)):
            return None
        return self._draw(self._position)

    def _draw_motion(self, end: np.ndarray) -> list[np.ndarray]:
        """The agent on its way from where it is to ``end`` (the board moves it at once; a
        video shows the jump as a glide): ``frames_per_decision - 1`` pictures before ``end``."""
        n, start = self.frames_per_decision, self._position
        return [self._draw(start + (end - start) * (k / n)) for k in range(1, n)]

    def _draw(self, position: np.ndarray) -> np.ndarray:
        """The board with the agent at ``position``."""
        frame = np.full((self.height, self.width, 3), 235, dtype=np.uint8)
        sx, sy = self.width / self.arena, self.height / self.arena
        for x, y, h in self.obstacles:
            c0, r0 = self.world_to_pixel(x - h, y + h)
            c1, r1 = self.world_to_pixel(x + h, y - h)
            cv2.rectangle(frame, (c0, r0), (c1, r1), (61, 89, 150), -1)
        objects = self.task.objects
        for i, kind in enumerate(self.kinds):
            if not self._present[i]:
                continue
            col, row = self.world_to_pixel(*self._positions[i])
            color = hex_to_rgb(objects[kind].color)
            if self.is_item[i]:  # items small discs, places their pickup zone
                cv2.circle(frame, (col, row), max(1, int(0.2 * min(sx, sy))), color, -1, cv2.LINE_AA)
            else:
                cv2.ellipse(frame, (col, row), (max(1, int(self.radius * sx)), max(1, int(self.radius * sy))),
                            0, 0, 360, color, -1, cv2.LINE_AA)
        col, row = self.world_to_pixel(*position)
        cv2.circle(frame, (col, row), max(1, int(0.15 * min(sx, sy))), (20, 20, 20), -1, cv2.LINE_AA)
        return add_status_panel(frame, self) if self.status_panel else frame
