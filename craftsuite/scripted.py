"""Scripted policies: go to the next object the objective needs.

``ObjectivePlanner`` knows only the task spec, its rules and its automaton, so it works
for user-written tasks too. It searches breadth first over abstract states (automaton
state, inventory, items left per kind) whose moves are "touch an object of kind k", and
returns the first kind on a shortest route to acceptance. ``GridScriptedPolicy`` walks
there on a grid, stepping only on cells whose object leaves the automaton where it is.
"""

from __future__ import annotations

from collections import deque

from .labelling import Labeller
from .rendering.grid import WALL
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


class GridScriptedPolicy:
    """Acts in a ``GridWorldEnv`` (its ``unwrapped``): ``policy(obs) -> action``."""

    def __init__(self, env):
        self.env = env.unwrapped
        self.planner = ObjectivePlanner(self.env.task)

    def __call__(self, observation=None) -> int:
        env = self.env
        inv, w, cells = tuple(env.inventory_counts), env.automaton_state, env._cells
        remaining = [0] * len(env.task.objects)
        for kind in cells:
            if kind >= 0:
                remaining[kind] += 1
        for k in range(env.rules.n_items, len(remaining)):
            remaining[k] = max(remaining[k], 1)  # places are never used up
        return self.toward(self.planner.next_kind(w, inv, remaining))

    def toward(self, target: int | None) -> int:
        """A step towards the nearest object of kind ``target``, through harmless cells."""
        env = self.env
        size, cells, agent = env.size, env._cells, env._agent
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


_STEPS = ((0, 0, -1), (1, 1, 0), (2, 0, 1), (3, -1, 0))  # action, dx, dy


def _bfs_first_step(size, cells, start, goals, blocked) -> int | None:
    """First action of a shortest path from ``start`` to any goal cell, or None."""
    if not goals:
        return None
    first = {start: None}
    queue = deque([start])
    while queue:
        cell = queue.popleft()
        y, x = divmod(cell, size)
        for action, dx, dy in _STEPS:
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


def run_episode(env, policy, seed: int | None = None, max_steps: int = 10_000):
    """Roll out ``policy`` until the episode ends: (total reward, steps, last info)."""
    obs, info = env.reset(seed=seed)
    total, steps = 0.0, 0
    for steps in range(1, max_steps + 1):
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        total += float(reward)
        if terminated or truncated:
            break
    return total, steps, info


__all__ = ["ObjectivePlanner", "GridScriptedPolicy", "run_episode"]
