"""MuJoCo worlds: a point-mass agent in a square arena, the same tasks and rules as the grids."""

from __future__ import annotations

import mujoco
import numpy as np

from ..rendering.frames import frame_side
from ..rendering.gl import gl_error_hint
from ..rendering.panel import add_status_panel
from ..spec import TaskSpec
from .planar import PlanarWorld, within_boxes
from .scene import AGENT_HALF, build_scene

TOP_SPEED = 2.0  # m/s at full thrust (gear 10 / damping 5 in assets/arena.xml)
_PLACEMENT_TRIES = 200
_FAR = 1e6  # where consumed objects are parked: never within reach
class ContinuousWorldEnv(PlanarWorld):
    """A CraftSuite task in a MuJoCo arena with a point-mass agent.

    ## Description
    The agent, a 0.3 m cube on two slide joints, moves in a square arena (7 x 7 m by
    default) walled on all sides; obstacle variants add solid walls. An object is touched
    while the agent's centre is within ``pickup_radius`` (0.4 m) of it: items are picked
    up (and vanish) when the task's rules allow, places act on entering their zone. Rules,
    labels and the automaton are the same code as the grid worlds use.

    ## Action Space
    ``Box(-1, 1, (2,), float32)``: thrust along x and y. Out-of-range values are clipped;
    NaN, infinite or wrongly shaped actions raise ``ValueError``. Each action is held for
    the spec's ``continuous.control_period`` (default 0.25 s: ``frame_skip`` 10 physics
    steps of 0.025 s); full thrust reaches the top speed of 2 m/s (0.5 m per decision)
    with a 0.2 s time constant, so crossing the arena takes about 14 decisions, as a 7x7
    grid teacher crosses its grid in 6 moves, and the scripted policy completes Blind
    Craftsman in about 40. A fine-control world is
    ``gymnasium.make(id, frame_skip=2, max_episode_steps=1000)`` (0.05 s, the same 50 s
    of simulated time); no TD3 student has learned a task there.

    ## Observation Space
    ``Box(-1, 1, (4 + 3 * n_objects + n_inventory,), float32)``: agent position divided
    by half the arena and velocity divided by the top speed; per object slot (spec order,
    fixed count) its position relative to the agent divided by the arena side and a
    present flag (0 once consumed, its position then 0); inventory counts divided by their
    largest possible value. ``observation_layout`` gives the slices. With ``product=True``
    the automaton state's one-hot follows.

    ## Rewards
    The spec's step reward (-0.1), item rewards on pickup, the completion reward (+100) on
    acceptance, and ``boundary_reward`` (-0.1) on every step the agent pushes against the
    boundary wall.

    ## Starting State
    Objects and the agent at random positions, at least two pickup radii apart (so no
    zones overlap, nor the start), clear of walls and obstacles.

    ## Episode End
    Terminated on acceptance (``is_success``) or on reaching the rejecting sink
    (``violation``); truncated at ``continuous.max_steps`` decisions (200) by TimeLimit.

    ## Rendering
    ``rgb_array``: the top camera's view of the arena, ``(height, width, 3)`` uint8
    (``gymnasium.make`` keywords ``width`` and ``height``, 240 by default, each a whole
    number of pixels up to ``MAX_FRAME_SIDE``; ``frame_shape`` says it). With
    ``status_panel=True`` (for videos people watch) a 40-row strip with the inventory and
    the automaton state is added below, ``(height + 40, width, 3)``; it is off by default
    because a frame showing the automaton state would hand it to an agent that learns from
    pixels. For videos, ``set_frames_per_decision(n)`` has ``step`` draw the arena during
    its physics steps too, and ``motion_frames()`` gives the decision's ``n`` pictures.

    ## Registered Configurations
    ``CraftSuite/<Task>-Cont-v0`` for every task spec in ``tasks/``, the rungs of the
    ladder and the paper's tasks (``craftsuite tasks`` lists them).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 4}  # at the default 0.25 s; __init__ sets 1 / period
    AGENT_FIELDS = {"agent_position": slice(0, 2), "agent_velocity": slice(2, 4)}

    def __init__(self, task: str | TaskSpec = "BlindCraftsman", render_mode: str | None = None,
                 width: int = 240, height: int = 240, frame_skip: int | None = None,
                 status_panel: bool = False):
        if frame_skip is not None and (not isinstance(frame_skip, int) or isinstance(frame_skip, bool)
                                       or frame_skip < 1):
            raise ValueError(f"frame_skip must be a positive integer (physics steps per action), got {frame_skip!r}")
        self.width, self.height = frame_side("width", width), frame_side("height", height)
        super().__init__(task, render_mode, status_panel)
        spec = self.task
        cfg = spec.continuous
        self.arena = cfg.arena
        self.half = cfg.arena / 2
        self.radius = cfg.pickup_radius
        self.scene = scene = build_scene(spec)
        self._boxes = np.array(scene.obstacles, dtype=float).reshape(-1, 3)  # x, y, half side
        self.model = mujoco.MjModel.from_xml_string(scene.xml)
        self.data = mujoco.MjData(self.model)
        self.frame_skip = frame_skip = frame_skip or self._spec_frame_skip()
        self.dt = self.model.opt.timestep * frame_skip  # the control period
        self.metadata = {**self.metadata, "render_fps": round(1 / self.dt)}
        # arena.xml's off-screen framebuffer (640 x 640) would refuse larger frames
        offscreen = self.model.vis.global_
        offscreen.offwidth = max(offscreen.offwidth, self.width)
        offscreen.offheight = max(offscreen.offheight, self.height)
        # An orthographic fovy is the vertical extent in metres; widen it for tall frames so
        # the whole arena stays in view across the narrower side.
        top = self.model.camera("top").id
        self.model.cam_fovy[top] *= max(1.0, self.height / self.width)
        self._view_height = float(self.model.cam_fovy[top])
        self._body_ids = np.array([self.model.body(n).id for n in scene.object_bodies])
        self._geom_ids = np.array([self.model.geom(n).id for n in scene.object_bodies])
        self._rgba = self.model.geom_rgba[self._geom_ids].copy()
        self._lay_out(scene.object_kinds)
        n_obj = len(self.kinds)
        # how far from the centre, on either axis, the agent touches the boundary wall
        self.wall_limit = self.half - AGENT_HALF - 0.02
        self._any_inside = False
        self.radius2 = self.radius ** 2
        self._offset_scale = np.zeros((n_obj, 1))
        self._obs_objects = self._object_view()
        self._renderer = None
        self.inventory_counts = self.rules.new_inventory()

    def _spec_frame_skip(self) -> int:
        """Physics steps per action for the spec's control period (a whole number of them)."""
        try:  # the spec checked this against arena.xml; a spec built in code may not have been
            return self.task.continuous.frame_skip(self.model.opt.timestep)
        except ValueError as err:
            raise ValueError(f"{self.task.path or self.task.name}: continuous.control_period: {err}") from None

    def _object_view(self) -> np.ndarray:
        """(dx, dy, present) rows of the observation buffer, as a writable view."""
        n_obj = len(self.kinds)
        return self._obs[4:4 + 3 * n_obj].reshape(n_obj, 3)

    # -- public views --------------------------------------------------------------------------
    @property
    def agent_position(self) -> np.ndarray:
        return self.data.qpos[:2].copy()

    # -- episodes ----------------------------------------------------------------------------------
    def _clear(self, points: np.ndarray, margin: float) -> np.ndarray:
        """Which of the (n, 2) points keep ``margin`` from the walls and every obstacle."""
        ok = (np.abs(points) <= self.half - margin).all(axis=1)
        return ok & ~within_boxes(points, self._boxes, margin)

    def _sample_positions(self, n: int) -> np.ndarray:
        """n points, pairwise >= 2 pickup radii apart, clear of walls and obstacles.

        Uniform dart throwing (batches of candidates, checked with numpy) for sparse
        scenes; scenes too crowded for it (Diamond Mine's 43 objects fill over half the
        arena with pickup zones) take random cells of a jittered lattice.
        """
        rng, spacing = self.np_random, 2 * self.radius + 1e-3
        margin = max(self.radius, AGENT_HALF) + 0.05
        span = self.arena - 2 * margin
        if n > 0.35 * (span / spacing) ** 2:
            return self._jittered_grid(n, spacing, margin)
        points = np.empty((0, 2))
        for _ in range(n):
            for _ in range(_PLACEMENT_TRIES // 20):
                cand = rng.uniform(-self.half + margin, self.half - margin, (20, 2))
                ok = self._clear(cand, margin)
                if len(points):
                    gaps = np.linalg.norm(cand[:, None, :] - points[None, :, :], axis=2).min(axis=1)
                    ok = ok & (gaps >= spacing)
                hits = np.flatnonzero(ok)
                if len(hits):
                    points = np.vstack([points, cand[hits[0]]])
                    break
            else:
                return self._jittered_grid(n, spacing, margin)
        return points

    def _jittered_grid(self, n: int, spacing: float, margin: float) -> np.ndarray:
        """Crowded scenes (Diamond Mine's 43 objects): random cells of a lattice, jittered."""
        span = self.arena - 2 * margin
        per_side = int(span // spacing) + 1
        step = span / (per_side - 1)
        jitter = max(0.0, (step - spacing) / 2)
        axis = np.linspace(-self.half + margin, self.half - margin, per_side)
        cells = np.array([(x, y) for x in axis for y in axis])
        cells = cells[self._clear(cells, margin)]
        if len(cells) < n:
            raise RuntimeError(f"{self.task.name}: {n} positions do not fit the arena")
        chosen = cells[self.np_random.permutation(len(cells))[:n]]
        return chosen + self.np_random.uniform(-jitter, jitter, chosen.shape)

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        model, data = self.model, self.data
        mujoco.mj_resetData(model, data)
        n_obj = len(self.kinds)
        points = self._sample_positions(n_obj + 1)
        self._positions = points[:n_obj].copy()
        data.qpos[:2] = points[n_obj]
        model.body_pos[self._body_ids, :2] = self._positions
        model.body_pos[self._body_ids, 2] = 0.0
        model.geom_rgba[self._geom_ids] = self._rgba
        self._present[:] = True
        self._inside[:] = False
        self._any_inside = False
        self._offset_scale[:] = 1.0 / self.arena
        mujoco.mj_forward(model, data)
        self.inventory_counts = self.rules.new_inventory()
        self._level_mask = self.labeller.levels(self.inventory_counts)
        self._started = True
        obs = self._obs
        obs[:] = 0.0
        self._obs_objects[:, 2] = 1.0
        self._write_observation(self._positions - data.qpos[:2])
        return obs.copy(), self.tracker.reset()

    def _write_observation(self, offsets: np.ndarray):
        """Agent state and object offsets (``offsets`` = object positions - agent position)."""
        obs, data = self._obs, self.data
        obs[0] = data.qpos[0] / self.half
        obs[1] = data.qpos[1] / self.half
        obs[2] = min(1.0, max(-1.0, data.qvel[0] / TOP_SPEED))
        obs[3] = min(1.0, max(-1.0, data.qvel[1] / TOP_SPEED))
        # consumed objects sit far away with scale 0: their offsets read 0
        view = self._obs_objects[:, :2]
        np.multiply(offsets, self._offset_scale, out=view)

    def step(self, action):
        x, y = self.planar_action(action, "thrust")
        model, data = self.model, self.data
        data.ctrl[0] = x
        data.ctrl[1] = y
        if self._drawing_motion():
            self._motion = self._step_physics_drawing()
        else:
            for _ in range(self.frame_skip):
                mujoco.mj_step(model, data)

        reward = self._step_reward
        px, py = data.qpos[0], data.qpos[1]
        lim = self.wall_limit
        if (abs(px) >= lim and x * px > 0) or (abs(py) >= lim and y * py > 0):
            reward += self.boundary_reward

        offsets = self._positions - data.qpos[:2]
        dist2 = np.einsum("ij,ij->i", offsets, offsets)
        mask = self._level_mask
        if dist2.min() < self.radius2 or self._any_inside:
            inside = dist2 < self.radius2
            mask, reward = self._touch(inside, mask, reward)
            self._inside = inside
            self._any_inside = bool(inside.any())
        self._write_observation(offsets)

        bonus, done, info = self.tracker.advance(mask)
        return self._obs.copy(), reward + bonus, done, False, info

    def _step_physics_drawing(self) -> list[np.ndarray]:
        """The decision's physics steps, as ``step`` takes them, with a picture after every
        ``frame_skip / frames_per_decision`` of them but the last (``render()`` draws that one,
        after the touches)."""
        n, skip, frames = self.frames_per_decision, self.frame_skip, []
        for k in range(skip):
            mujoco.mj_step(self.model, self.data)
            if len(frames) < n - 1 and k + 1 >= round((len(frames) + 1) * skip / n):
                frames.append(self.render())
        return frames

    def set_frames_per_decision(self, n: int) -> int:
        return super().set_frames_per_decision(min(n, self.frame_skip))  # at most one per physics step

    def _remove(self, i: int):
        self._positions[i] = _FAR
        self._offset_scale[i] = 0.0
        self._obs_objects[i, 2] = 0.0
        self.model.geom_rgba[self._geom_ids[i], 3] = 0.0
        self.model.body_pos[self._body_ids[i], 2] = -1.0

    # -- rendering -----------------------------------------------------------------------------------
    def world_to_pixel(self, x: float, y: float) -> tuple[int, int]:
        """(column, row) of an arena point in the camera image (top-down, orthographic)."""
        tall = self._view_height
        wide = tall * self.width / self.height
        col = (x / wide + 0.5) * self.width
        row = (0.5 - y / tall) * self.height
        return int(col), int(row)

    def render(self):
        if not self._can_render(bool(self._started)):
            return None
        if self._renderer is None:
            try:
                self._renderer = mujoco.Renderer(self.model, self.height, self.width)
            except Exception as err:  # the GL backend could not start
                raise RuntimeError(gl_error_hint(err)) from err
        self._renderer.update_scene(self.data, camera="top")
        frame = self._renderer.render()
        return add_status_panel(frame, self) if self.status_panel else frame

    def close(self):
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        super().close()

    def __getstate__(self):
        state = self.__dict__.copy()
        state["_renderer"] = None  # GL contexts do not travel; render() makes a new one
        del state["_obs_objects"]  # a view into _obs: pickling would detach it
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._obs_objects = self._object_view()
