"""The MuJoCo world natively vectorized: N point-mass episodes on one ``MjModel``.

``gymnasium.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point", ...)`` builds
this for the ``Cont`` ids, with the contract of ``craftsuite.envs.vector`` (read its module
docstring: observations, rewards, flags, infos, ``info["transition"]``, autoreset, seeds and
reset masks as gymnasium's ``SyncVectorEnv`` over N ``gymnasium.make(id, ...)`` gives them).

Physics: one ``MjModel`` (the template world's) and one ``MjData`` per env, each stepped
``frame_skip`` physics steps per action with ``mujoco.mj_step(model, data, nstep=...)``, as
the single env steps its own. Sharing the model is exact: the object bodies are welded to
the world and never collide (``contype=0``), so where their ``body_pos`` puts them (the
single env writes it for rendering) changes nothing the agent's degrees of freedom see.
Everything else (boundary reward, distances, touches, observations, the automaton) is numpy
over the N envs; only envs within reach of an object run the task's ``Rules`` and
``Labeller`` (``PlanarWorld._touch``'s code, per env). A reset draws the episode with the
template world on the env's own generator and copies the template's ``MjData`` (after its
``mj_resetData``, agent placement and ``mj_forward``) into the env's: the same physics state,
bit for bit, as the single env's after its reset.

This module imports MuJoCo; ``craftsuite.envs.vector`` (grid and kinematic) does not.
"""

from __future__ import annotations

import mujoco
import numpy as np
from gymnasium.vector import AutoresetMode

from ..spec import TaskSpec
from .continuous import _FAR, TOP_SPEED, ContinuousWorldEnv
from .vector import PlanarVectorEnv, _check_kwargs


class ContinuousVectorEnv(PlanarVectorEnv):
    """``num_envs`` episodes of the MuJoCo world (see ``ContinuousWorldEnv``): one shared
    ``MjModel``, an ``MjData`` per env; agent positions and velocities as (N, 2) arrays,
    object slots as (N, n_objects) arrays."""

    # the single MuJoCo id's keywords; width/height/status_panel only shape frames, which
    # this does not draw (render_mode must stay None)
    WHAT = "thrust"
    KEYWORDS = ("product", "render_mode", "width", "height", "frame_skip", "status_panel",
                "max_episode_steps", "autoreset_mode")

    def __init__(self, num_envs: int, task: str | TaskSpec = "BlindCraftsman", product: bool = False,
                 max_episode_steps: int | None = None,
                 autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP, **kwargs):
        _check_kwargs("MuJoCo", kwargs, self.KEYWORDS)
        kwargs.pop("render_mode", None)
        template = ContinuousWorldEnv(task, **kwargs)
        super().__init__(template, num_envs, product, max_episode_steps, autoreset_mode)
        n_obj = len(template.kinds)
        self.model = template.model  # shared: the template's resets only move object bodies
        self._datas = [mujoco.MjData(self.model) for _ in range(num_envs)]
        # views into each MjData, made once (they stay valid while the data lives)
        self._ctrl = [d.ctrl for d in self._datas]
        self._qpos = [d.qpos for d in self._datas]
        self._qvel = [d.qvel for d in self._datas]
        self.frame_skip = template.frame_skip
        self.dt = template.dt
        self.kinds = list(template.kinds)
        self.is_item = template.is_item
        self.arena, self.half = template.arena, template.half
        self.radius2 = template.radius2
        self._wall_limit = template.wall_limit
        self.boundary_reward = template.boundary_reward
        self.inv_offset = template.inv_offset
        self._n_obj = n_obj
        self._position = np.zeros((num_envs, 2))  # qpos[:2] of each env's data
        self._velocity = np.zeros((num_envs, 2))  # qvel[:2]
        self._positions = np.zeros((num_envs, n_obj, 2))  # _FAR once consumed, as the single env parks them
        self._offset_scale = np.zeros((num_envs, n_obj, 1))  # 1 / arena, 0 once consumed
        self._present = np.zeros((num_envs, n_obj), dtype=bool)
        self._inside = np.zeros((num_envs, n_obj), dtype=bool)

    def _load(self, i: int) -> None:
        world = self.world
        mujoco.mj_copyData(self._datas[i], self.model, world.data)
        self._position[i] = world.data.qpos[:2]
        self._velocity[i] = world.data.qvel[:2]
        self._positions[i] = world._positions
        self._offset_scale[i] = world._offset_scale
        self._present[i] = True
        self._inside[i] = False

    def _move(self, actions, active):
        """``ContinuousWorldEnv.step`` for the active envs, up to the automaton."""
        model, nstep = self.model, self.frame_skip
        position, velocity = self._position, self._velocity
        ctrl, qpos, qvel, datas = self._ctrl, self._qpos, self._qvel, self._datas
        rows = actions.tolist()
        for i in np.flatnonzero(active).tolist():
            ctrl[i][:] = rows[i]
            mujoco.mj_step(model, datas[i], nstep=nstep)
            position[i] = qpos[i][:2]
            velocity[i] = qvel[i][:2]

        rewards = np.full(self.num_envs, self._step_reward)
        lim = self._wall_limit
        pushing = ((np.abs(position) >= lim) & (actions * position > 0)).any(axis=1)
        rewards[active & pushing] += self.boundary_reward

        offsets = self._positions - position[:, None, :]
        inside = np.einsum("nij,nij->ni", offsets, offsets) < self.radius2
        inside &= active[:, None]
        masks = self._levels.copy()
        for i in np.flatnonzero(inside.any(axis=1)).tolist():
            self._touch(i, inside[i], rewards, masks)
        self._inside[active] = inside[active]
        self._write_observation(offsets)
        return rewards, masks

    def _remove(self, i: int, j: int) -> None:
        """As the single world's ``_remove``: the slot parked far away, its offset zeroed."""
        self._positions[i, j] = _FAR
        self._offset_scale[i, j] = 0.0

    def _write_observation(self, offsets: np.ndarray) -> None:
        """``ContinuousWorldEnv._write_observation`` for all envs (the inventory is written on
        touches and resets, the only times it changes)."""
        obs, n_obj = self._obs, self._n_obj
        obs[:, 0:2] = self._position / self.half
        obs[:, 2:4] = np.clip(self._velocity / TOP_SPEED, -1.0, 1.0)
        scaled = offsets * self._offset_scale  # consumed slots: far away times 0
        obs[:, 4:4 + 3 * n_obj:3] = scaled[..., 0]
        obs[:, 5:5 + 3 * n_obj:3] = scaled[..., 1]
        obs[:, 6:6 + 3 * n_obj:3] = self._present


def make_continuous_vector(num_envs: int, **kwargs) -> ContinuousVectorEnv:
    """Vector entry point of the MuJoCo ids (``gymnasium.make_vec(..., vectorization_mode=
    "vector_entry_point")``): the spec's ``task``, ``max_episode_steps`` and the single id's
    keywords."""
    return ContinuousVectorEnv(num_envs, **kwargs)
