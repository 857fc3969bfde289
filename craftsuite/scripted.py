"""Scripted policies: go to the next object the objective needs.

``ObjectivePlanner`` knows only the task spec, its rules and its automaton, so it works
for user-written tasks too. It searches breadth first over abstract states (automaton
state, inventory, items left per kind) whose moves are "touch an object of kind k", and
returns the first kind on a shortest route to acceptance. ``GridScriptedPolicy`` walks
there on a grid, stepping only on cells whose object leaves the automaton where it is.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from .envs.cells import MOVES, WALL
from .labelling import Labeller
from .rules import Rules
from .spec import TaskSpec


class ObjectivePlanner:
    def __init__(self, spec: TaskSpec):
        self.spec = spec
        self.rules = Rules(spec)
        self.automaton = spec.automaton
        self.labeller = Labeller(spec, self.automaton.propositions)
        self._plans: dict[tuple, int | None] = {}

    def touch(self, w: int, inv: tuple[int, ...], kind: int) -> tuple[int, tuple[int, ...], bool]:
        """Simulate entering an object of ``kind``: (next automaton state, inventory, consumed)."""
        new = list(inv)
        outcome = self.rules.touch(new, kind, arrived=True)
        arrived = kind if self.rules.is_place(kind) else -1
        gained = outcome.gained if outcome else 0
        mask = self.labeller(new, gained, arrived)
        return self.automaton.step(w, mask), tuple(new), bool(outcome and outcome.consumed)

    def harmless(self, w: int, inv: tuple[int, ...], kind: int) -> bool:
        """Stepping on ``kind`` now leaves the automaton state unchanged."""
        return self.touch(w, inv, kind)[0] == w

    def next_kind_in(self, env) -> int | None:
        """The next kind to touch in a world (its ``unwrapped``)."""
        return self.next_kind(env.automaton_state, env.inventory_counts, env.remaining_counts())

    def next_kind(self, w: int, inv, remaining) -> int | None:
        """The object kind to touch next on a shortest route to acceptance (None: no route)."""
        start = (w, tuple(inv), tuple(remaining))
        if start in self._plans:
            return self._plans[start]
        accepting, rejecting = self.automaton.accepting, self.automaton.rejecting
        first: dict[tuple, int | None] = {start: None}
        queue = deque([start])
        answer = None
        while queue and answer is None:
            state = queue.popleft()
            sw, sinv, srem = state
            for kind in range(len(self.spec.objects)):
                if srem[kind] == 0:
                    continue
                w2, inv2, consumed = self.touch(sw, sinv, kind)
                if rejecting[w2] or (w2 == sw and inv2 == sinv):
                    continue
                rem2 = srem if not consumed else srem[:kind] + (srem[kind] - 1,) + srem[kind + 1:]
                nxt = (w2, inv2, rem2)
                if nxt in first:
                    continue
                first[nxt] = kind if state == start else first[state]
                if accepting[w2]:
                    answer = first[nxt]
                    break
                queue.append(nxt)
        self._plans[start] = answer
        return answer


class ScriptedPolicy:
    """A policy that heads for the next object its planner names: ``policy(obs) -> action``
    (the observation is not read: it acts on the world, ``env.unwrapped``). Subclasses
    define ``toward(kind)`` for their world's moves."""

    def __init__(self, env):
        self.env = env.unwrapped
        self.planner = ObjectivePlanner(self.env.task)

    def __call__(self, observation=None):
        return self.toward(self.planner.next_kind_in(self.env))


class GridScriptedPolicy(ScriptedPolicy):
    """Acts in a ``GridWorldEnv`` (its ``unwrapped``): ``policy(obs) -> action``."""

    def toward(self, target: int | None) -> int:
        """A step towards the nearest object of kind ``target``, through harmless cells."""
        env = self.env
        size, cells = env.size, env.cells
        x, y = env.agent_position
        agent = y * size + x
        if target is None:
            return int(env.np_random.integers(4))
        w, inv = env.automaton_state, tuple(env.inventory_counts)
        safe = {k: self.planner.harmless(w, inv, k) for k in range(len(env.task.objects))}
        goals = {c for c, k in enumerate(cells) if k == target and c != agent}

        def unsafe(k):
            return k == WALL or (k >= 0 and not safe[k] and k != target)

        step = _bfs_first_step(size, cells, agent, goals, unsafe)
        if step is None:  # only unsafe paths: accept any non-wall route
            step = _bfs_first_step(size, cells, agent, goals, lambda k: k == WALL)
        return int(env.np_random.integers(4)) if step is None else step


def _bfs_first_step(size, cells, start, goals, blocked) -> int | None:
    """First action of a shortest path from ``start`` to any goal cell, or None."""
    if not goals:
        return None
    first = {start: None}
    queue = deque([start])
    while queue:
        cell = queue.popleft()
        y, x = divmod(cell, size)
        for action, (dx, dy) in MOVES.items():
            nx, ny = x + dx, y + dy
            if not (0 <= nx < size and 0 <= ny < size):
                continue
            nxt = ny * size + nx
            if nxt in first:
                continue
            if nxt in goals:
                return action if cell == start else first[cell]
            if blocked(cells[nxt]):
                continue
            first[nxt] = action if cell == start else first[cell]
            queue.append(nxt)
    return None


class ContinuousScriptedPolicy(ScriptedPolicy):
    """Acts in a ``ContinuousWorldEnv``: ``policy(obs) -> thrust``.

    Paths come from a breadth-first search on a 0.25 m occupancy grid: walls and
    obstacles (grown by the agent's size), and the pickup zones of objects that would
    change the automaton state (grown by a safety margin), are blocked. The agent steers
    for a cell a few steps down the path with a velocity controller.
    """

    CELL = 0.25
    LOOKAHEAD = 3

    def __init__(self, env):
        from .envs.scene import AGENT_HALF

        super().__init__(env)
        e = self.env
        self.n = int(np.ceil(e.arena / self.CELL))
        centres = (np.arange(self.n) + 0.5) * (e.arena / self.n) - e.half
        self.cx, self.cy = np.meshgrid(centres, centres, indexing="xy")  # [row=y index, col=x]
        grow = AGENT_HALF + 0.05
        static = (np.abs(self.cx) > e.half - grow) | (np.abs(self.cy) > e.half - grow)
        for x, y, h in e.scene.obstacles:
            static |= (np.abs(self.cx - x) < h + grow) & (np.abs(self.cy - y) < h + grow)
        self.static = static

    def cell_of(self, p) -> tuple[int, int]:
        e = self.env
        ix = int(np.clip((p[0] + e.half) / e.arena * self.n, 0, self.n - 1))
        iy = int(np.clip((p[1] + e.half) / e.arena * self.n, 0, self.n - 1))
        return iy, ix

    def toward(self, target: int | None) -> np.ndarray:
        """Thrust towards the nearest object of kind ``target``, around unsafe zones."""
        from .envs.continuous import TOP_SPEED

        e = self.env
        if target is None:
            return np.zeros(2, dtype=np.float32)
        pos, vel = e.data.qpos[:2].copy(), e.data.qvel[:2].copy()
        w, inv = e.automaton_state, tuple(e.inventory_counts)
        objects = e.objects
        kinds, present, positions = objects.kinds, objects.present, objects.positions
        # a place acts on entering: instances we stand in do not count until we leave them
        goal_objects = np.flatnonzero((kinds == target) & present & ~objects.inside)
        if len(goal_objects) == 0:
            near = np.flatnonzero((kinds == target) & present)
            if len(near) == 0:
                return np.zeros(2, dtype=np.float32)
            away = pos - positions[near[0]]
            return self._steer(away / (np.linalg.norm(away) + 1e-9) * TOP_SPEED, vel)
        unsafe = [i for i in np.flatnonzero(present)
                  if kinds[i] != target and not self.planner.harmless(w, inv, int(kinds[i]))]
        blocked = self.static.copy()
        for i in unsafe:
            ox, oy = positions[i]
            blocked |= (self.cx - ox) ** 2 + (self.cy - oy) ** 2 < (e.radius + 0.3) ** 2
        goal = np.zeros_like(blocked)
        for i in goal_objects:
            gx, gy = positions[i]
            goal |= (self.cx - gx) ** 2 + (self.cy - gy) ** 2 < (0.6 * e.radius) ** 2
        path = _grid_path(blocked, goal, self.cell_of(pos)) or _grid_path(self.static, goal, self.cell_of(pos))
        if path is None or len(path) <= self.LOOKAHEAD:
            dists = np.linalg.norm(positions[goal_objects] - pos, axis=1)
            aim = positions[goal_objects[dists.argmin()]]
        else:
            iy, ix = path[self.LOOKAHEAD]
            aim = np.array([self.cx[iy, ix], self.cy[iy, ix]])
        offset = aim - pos
        dist = np.linalg.norm(offset)
        desired = offset / (dist + 1e-9) * TOP_SPEED * min(1.0, dist / 0.3 + 0.3)
        return self._steer(desired, vel)

    @staticmethod
    def _steer(desired, vel) -> np.ndarray:
        from .envs.continuous import TOP_SPEED

        thrust = desired / TOP_SPEED + 0.5 * (desired - vel) / TOP_SPEED
        return np.clip(thrust, -1, 1).astype(np.float32)


class KinematicScriptedPolicy(ScriptedPolicy):
    """Acts in a ``KinematicWorldEnv``: ``policy(obs) -> displacement``.

    Moves are jumps (only where one ends counts), so no path search: jump onto the nearest
    object of the kind the planner names when it is in reach, else to the point in reach
    (on a 25 x 25 lattice of moves) nearest to it (Chebyshev: a jump covers a square) whose
    end touches no object that would change the automaton state.
    """

    def __init__(self, env):
        super().__init__(env)
        axis = np.linspace(-1.0, 1.0, 25)
        # float32, the actions' type: ends are checked where the world will put them
        self._moves = np.array([(x, y) for x in axis for y in axis], dtype=np.float32)

    def __call__(self, observation=None):
        target = self.planner.next_kind_in(self.env)
        if target is None and self.env.board.ends_by_tile:
            # the objective may be met before the episode ends (the authors' at_home is a
            # cell, their home a disc): go on to a tile that ends it
            inv = self.env.inventory_counts
            target = next((t.kind for t in self.env.board.tiles
                           if t.ends_episode and self.env.board.act(list(inv), t.kind)), None)
        return self.toward(target)

    def toward(self, target: int | None) -> np.ndarray:
        e = self.env
        if target is None:
            return np.zeros(2, dtype=np.float32)
        pos, w, inv = e.agent_position, e.automaton_state, tuple(e.inventory_counts)
        objects = e.objects
        kinds, present, positions, inside = objects.kinds, objects.present, objects.positions, objects.inside
        # on the board an item touched at capacity is lost: full items are unsafe too (an
        # item's inventory slot is its kind: spec.inventory lists the items first)
        full = {k for k in range(e.rules.n_items) if e.board.capacity[k] is not None and inv[k] >= e.board.capacity[k]}
        unsafe = [i for i in np.flatnonzero(present)
                  if (kinds[i] != target and not self.planner.harmless(w, inv, int(kinds[i]))) or kinds[i] in full]
        # a place acts on entering: an instance we stand in counts once we have left it
        goals = np.flatnonzero((kinds == target) & present & ~inside)
        avoid = positions[unsafe + np.flatnonzero((kinds == target) & inside).tolist()]
        if len(goals):
            aims = positions[goals]
            # objects on the board's edge (x or y = 0): aim 1e-4 inside, or the float32 action's
            # rounding (~1e-7 here) could end the jump just off the board, rejecting the move
            # (and 1e-3 up and right of the object, so that it ends in the object's cell, not
            # rounded down into the one below: a cell can be a label)
            aim = np.clip(aims[np.abs(aims - pos).max(axis=1).argmin()] + 1e-3, 1e-4, e.arena - 1e-4)
            if np.abs(aim - pos).max() <= e.step_size:  # in reach: land on it
                return ((aim - pos) / e.step_size).astype(np.float32)
        ends = pos + e.step_size * self._moves.astype(np.float64)
        ok = (ends >= 0).all(axis=1) & (ends < e.arena).all(axis=1) & ~e.in_obstacle(ends)
        if len(avoid):
            ok &= (np.linalg.norm(ends[:, None, :] - avoid[None, :, :], axis=2) >= e.radius + 0.05).all(axis=1)
        for i in unsafe:  # a place labelled by its cell is arrived at anywhere in the cell
            if e.board.tiles[kinds[i]].by_cell:
                ok &= (np.floor(ends) != np.floor(positions[i])).any(axis=1)
        if not ok.any():
            return np.zeros(2, dtype=np.float32)
        if len(goals):
            score = np.abs(ends - aim).max(axis=1) + 1e-3 * np.linalg.norm(ends - aim, axis=1)
        else:  # only instances we stand in: the shortest safe step out of them
            score = np.linalg.norm(self._moves, axis=1)
        score[~ok] = np.inf
        return self._moves[score.argmin()].copy()


def _grid_path(blocked: np.ndarray, goal: np.ndarray, start: tuple[int, int]):
    """Cells of a shortest 8-connected path from ``start`` into ``goal``, or None."""
    if not goal.any():
        return None
    rows, cols = blocked.shape
    parent = {start: None}
    queue = deque([start])
    while queue:
        cell = queue.popleft()
        if goal[cell]:
            path = []
            while cell is not None:
                path.append(cell)
                cell = parent[cell]
            return path[::-1]
        y, x = cell
        for dy, dx in ((0, 1), (1, 0), (0, -1), (-1, 0), (1, 1), (1, -1), (-1, 1), (-1, -1)):
            ny, nx = y + dy, x + dx
            if 0 <= ny < rows and 0 <= nx < cols and (ny, nx) not in parent and not blocked[ny, nx]:
                if dy and dx and (blocked[y, nx] or blocked[ny, x]):
                    continue  # no corner cutting past walls
                parent[(ny, nx)] = cell
                queue.append((ny, nx))
    return None


def scripted_policy(env):
    """The scripted policy for a CraftSuite world: grid, MuJoCo or kinematic."""
    from .envs.grid import GridWorldEnv
    from .envs.kinematic import KinematicWorldEnv

    if isinstance(env.unwrapped, KinematicWorldEnv):
        return KinematicScriptedPolicy(env)
    return GridScriptedPolicy(env) if isinstance(env.unwrapped, GridWorldEnv) else ContinuousScriptedPolicy(env)


__all__ = ["ObjectivePlanner", "GridScriptedPolicy", "ContinuousScriptedPolicy", "KinematicScriptedPolicy",
           "scripted_policy"]
