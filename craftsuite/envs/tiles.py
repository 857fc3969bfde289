"""The kinematic board's rules: the authors' tiles, read from a task spec.

The kinematic world follows the authors' ``MineWorldEnvContinuous``
(``discrete/lib/env/mineworldenv.py`` in adenm-10/Automaton_Distillation), whose objects are
tiles (``MineWorldTileType``) with their own mechanics, unlike the grid and MuJoCo worlds'
``Rules``:

- on every step, the first tile (board order) within reach whose requirements the inventory
  meets acts: its inventory change is applied once, each count clipped to its capacity
  (an item touched at capacity is still used up: a third wood held two at a time is lost);
  it pays its reward, leaves the board if consumable and ends the episode if terminal;
- a place acts on every step the agent stays in reach (a factory turns one wood into one
  tool per step), not once per arrival;
- a place with a fixed ``corner`` placement sits at (0, 0).

A spec says what its objects are; each object's ``kinematic`` table (``spec.BoardTile``)
adds what only the board reads (a place's requirement, reward, whether it ends the episode).
Board order is the authors' dict order: fixed tiles first, then the others in spec order.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..spec import TaskSpec


@dataclass(frozen=True)
class Tile:
    """One kind of object as a board tile; slots index the spec's inventory."""

    kind: int
    change: tuple[tuple[int, int], ...]  # (slot, delta): the authors' inventory_modifier
    requires: tuple[tuple[int, int], ...]  # (slot, at least)
    excludes: tuple[int, ...]  # slots that must be 0
    reward: float
    consumable: bool
    ends_episode: bool
    gains: int  # bits of the slots the change raises: what an ``obtained`` label reads
    by_cell: bool  # an ``arrived`` label reads the agent's cell, not the tile acting


@dataclass(frozen=True)
class Act:
    """What one tile acting did."""

    reward: float
    gained: int
    consumed: bool
    ends_episode: bool
    arrived: int  # the kind that acted, as ``Labeller`` reads ``arrived``; -1 for a place labelled by its cell


class BoardRules:
    """The tiles of one task and what acting on them does to an inventory."""

    def __init__(self, spec: TaskSpec):
        slot = {n: i for i, n in enumerate(spec.inventory)}
        self.capacity = [None] * len(slot)
        for item in spec.items:
            self.capacity[slot[item.name]] = item.capacity
        self.tiles: list[Tile] = []
        n_items = len(spec.items)
        for kind, obj in enumerate(spec.objects):
            t = obj.kinematic
            if kind < n_items:
                change = {obj.name: 1}
                requires = dict(obj.requires) if t.requires is None else dict(t.requires)
                excludes = tuple(slot[n] for n in obj.excludes)
                reward = obj.reward if t.reward is None else t.reward
                consumable = True if t.consumable is None else t.consumable
            else:
                change = {}
                for recipe in spec.recipes:
                    if recipe.at == obj.name:
                        for n, k in recipe.consume.items():
                            change[n] = change.get(n, 0) - k
                        for n, k in recipe.produce.items():
                            change[n] = change.get(n, 0) + k
                requires = dict(t.requires or {})
                excludes = ()
                reward = 0.0 if t.reward is None else t.reward
                consumable = bool(t.consumable)
            pairs = tuple((slot[n], d) for n, d in change.items() if d)
            self.tiles.append(Tile(
                kind=kind, change=pairs, requires=tuple((slot[n], k) for n, k in requires.items()),
                excludes=excludes, reward=float(reward), consumable=consumable, ends_episode=t.ends_episode,
                gains=sum(1 << s for s, d in pairs if d > 0), by_cell=t.label == "cell"))
        # recipes that apply anywhere (CraftSuite's; the authors' tasks have none) run after a tile acts
        self._anywhere = [([(slot[n], k) for n, k in r.consume.items()], [(slot[n], k) for n, k in r.produce.items()],
                           r.repeat) for r in spec.recipes if r.at is None]
        self.ends_by_tile = any(t.ends_episode for t in self.tiles)

    def acceptance_completes(self, automaton, labeller) -> bool:
        """Whether the automaton can accept only on a step where a tile ends the episode, so
        that acceptance and completion are one event (Dungeon Quest: only the dragon acting
        labels ``dragon``). Where entering acceptance needs no label that only such a tile
        sets (Blind Craftsman: ``home`` holds in home's whole cell), the automaton may
        accept on a step that completes nothing. Without such tiles, acceptance ends the
        episode: the two are one event too."""
        if not self.ends_by_tile:
            return True
        ending = [t for t in self.tiles if t.ends_episode]
        others = [t for t in self.tiles if not t.ends_episode]
        raised_elsewhere = {s for t in others for s, d in t.change if d > 0}
        raised_elsewhere |= {s for _, produce, _ in self._anywhere for s, _ in produce}
        only_ending = labeller.event_bits(
            slots={s for t in ending for s, d in t.change if d > 0} - raised_elsewhere,
            places={t.kind for t in ending if not t.by_cell})
        accepting = automaton.accepting.astype(bool)
        if accepting[automaton.initial]:
            return False
        delta = automaton.delta
        masks = np.arange(delta.shape[1])
        entering = accepting[delta] & ~accepting[:, None]  # (state, mask): a step into acceptance
        return bool(((masks & only_ending) != 0)[np.nonzero(entering)[1]].all())

    def act(self, inv: list[int], kind: int) -> Act | None:
        """The tile of ``kind`` acts on ``inv`` (changed in place) if the inventory meets its
        requirements and its change leaves no count negative (the authors'
        ``meets_requirements``); None when it does not act."""
        tile = self.tiles[kind]
        if any(inv[s] < k for s, k in tile.requires) or any(inv[s] > 0 for s in tile.excludes):
            return None
        if any(inv[s] + d < 0 for s, d in tile.change):
            return None
        capacity = self.capacity
        for s, d in tile.change:
            inv[s] += d
            if capacity[s] is not None and inv[s] > capacity[s]:
                inv[s] = capacity[s]
        gained = tile.gains
        for consume, produce, repeat in self._anywhere:
            while all(inv[s] >= k for s, k in consume):
                for s, k in consume:
                    inv[s] -= k
                for s, k in produce:
                    inv[s] += k
                    gained |= 1 << s
                if not repeat:
                    break
        return Act(tile.reward, gained, tile.consumable, tile.ends_episode, -1 if tile.by_cell else kind)

    def first_acting(self, inv: list[int], inside) -> tuple[int, Act] | tuple[int, None]:
        """Slot and outcome of the first object within reach (``inside``: (slot, kind) pairs in
        board order) that acts; (-1, None) when none does."""
        for j, kind in inside:
            outcome = self.act(inv, kind)
            if outcome is not None:
                return j, outcome
        return -1, None
