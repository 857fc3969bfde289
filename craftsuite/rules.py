"""A task's inventory mechanics, shared by every world of the task.

Worlds decide *where* the agent is and which object it touches; ``Rules`` decides what
touching it does: pick an item up (capacity, requirements, exclusions), run a place's
recipes on arrival, then the automatic recipes. Inventory is a plain list of counts in
``spec.inventory`` order (lists beat numpy arrays for a handful of scalars per step).
"""

from __future__ import annotations

from dataclasses import dataclass

from .spec import Item, Recipe, TaskSpec


@dataclass(frozen=True)
class Outcome:
    """What one touch did. ``gained`` has bit ``i`` set when inventory slot ``i`` went up."""

    consumed: bool  # the object is used up and leaves the world
    reward: float
    gained: int


class _CompiledRecipe:
    __slots__ = ("consume", "produce", "repeat")

    def __init__(self, recipe: Recipe, slot: dict[str, int]):
        self.consume = [(slot[n], k) for n, k in recipe.consume.items()]
        self.produce = [(slot[n], k) for n, k in recipe.produce.items()]
        self.repeat = recipe.repeat

    def apply(self, inv: list[int]) -> int:
        """Run the recipe as often as allowed; return the bits of the slots produced."""
        gained = 0
        while all(inv[s] >= k for s, k in self.consume):
            for s, k in self.consume:
                inv[s] -= k
            for s, k in self.produce:
                inv[s] += k
                gained |= 1 << s
            if not self.repeat:
                break
        return gained


class Rules:
    """Pickups, place recipes and automatic recipes of one task spec.

    Object kinds are indices into ``spec.objects`` (items first, then places).
    """

    def __init__(self, spec: TaskSpec):
        self.spec = spec
        self.inventory_names = spec.inventory
        slot = {n: i for i, n in enumerate(self.inventory_names)}
        self.n_items = len(spec.items)
        self._items = [self._compile_item(it, slot) for it in spec.items]
        self._at_place = [
            [_CompiledRecipe(r, slot) for r in spec.recipes if r.at == p.name] for p in spec.places
        ]
        self._anywhere = [_CompiledRecipe(r, slot) for r in spec.recipes if r.at is None]
        self.scale = self._max_counts(spec, slot)

    @staticmethod
    def _compile_item(item: Item, slot: dict[str, int]):
        return (
            slot[item.name],
            item.capacity,
            [(slot[n], k) for n, k in item.requires.items()],
            [slot[n] for n in item.excludes],
            item.reward,
        )

    @staticmethod
    def _max_counts(spec: TaskSpec, slot: dict[str, int]) -> list[float]:
        """An upper bound of each inventory count, to normalise observations into [0, 1].

        Capacity limits what is held at once, not what flows through recipes over an
        episode (3 wood carried 2 at a time still make 3 tools), and a place recipe runs
        again on every arrival: produced counts are bounded by the total supply.
        """
        supply = [0.0] * len(slot)  # how many can ever be obtained in an episode
        held = [0.0] * len(slot)
        for it in spec.items:
            supply[slot[it.name]] = float(it.count)
            held[slot[it.name]] = float(min(it.capacity or it.count, it.count))
        for r in spec.recipes:  # recipes appear after what they consume in spec.inventory
            runs = min(supply[slot[n]] // k for n, k in r.consume.items())
            for n, k in r.produce.items():
                supply[slot[n]] += k * runs
                held[slot[n]] = supply[slot[n]]
        return [max(h, 1.0) for h in held]

    def new_inventory(self) -> list[int]:
        return [0] * len(self.inventory_names)

    def is_place(self, kind: int) -> bool:
        return kind >= self.n_items

    def touch(self, inv: list[int], kind: int, arrived: bool) -> Outcome | None:
        """The agent is on an object of ``kind`` (``arrived``: it entered this step).

        Items are tried on every touch; places act on arrival only. Returns None when
        nothing happened (the common case, kept allocation-free).
        """
        if kind < self.n_items:
            s, capacity, requires, excludes, reward = self._items[kind]
            if capacity is not None and inv[s] >= capacity:
                return None
            if any(inv[r] < k for r, k in requires) or any(inv[e] > 0 for e in excludes):
                return None
            inv[s] += 1
            gained = 1 << s
            for recipe in self._anywhere:
                gained |= recipe.apply(inv)
            return Outcome(True, reward, gained)
        if not arrived:
            return None
        gained = 0
        for recipe in self._at_place[kind - self.n_items]:
            gained |= recipe.apply(inv)
        for recipe in self._anywhere:
            gained |= recipe.apply(inv)
        return Outcome(False, 0.0, gained)
