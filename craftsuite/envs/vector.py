"""Natively vectorized grid and kinematic worlds: N episodes stepped together with numpy.

``gymnasium.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point", ...)`` builds
these for the ``Grid<size>`` and ``Kinematic`` ids. They give exactly what gymnasium's
``SyncVectorEnv`` over N ``gymnasium.make(id, ...)`` gives for the same seeds and actions
(observations, rewards, terminations, truncations, infos, autoreset), several times faster:
moves, board checks, distance tests, observations and the automaton step are numpy over
all envs at once. Only the envs that touch an object in a step go through the task's
``Rules`` and ``Labeller`` in Python, so the rules stay the single worlds' code; resets draw
layouts with a single world (the "template") on each env's own generator, so every layout
is the single world's draw.

Contract (what a training engine may rely on):

* Observations: ``(N, obs_dim)`` float32, the single env's vector (with ``product=True`` the
  automaton state's one-hot last), a fresh array every call.
* Rewards ``(N,)`` float64; terminated, truncated ``(N,)`` bool; truncation at the id's
  ``max_episode_steps`` (as TimeLimit; both flags may be set on one step).
* Infos as ``SyncVectorEnv`` aggregates the single env's info: ``labels`` (object array of
  name tuples), ``label_mask``, ``automaton_state`` (int64), ``automaton_transition``
  (object array of ``(w, sigma, w')`` tuples, None where an env was reset), ``is_success``,
  ``violation`` (bool), each with its ``_key`` mask. Added: ``info["transition"]``, an
  ``(N, 3)`` int64 array of the transition ``(w, sigma, w')`` each env's action caused in
  this call, with ``info["_transition"]`` True where there is one. Rows of envs that did not
  step (every env on ``reset()``; under NEXT_STEP the envs reset instead of stepped) hold
  ``-1`` and their mask is False. Under SAME_STEP every env steps, so every row is set; for
  an env whose episode ended it is the final step's transition (also in ``final_info``).
* Autoreset as ``SyncVectorEnv``: ``autoreset_mode=`` ``"NextStep"`` (the default: the
  step after an episode's end resets that env, reward 0, and its info is the reset's) or
  ``"SameStep"`` (ended envs reset at once; the observation returned is the new episode's,
  ``info["final_obs"]`` is an object array holding the last observation of each ended env
  (None elsewhere), ``info["final_info"]`` the aggregated infos of the ended envs (with
  their ``_key`` masks); ``_final_obs`` / ``_final_info`` mark the ended envs; the keys are
  absent on steps where no episode ended). ``metadata["autoreset_mode"]`` says which.
* ``reset(seed=s)`` seeds env i with ``s + i``; a list seeds each env; ``options=
  {"reset_mask": mask}`` resets only the masked envs, as ``SyncVectorEnv`` does.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..names import unknown_keywords
from ..spec import TaskSpec
from ..wrappers import AutomatonObservation
from .cells import EMPTY, MOVES
from .grid import GridWorldEnv
from .kinematic import KinematicWorldEnv
from .planar import touch_slots, within_boxes

_NO_TRANSITION = -1  # info["transition"] rows of envs that did not step


class CraftVectorEnv(VectorEnv):
    """What the vectorized worlds share: seeds, resets through the template world, the
    automaton for all envs, truncation, autoreset and infos. Subclasses hold the world's
    state as (N, ...) arrays and define ``_check_actions``, ``_load(i)`` (copy the template's
    fresh episode into env i) and ``_move(actions, active)`` (step the world of the
    ``active`` envs: rewards and label masks, before the automaton)."""

    def __init__(self, template: gym.Env, num_envs: int, product: bool,
                 max_episode_steps: int | None, autoreset_mode: str | AutoresetMode):
        check_num_envs(num_envs)  # the one check of every vectorization mode (craftsuite.make_vec)
        check_world_values({"product": product, "max_episode_steps": max_episode_steps})
        try:
            mode = AutoresetMode(autoreset_mode)
        except ValueError:
            raise ValueError(f"autoreset_mode {autoreset_mode!r} is not supported; use "
                             f"{AutoresetMode.NEXT_STEP.value!r} or {AutoresetMode.SAME_STEP.value!r}") from None
        if mode is AutoresetMode.DISABLED:
            raise ValueError("autoreset_mode 'Disabled' is not supported; use 'NextStep' or 'SameStep'")
        self.world = template  # draws every layout; never stepped
        self.task = template.task
        self.num_envs = n = num_envs
        self.product = product
        self.max_episode_steps = max_episode_steps
        self.autoreset_mode = mode
        self.metadata = {"render_modes": [], "autoreset_mode": mode}
        self.render_mode = None
        self.rules, self.labeller = template.rules, template.labeller
        automaton = self.automaton = template.automaton
        self._delta = automaton.delta.astype(np.int64)
        self._accepting = automaton.accepting.astype(bool)
        self._rejecting = automaton.rejecting.astype(bool)
        self._initial = int(automaton.initial)
        self._completion = float(self.task.completion_reward)
        self._step_reward = float(self.task.step_reward)
        # whether acceptance and violation end an episode (with the completion reward), or
        # only the world does (``_world_ended``, set by ``_move``: the kinematic board's tiles)
        self._objective_ends = True
        self._world_ended = np.zeros(num_envs, dtype=bool)

        # the single env's spaces, the product one built by the wrapper itself
        space = AutomatonObservation(template).observation_space if product else template.observation_space
        self.single_observation_space = space
        self.observation_space = batch_space(space, n)
        self.single_action_space = template.action_space
        self.action_space = batch_space(template.action_space, n)
        self._base = template.observation_space.shape[0]  # where the one-hot starts
        self._obs = np.zeros((n, space.shape[0]), dtype=np.float32)
        self._one_hot = np.eye(automaton.n_states, dtype=np.float32)

        self._rngs: list[np.random.Generator | None] = [None] * n
        self._inventories = [self.rules.new_inventory() for _ in range(n)]
        self._levels = np.zeros(n, dtype=np.int64)  # the inventory's level bits, per env
        self._state = np.full(n, self._initial, dtype=np.int64)
        self._elapsed = np.zeros(n, dtype=np.int64)
        self._autoreset = np.zeros(n, dtype=bool)
        self._started = np.zeros(n, dtype=bool)  # reset at least once
        # label tuples by mask, filled as masks occur (the table is as wide as delta's rows)
        self._label_table = np.full(self._delta.shape[1], None, dtype=object)
        self._known_labels = np.zeros(self._delta.shape[1], dtype=bool)

    # -- subclass hooks ------------------------------------------------------------------------------
    def _check_actions(self, actions) -> np.ndarray:
        raise NotImplementedError

    def _load(self, i: int) -> None:
        raise NotImplementedError

    def _move(self, actions: np.ndarray, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    # -- episodes ------------------------------------------------------------------------------------
    def _reset_env(self, i: int, seed: int | None = None) -> None:
        """Env i's next episode: the template world draws it from env i's generator (seeded
        as ``gym.Env.reset(seed=...)`` seeds, or created unseeded on first use)."""
        if seed is not None:
            self._rngs[i] = seeding.np_random(seed)[0]
        elif self._rngs[i] is None:
            self._rngs[i] = seeding.np_random()[0]
        world = self.world
        world.np_random = self._rngs[i]
        world.reset()
        self._inventories[i] = self.rules.new_inventory()
        self._levels[i] = self.labeller.levels(self._inventories[i])
        self._obs[i, :self._base] = world._obs
        self._load(i)
        self._state[i] = self._initial
        self._elapsed[i] = 0
        self._autoreset[i] = False
        self._started[i] = True

    def reset(self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None):
        """Reset every env (or those of ``options["reset_mask"]``); ``seed`` as SyncVectorEnv
        takes it: None, an int ``s`` (env i gets ``s + i``) or one seed per env."""
        n = self.num_envs
        if seed is None:
            seeds = [None] * n
        elif _seed(seed) is not None:
            seeds = [_seed(seed) + i for i in range(n)]
        elif isinstance(seed, Sequence | np.ndarray) and not isinstance(seed, str | bytes):
            seeds = [None if s is None else _seed(s) for s in seed]
            if len(seeds) != n:
                raise ValueError(f"reset(seed=...) got {len(seeds)} seeds for num_envs={n}")
            bad = next((i for i, s in enumerate(seeds) if s is None and seed[i] is not None), None)
            if bad is not None:
                raise ValueError(f"reset(seed=...)'s seed {bad} is {seed[bad]!r}: each is None or an integer >= 0")
        else:
            raise ValueError(f"reset(seed=...) takes None, an integer or one seed per env, got {seed!r}")
        rows = np.ones(n, dtype=bool)
        if options and "reset_mask" in options:
            rows = np.asarray(options["reset_mask"])
            if rows.shape != (n,) or rows.dtype != np.bool_ or not rows.any():
                raise ValueError(f"options['reset_mask'] must be a bool array of shape ({n},) with a True, "
                                 f"got {options['reset_mask']!r}")
        for i in np.flatnonzero(rows).tolist():
            self._reset_env(i, seeds[i])
        self._write_one_hot()
        none = np.zeros(n, dtype=np.int64)  # no labels, states or transitions yet
        infos = self._infos(rows, none, none, none, np.zeros(n, bool), np.zeros(n, bool),
                            stepped=np.zeros(n, dtype=bool))
        return self._obs.copy(), infos

    def step(self, actions):
        if not self._started.all():
            raise RuntimeError(f"call reset() before step(): envs {np.flatnonzero(~self._started).tolist()} "
                               "were never reset")
        actions = self._check_actions(actions)
        n = self.num_envs
        same_step = self.autoreset_mode is AutoresetMode.SAME_STEP
        # NEXT_STEP: envs whose episode ended last call reset now instead of stepping
        active = np.ones(n, dtype=bool) if same_step else ~self._autoreset
        rewards, masks = self._move(actions, active)

        w = self._state
        w2 = np.where(active, self._delta[w, masks], w)
        success = self._accepting[w2] & active
        violation = self._rejecting[w2] & active
        terminated = self._world_ended & active
        if self._objective_ends:
            rewards += np.where(success, self._completion, 0.0)  # reward + bonus, as the single env adds them
            terminated |= success | violation
        else:  # success is completion: the world ended the episode with the objective met
            success &= terminated
        self._elapsed += active
        truncated = active & (self._elapsed >= self.max_episode_steps) if self.max_episode_steps \
            else np.zeros(n, dtype=bool)
        self._state = w2.copy()  # resets below rewrite the state; w2 stays the step's
        self._write_one_hot()
        ended = terminated | truncated

        infos: dict[str, Any] = {}
        if same_step:
            reset = ended
            if ended.any():
                infos = self._final(ended, masks, w, w2, success, violation)
        else:
            reset = ~active
            rewards[reset] = 0.0
        for i in np.flatnonzero(reset).tolist():
            self._reset_env(i)
        if reset.any():
            self._write_one_hot()
        self._autoreset = ended.copy() if not same_step else np.zeros(n, dtype=bool)
        infos.update(self._infos(np.ones(n, dtype=bool), masks, w, w2, success, violation,
                                 stepped=active, fresh=reset))
        return self._obs.copy(), rewards, terminated, truncated, infos

    def _write_one_hot(self) -> None:
        if self.product:
            self._obs[:, self._base:] = self._one_hot[self._state]

    # -- infos ---------------------------------------------------------------------------------------
    def _label_names(self, masks: np.ndarray) -> np.ndarray:
        """The label tuples of ``masks`` as an object array (the tuples cached per mask, as the
        single env caches them)."""
        known = self._known_labels
        if not known[masks].all():
            for m in np.unique(masks[~known[masks]]).tolist():
                self._label_table[m] = self.labeller.names(m)
                known[m] = True
        return self._label_table[masks]

    def _infos(self, rows, masks, w, w2, success, violation, stepped, fresh=None) -> dict[str, Any]:
        """The infos SyncVectorEnv would aggregate for the envs in ``rows``: a step's for the
        ``stepped`` envs, a reset's (``ObjectiveTracker.reset``) for the ``fresh`` ones."""
        n = self.num_envs
        fresh = ~stepped if fresh is None else fresh
        plain = stepped & ~fresh & rows  # entries holding the step's values
        labels = self._label_names(masks)
        transitions = np.fromiter(zip(w.tolist(), masks.tolist(), w2.tolist()), dtype=object, count=n)
        if not plain.all():
            labels[~plain] = None
            transitions[~plain] = None
            for i in np.flatnonzero(rows & ~plain).tolist():
                labels[i] = ()  # a reset's labels
        reset_rows = rows & ~plain
        state = np.where(plain, w2, np.where(reset_rows, self._initial, 0))
        # the engine's transition array: what each env's action did, whatever reset came after
        transition = np.stack([w, masks, w2], axis=1)
        transition[~stepped] = _NO_TRANSITION
        return {
            "labels": labels, "_labels": rows.copy(),
            "label_mask": np.where(plain, masks, 0), "_label_mask": rows.copy(),
            "automaton_state": state, "_automaton_state": rows.copy(),
            "automaton_transition": transitions, "_automaton_transition": rows.copy(),
            "is_success": success & plain, "_is_success": rows.copy(),
            "violation": violation & plain, "_violation": rows.copy(),
            "transition": transition, "_transition": stepped.copy(),
        }

    def _final(self, ended, masks, w, w2, success, violation) -> dict[str, Any]:
        """SAME_STEP's ``final_obs`` and ``final_info`` of the ended envs, built with
        gymnasium's own aggregation from each env's single-env info."""
        infos: dict[str, Any] = {}
        for i in np.flatnonzero(ended).tolist():
            m = int(masks[i])
            info = {"labels": self._label_names(masks[i:i + 1])[0], "label_mask": m, "automaton_state": int(w2[i]),
                    "automaton_transition": (int(w[i]), m, int(w2[i])),
                    "is_success": bool(success[i]), "violation": bool(violation[i])}
            infos = self._add_info(infos, {"final_obs": self._obs[i].copy(), "final_info": info}, i)
        return infos

    def render(self):
        raise NotImplementedError(
            f"{type(self).__name__} does not render; make the single env to render "
            "(gymnasium.make(id, render_mode='rgb_array'))")


def _seed(value) -> int | None:
    """``value`` as a reset seed (an integer >= 0, numpy's too: gymnasium's seeding takes
    Python's alone), else None."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 0:
        return None
    return int(value)


def check_num_envs(num_envs) -> None:
    """Raise a ValueError unless ``num_envs`` is a positive integer (every vectorization mode)."""
    if not isinstance(num_envs, int) or isinstance(num_envs, bool) or num_envs < 1:
        raise ValueError(f"num_envs must be a positive integer, got {num_envs!r}")


_TRUTHS = {"product": "whether the observation has the automaton state's one-hot",
           "disable_env_checker": "whether gymnasium skips its env checker"}


def check_world_values(kwargs: dict, prefix: str = "") -> None:
    """Raise a ValueError naming a world keyword's value of the wrong kind: ``product`` and
    ``disable_env_checker`` True or False ("no" or 0 would pass as a truth value),
    ``max_episode_steps`` a positive integer or None (gymnasium's own message names no flag);
    for single and vector worlds alike."""
    for name, what in _TRUTHS.items():
        if not isinstance(kwargs.get(name, False), bool):
            raise ValueError(f"{prefix}{name} must be True or False ({what}), got {kwargs[name]!r}")
    steps = kwargs.get("max_episode_steps")
    if steps is not None and (isinstance(steps, bool) or not isinstance(steps, int) or steps < 1):
        raise ValueError(f"{prefix}max_episode_steps must be a positive integer (the decisions before an episode is "
                         f"cut short), got {steps!r}")


def _check_kwargs(world: str, kwargs: dict, accepted: tuple[str, ...]) -> None:
    unknown = sorted(set(kwargs) - set(accepted))
    if unknown:
        raise ValueError(unknown_keywords(unknown, accepted, f"the vectorized {world} world"))
    if kwargs.get("render_mode") is not None:
        raise ValueError(f"render_mode={kwargs['render_mode']!r}: the vectorized {world} world does not render; "
                         "make the single env to render (gymnasium.make(id, render_mode=...))")


class GridVectorEnv(CraftVectorEnv):
    """``num_envs`` grid episodes of one task (see ``GridWorldEnv`` for the world): agent
    cells as an (N,) array, the objects on the cells as an (N, cells) array."""

    # single-env keywords; width/height/status_panel only shape frames, which this does not draw
    KEYWORDS = ("product", "layout_seed", "render_mode", "status_panel", "max_episode_steps", "autoreset_mode")

    def __init__(self, num_envs: int, task: str | TaskSpec = "BlindCraftsman", size: int = 7,
                 product: bool = False, layout_seed: int | None = None, max_episode_steps: int | None = None,
                 autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP, **kwargs):
        _check_kwargs("grid", kwargs, self.KEYWORDS)
        kwargs.pop("render_mode", None)
        template = GridWorldEnv(task, size, layout_seed=layout_seed, **kwargs)
        super().__init__(template, num_envs, product, max_episode_steps, autoreset_mode)
        self.size = size
        self._n_cells = size * size
        self.inv_offset = template.inv_offset
        self.inv_scale = template.inv_scale
        self._cells = np.full((num_envs, self._n_cells), EMPTY, dtype=np.int16)
        self._agent = np.zeros(num_envs, dtype=np.int64)
        self._rows = np.arange(num_envs)
        self._next_cell = self._move_table(size, template.obstacles)

    @staticmethod
    def _move_table(size: int, obstacles: list[int]) -> np.ndarray:
        """``[cell, action]`` -> the cell the agent ends in: itself where the move would leave
        the grid or enter an obstacle (obstacles never move, so the table holds for every
        episode)."""
        table = np.empty((size * size, len(MOVES)), dtype=np.int64)
        walls = set(obstacles)
        for cell in range(size * size):
            y, x = divmod(cell, size)
            for a, (dx, dy) in MOVES.items():
                nx, ny = x + dx, y + dy
                inside = 0 <= nx < size and 0 <= ny < size and ny * size + nx not in walls
                table[cell, a] = ny * size + nx if inside else cell
        return table

    def _load(self, i: int) -> None:
        self._cells[i] = self.world._cells
        self._agent[i] = self.world._agent

    def _check_actions(self, actions) -> np.ndarray:
        a = np.asarray(actions)
        if a.shape != (self.num_envs,) or a.dtype.kind not in "iu" or ((a < 0) | (a >= len(MOVES))).any():
            raise ValueError(f"invalid actions {actions!r} for {self.num_envs} {self.task.name} grids: expected "
                             f"an integer array of shape ({self.num_envs},) with values in [0, {len(MOVES)})")
        return a.astype(np.int64, copy=False)

    def _move(self, actions, active):
        """``GridWorldEnv.step`` for the active envs, up to the automaton."""
        rows, obs, agent = self._rows, self._obs, self._agent
        target = self._next_cell[agent, actions]
        moved = active & (target != agent)
        m = np.flatnonzero(moved)
        obs[m, agent[m]] = 0.0
        obs[m, target[m]] = 1.0
        agent[m] = target[m]

        rewards = np.full(self.num_envs, self._step_reward)
        masks = self._levels.copy()
        kinds = self._cells[rows, agent]
        # the agent stands on an object: the rare case, done per env with the shared rules
        for i in np.flatnonzero(active & (kinds >= 0)).tolist():
            self._touch(i, int(kinds[i]), bool(moved[i]), rewards, masks)
        return rewards, masks

    def _touch(self, i: int, kind: int, moved: bool, rewards: np.ndarray, masks: np.ndarray) -> None:
        """The object part of ``GridWorldEnv.step`` for env i."""
        inv, rules, labeller = self._inventories[i], self.rules, self.labeller
        outcome = rules.touch(inv, kind, moved)
        arrived = kind if moved and kind >= rules.n_items else -1
        if outcome is not None:
            rewards[i] += outcome.reward
            cell = int(self._agent[i])
            if outcome.consumed:
                self._cells[i, cell] = EMPTY
                self._obs[i, (2 + kind) * self._n_cells + cell] = 0.0
            off, scale = self.inv_offset, self.inv_scale
            for s, count in enumerate(inv):
                self._obs[i, off + s] = count / scale[s]
            self._levels[i] = labeller.levels(inv)
            masks[i] = labeller(inv, outcome.gained, arrived)
        elif arrived >= 0:
            masks[i] = labeller(inv, 0, arrived)


class PlanarVectorEnv(CraftVectorEnv):
    """What the kinematic board's and the MuJoCo world's vector envs share, as their single
    worlds share ``PlanarWorld``: two numbers an action (``WHAT`` they are); and for the
    MuJoCo world, the rules' reading of a touch (``_touch``; the board acts through its
    ``BoardRules``). Subclasses keep (N, n_objects) ``_present`` arrays (and ``_inside``
    where ``_touch`` is used) and define ``_remove(i, j)``: what consuming slot j of env i
    changes besides ``_present``."""

    WHAT = "displacement"

    def _check_actions(self, actions) -> np.ndarray:
        try:
            a = np.asarray(actions, dtype=np.float64)
        except (TypeError, ValueError):
            a = None
        if a is None or a.shape != (self.num_envs, 2):
            raise ValueError(f"invalid actions {actions!r}: expected {self.num_envs} rows of 2 numbers "
                             f"({self.WHAT} along x and y) in [-1, 1]")
        if not np.isfinite(a).all():
            raise ValueError(f"invalid actions: NaN or infinite {self.WHAT} in rows "
                             f"{np.flatnonzero(~np.isfinite(a).all(axis=1)).tolist()}")
        return np.clip(a, -1.0, 1.0)

    def _remove(self, i: int, j: int) -> None:
        """What else consuming slot ``j`` of env ``i`` changes."""

    def _touch(self, i: int, inside: np.ndarray, rewards: np.ndarray, masks: np.ndarray) -> None:
        """``PlanarWorld._touch`` for env i: items within reach, places on entering."""
        inv, rules, labeller = self._inventories[i], self.rules, self.labeller

        def consume(j: int) -> None:
            self._present[i, j] = False
            self._remove(i, j)

        reward, gained, arrived, touched = touch_slots(rules, inv, self.kinds, self.is_item, inside,
                                                       self._inside[i], float(rewards[i]), consume)
        rewards[i] = reward
        if touched:
            scale, off = rules.scale, self.inv_offset
            for s, count in enumerate(inv):
                self._obs[i, off + s] = count / scale[s]
            self._levels[i] = labeller.levels(inv)
        if touched or arrived >= 0:
            masks[i] = labeller(inv, gained, arrived)


class KinematicVectorEnv(PlanarVectorEnv):
    """``num_envs`` episodes on the kinematic board (see ``KinematicWorldEnv``): positions
    as (N, 2), object slots as (N, n_objects) arrays. Motion, reach and observations are
    numpy over all envs; the envs with an object in reach go through ``BoardRules`` in
    Python, as the single world does."""

    KEYWORDS = ("product", "render_mode", "width", "height", "status_panel", "size", "observation",
                "max_episode_steps", "autoreset_mode")

    def __init__(self, num_envs: int, task: str | TaskSpec = "BlindCraftsman", product: bool = False,
                 max_episode_steps: int | None = None,
                 autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP, **kwargs):
        _check_kwargs("kinematic", kwargs, self.KEYWORDS)
        kwargs.pop("render_mode", None)
        template = KinematicWorldEnv(task, **kwargs)
        super().__init__(template, num_envs, product, max_episode_steps, autoreset_mode)
        n_obj = len(template.kinds)
        self.board = template.board
        self._objective_ends = not self.board.ends_by_tile
        self.kinds = list(template.kinds)
        self.cell_bits = template.cell_bits
        self._boxes = template.obstacles
        self.arena, self.half = template.arena, template.half
        self._authors = template.observation == "authors"
        self.radius2 = template.radius ** 2
        self._step_size = template.step_size
        self.boundary_reward = template.boundary_reward
        self.inv_offset = template.inv_offset
        self._scale = np.array(self.rules.scale)
        self._position = np.zeros((num_envs, 2))
        self._positions = np.zeros((num_envs, n_obj, 2))
        self._present = np.zeros((num_envs, n_obj), dtype=bool)

    def _load(self, i: int) -> None:
        world = self.world
        self._position[i] = world._position
        self._positions[i] = world._positions
        self._present[i] = True

    def _move(self, actions, active):
        """``KinematicWorldEnv.step`` for the active envs, up to the automaton."""
        target = self._position + self._step_size * actions
        on = active & (target >= 0.0).all(axis=1) & (target < self.arena).all(axis=1)
        if len(self._boxes):
            on &= ~within_boxes(target, self._boxes)
        rewards = np.full(self.num_envs, self._step_reward)
        masks = self._levels.copy()
        ended = self._world_ended
        ended[:] = False
        # the authors reject a move off the board: the agent stays and touches nothing
        rewards[active & ~on] += self.boundary_reward
        self._position[on] = target[on]
        offsets = self._positions - self._position[:, None, :]
        inside = self._present & (np.einsum("nij,nij->ni", offsets, offsets) < self.radius2)
        inside &= on[:, None]
        board, labeller, kinds = self.board, self.labeller, self.kinds
        for i in np.flatnonzero(inside.any(axis=1)).tolist():
            inv = self._inventories[i]
            j, outcome = board.first_acting(inv, [(j, kinds[j]) for j in np.flatnonzero(inside[i]).tolist()])
            if outcome is None:
                continue
            rewards[i] += outcome.reward
            ended[i] = outcome.ends_episode
            if outcome.consumed:
                self._present[i, j] = False
            self._levels[i] = labeller.levels(inv)
            masks[i] = labeller(inv, outcome.gained, outcome.arrived)
            off = self.inv_offset
            self._obs[i, off:off + len(inv)] = inv if self._authors else np.asarray(inv) / self._scale
        if self.cell_bits:
            cell = np.floor(self._position)
            for bit, j in self.cell_bits:
                here = self._present[:, j] & (np.floor(self._positions[:, j]) == cell).all(axis=1)
                masks[here] |= bit
        self._write_observation(offsets)
        return rewards, masks

    def _write_observation(self, offsets: np.ndarray) -> None:
        """``KinematicWorldEnv._write_observation`` for all envs (the inventory is written on
        acts and resets, the only times it changes)."""
        obs, n_obj, present = self._obs, len(self.kinds), self._present
        if self._authors:
            obs[:, 0:2] = self._position / self.arena
            obs[:, 2:2 + n_obj] = np.where(present, np.sqrt((offsets ** 2).sum(axis=2)) / self.arena, 0.0)
            return
        obs[:, 0:2] = self._position / self.half - 1.0
        obs[:, 2:2 + 3 * n_obj:3] = np.where(present, offsets[..., 0] / self.arena, 0.0)
        obs[:, 3:3 + 3 * n_obj:3] = np.where(present, offsets[..., 1] / self.arena, 0.0)
        obs[:, 4:4 + 3 * n_obj:3] = present


def make_grid_vector(num_envs: int, **kwargs) -> GridVectorEnv:
    """Vector entry point of the grid ids (``gymnasium.make_vec(..., vectorization_mode=
    "vector_entry_point")``): the spec's ``task`` and ``size``, ``max_episode_steps``,
    and the single id's keywords."""
    return GridVectorEnv(num_envs, **kwargs)


def make_kinematic_vector(num_envs: int, **kwargs) -> KinematicVectorEnv:
    """Vector entry point of the kinematic ids."""
    return KinematicVectorEnv(num_envs, **kwargs)
