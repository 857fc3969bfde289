"""What the two continuous worlds share: objects in the plane, touched within a radius.

The MuJoCo world (``ContinuousWorldEnv``) and the kinematic board (``KinematicWorldEnv``)
share their object slots, actions, obstacle geometry and views here. What a touch does
differs: the MuJoCo world reads it through the task's ``Rules`` (``touch_slots``, shared
with its vector env, as the grids read theirs); the kinematic board follows the authors'
tiles (``envs/tiles.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import gymnasium as gym
import numpy as np

from ..rendering.panel import PANEL_HEIGHT
from ..spec import TaskSpec
from .base import CraftWorld


def obstacle_boxes(spec: TaskSpec) -> tuple[tuple[float, float, float], ...]:
    """Obstacle cells of the largest grid as (x, y, half side) in arena coordinates (y up,
    origin at the centre); the kinematic board shifts them to its corner origin."""
    if not spec.grid.obstacles:
        return ()
    n = max(spec.grid.sizes)
    cell = spec.continuous.arena / n
    half = spec.continuous.arena / 2
    return tuple(((x + 0.5) * cell - half, half - (y + 0.5) * cell, cell / 2)
                 for x, y in spec.grid.obstacles)


def within_boxes(points: np.ndarray, boxes: np.ndarray, margin: float = 0.0) -> np.ndarray:
    """Which of the (n, 2) points lie inside any (k, 3) box (x, y, half side) grown by ``margin``."""
    points = np.atleast_2d(points)
    if not len(boxes):
        return np.zeros(len(points), dtype=bool)
    gap = np.maximum(np.abs(points[:, None, 0] - boxes[:, 0]), np.abs(points[:, None, 1] - boxes[:, 1]))
    return (gap < boxes[:, 2] + margin).any(axis=1)


def touch_slots(rules, inv: list[int], kinds, is_item, inside: np.ndarray, was_inside, reward: float,
                consume) -> tuple[float, int, int, bool]:
    """The rules' reading of the object slots within reach (``inside``, cleared where a slot
    is consumed): items are touched while within reach, places act on entering their zone
    (not ``was_inside``). ``consume(j)`` removes slot j; ``inv`` changes in place. Returns
    (reward plus the touches', inventory bits gained, place kind entered or -1, whether any
    rule acted). One piece of code for the MuJoCo world and its vector env."""
    gained, arrived, touched = 0, -1, False
    for j in np.flatnonzero(inside).tolist():
        kind = kinds[j]
        entered = not was_inside[j]
        outcome = rules.touch(inv, kind, entered)
        if entered and not is_item[j]:
            arrived = kind
        if outcome is None:
            continue
        touched = True
        reward += outcome.reward
        gained |= outcome.gained
        if outcome.consumed:
            consume(j)
            inside[j] = False
    return reward, gained, arrived, touched


@dataclass(frozen=True)
class ObjectSlots:
    """The object slots of a continuous world at one moment, one row per slot (read-only
    copies: the world moves on without them)."""

    kinds: np.ndarray  # (n,) int: the slot's object kind, an index into ``task.objects``
    positions: np.ndarray  # (n, 2): where the slot's object is (meaningless once consumed)
    present: np.ndarray  # (n,) bool: not consumed yet
    inside: np.ndarray  # (n,) bool: the agent was within reach at the last step


def _frozen(array: np.ndarray) -> np.ndarray:
    array.flags.writeable = False
    return array


class PlanarWorld(CraftWorld):
    """Base of the continuous worlds. Subclasses set, per object slot, ``kinds`` (its
    object kind), ``is_item``, ``_present``, ``_inside`` (the agent was within reach at the
    last step) and ``_positions``; ``_obs`` with the inventory from ``inv_offset``; and
    ``width`` and ``height`` of a frame. What does not change between episodes (``kinds``,
    ``is_item``, ``inv_offset``, ``boundary_reward``) is public: the vector envs read it.
    They define ``_remove(i)``: what consuming slot ``i`` changes besides ``_present`` (the
    MuJoCo world hides its body)."""

    def _lay_out(self, kinds: list[int]) -> None:
        """The object slots (one per object, of these kinds), the spaces and the buffers, in
        the shared layout: the agent's fields, (dx, dy, present) per slot, the inventory."""
        self.kinds = list(kinds)
        n_obj, first = len(self.kinds), max(f.stop for f in self.AGENT_FIELDS.values())
        self.is_item = np.array([k < self.rules.n_items for k in self.kinds], dtype=bool)
        self.inv_offset = first + 3 * n_obj
        n_obs = self.inv_offset + len(self.rules.inventory_names)
        self.observation_space = gym.spaces.Box(-1.0, 1.0, (n_obs,), dtype=np.float32)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
        self._step_reward = self.task.step_reward
        self.boundary_reward = self.task.continuous.boundary_reward
        self._obs = np.zeros(n_obs, dtype=np.float32)
        self._positions = np.zeros((n_obj, 2))
        self._present = np.zeros(n_obj, dtype=bool)
        self._inside = np.zeros(n_obj, dtype=bool)
        self._started = False

    # the observation's first fields, before the objects' (dx, dy, present) rows
    AGENT_FIELDS: dict[str, slice] = {"agent_position": slice(0, 2)}

    @property
    def observation_layout(self) -> dict:
        """Slices of the observation by field: the agent's fields, ``objects`` ((dx, dy,
        present) per slot, named in ``object_names``), ``inventory`` (``inventory_names``)."""
        first = max(f.stop for f in self.AGENT_FIELDS.values())
        return {
            **self.AGENT_FIELDS,
            "objects": slice(first, first + 3 * len(self.kinds)),
            "object_names": tuple(self.task.objects[k].name for k in self.kinds),
            "inventory": slice(self.inv_offset, self.inv_offset + len(self.inventory_counts)),
            "inventory_names": self.rules.inventory_names,
        }

    def planar_action(self, action, what: str) -> tuple[float, float]:
        """``action`` as two floats clipped to [-1, 1]; ``what`` names them in errors
        ("thrust", "displacement").

        Raises:
            ValueError: not two numbers, or NaN or infinite ones.
            RuntimeError: before the first ``reset``.
        """
        try:
            x, y = action
            x, y = float(x), float(y)
        except (TypeError, ValueError):
            shape = getattr(action, "shape", None)
            raise ValueError(
                f"invalid action {action!r}" + (f" of shape {shape}" if shape is not None else "")
                + f": expected 2 numbers ({what} along x and y) in [-1, 1]"
            ) from None
        if not (abs(x) < float("inf") and abs(y) < float("inf")):  # also False for NaN
            raise ValueError(f"invalid action [{x}, {y}]: NaN or infinite {what}")
        if not self._started:
            raise RuntimeError("call reset() before step()")
        return min(1.0, max(-1.0, x)), min(1.0, max(-1.0, y))

    def remaining_counts(self) -> list[int]:
        """Objects of each kind still in the world (places are never used up)."""
        counts = [0] * len(self.task.objects)
        for i, kind in enumerate(self.kinds):
            counts[kind] += bool(self._present[i])
        return counts

    @property
    def objects(self) -> ObjectSlots:
        """The object slots now: kinds, positions, present, within reach. Built when asked
        for, never on a step."""
        return ObjectSlots(_frozen(np.array(self.kinds)), _frozen(self._positions.copy()),
                           _frozen(self._present.copy()), _frozen(self._inside.copy()))

    def object_positions(self) -> dict[str, list[tuple[float, float]]]:
        """Positions of the objects still in the world, by object name."""
        out: dict[str, list[tuple[float, float]]] = {o.name: [] for o in self.task.objects}
        for i, kind in enumerate(self.kinds):
            if self._present[i]:
                out[self.task.objects[kind].name].append(tuple(float(v) for v in self._positions[i].round(4)))
        return out

    def _touch(self, inside: np.ndarray, mask: int, reward: float) -> tuple[int, float]:
        """Apply the rules to every object whose zone the agent is in; return (label, reward).
        An item is touched while within reach, a place acts on entering its zone."""
        inv = self.inventory_counts
        reward, gained, arrived, touched = touch_slots(self.rules, inv, self.kinds, self.is_item, inside,
                                                       self._inside, reward, self._consume)
        if touched:
            self._write_inventory()
            self._level_mask = self.labeller.levels(inv)
        if touched or arrived >= 0:
            mask = self.labeller(inv, gained, arrived)
        return mask, reward

    def _consume(self, i: int) -> None:
        self._present[i] = False
        self._remove(i)

    def _remove(self, i: int) -> None:
        """What else consuming slot ``i`` changes (``_present`` is cleared already)."""

    def _write_inventory(self) -> None:
        off, scale = self.inv_offset, self.rules.scale
        for s, count in enumerate(self.inventory_counts):
            self._obs[off + s] = count / scale[s]

    # -- motion for videos -------------------------------------------------------------------
    frames_per_decision = 1  # pictures per decision that ``motion_frames`` gives
    _motion: list = []  # what ``step`` drew between the last two decisions (none at 1 per decision)

    def set_frames_per_decision(self, n: int) -> int:
        """Have ``step`` draw the motion of each decision, so that a video plays it rather
        than jumps: ``n - 1`` pictures between two decisions, evenly spaced in time (with a
        render mode; drawing costs, so 1, the default, draws none). Returns the number per
        decision the world will give, which a world may cap (MuJoCo: one per physics step)."""
        self.frames_per_decision = max(1, int(n))
        return self.frames_per_decision

    def _drawing_motion(self) -> bool:
        return self.frames_per_decision > 1 and self.render_mode == "rgb_array"

    def motion_frames(self) -> list[np.ndarray]:
        """The last decision as ``frames_per_decision`` pictures, evenly spaced in time: those
        ``step`` drew on the way, then ``render()``'s of where it ended (after a reset, call
        ``render()``: there was no motion)."""
        frames, self._motion = self._motion, []
        return [*frames, self.render()]

    @property
    def frame_shape(self) -> tuple[int, int, int]:
        """Shape of an ``rgb_array`` frame: ``(rows, columns, 3)``."""
        return (self.height + (PANEL_HEIGHT if self.status_panel else 0), self.width, 3)
