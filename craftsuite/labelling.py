"""Labelling: what happened in a step -> the set of true propositions, as a bitmask.

One ``Labeller`` per task, shared by every world of the task. Events (``obtained``,
``arrived``, ``reached``) are true on the step they happen; levels (``at_least``,
``exactly``) are true while they hold. Bit ``i`` of the mask is ``propositions[i]``, the automaton's bit order.
"""

from __future__ import annotations

from .names import unknown_name
from .spec import TaskSpec


class Labeller:
    def __init__(self, spec: TaskSpec, propositions: tuple[str, ...] | None = None):
        order = propositions or spec.proposition_names
        by_name = {p.name: p for p in spec.propositions}
        missing = set(order) - set(by_name)
        if missing:
            raise unknown_name("proposition", sorted(missing), sorted(by_name), f"(task {spec.name}'s)")
        slot = {n: i for i, n in enumerate(spec.inventory)}
        kind = {o.name: k for k, o in enumerate(spec.objects)}
        self.propositions = tuple(order)
        self._obtained, self._arrived, self._at_least, self._exactly, self._reached = [], [], [], [], []
        for bit, name in enumerate(order):
            p = by_name[name]
            if p.kind == "obtained":
                self._obtained.append((1 << bit, slot[p.subject]))
            elif p.kind == "arrived":
                self._arrived.append((1 << bit, kind[p.subject]))
            elif p.kind == "at_least":
                self._at_least.append((1 << bit, slot[p.subject], p.value))
            elif p.kind == "exactly":
                self._exactly.append((1 << bit, slot[p.subject], p.value))
            else:
                self._reached.append((1 << bit, slot[p.subject], p.value))

    def levels(self, inv: list[int]) -> int:
        """The bits that depend on the inventory alone (true while they hold)."""
        mask = 0
        for bit, s, k in self._at_least:
            if inv[s] >= k:
                mask |= bit
        for bit, s, k in self._exactly:
            if inv[s] == k:
                mask |= bit
        return mask

    def __call__(self, inv: list[int], gained: int = 0, arrived: int = -1) -> int:
        """Label of a step: inventory after it, slots ``gained`` in it, place kind entered."""
        mask = self.levels(inv)
        for bit, s in self._obtained:
            if gained >> s & 1:
                mask |= bit
        for bit, s, k in self._reached:
            if gained >> s & 1 and inv[s] == k:
                mask |= bit
        for bit, place in self._arrived:
            if place == arrived:
                mask |= bit
        return mask

    def arrived_bits(self, place: int) -> int:
        """The bits of the ``arrived`` propositions about place kind ``place``."""
        return sum(bit for bit, kind in self._arrived if kind == place)

    def event_bits(self, slots=(), places=()) -> int:
        """The bits of the events about inventory ``slots`` (``obtained``, ``reached``) and
        place kinds ``places`` (``arrived``): the propositions only such a change sets."""
        slots, places = set(slots), set(places)
        return (sum(bit for bit, s in self._obtained if s in slots)
                + sum(bit for bit, s, _ in self._reached if s in slots)
                + sum(bit for bit, kind in self._arrived if kind in places))

    def names(self, mask: int) -> tuple[str, ...]:
        return tuple(p for i, p in enumerate(self.propositions) if mask >> i & 1)
