"""The Automaton: a minimal DFA over proposition labels as a dense numpy table."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..names import unknown_name

MAX_PROPOSITIONS = 16  # the dense table has 2**n columns


@dataclass(frozen=True, eq=False)
class Automaton:
    """A DFA whose alphabet is the set of label bitmasks over ``propositions``.

    Attributes:
        formula: the LTLf objective it was compiled from.
        propositions: bit order of labels: bit ``i`` of a mask means ``propositions[i]``.
        delta: ``delta[state, mask] -> next state``, shape ``(n_states, 2**n_props)``.
        accepting: bool per state: the trace so far satisfies the formula.
        initial: the start state (always 0: states are numbered breadth first).
    """

    formula: str
    propositions: tuple[str, ...]
    delta: np.ndarray
    accepting: np.ndarray
    initial: int = 0
    _rows: list = field(init=False, repr=False, compare=False, default=None)

    def __post_init__(self):
        self._check()
        self.delta.setflags(write=False)
        self.accepting.setflags(write=False)
        # Python lists index ~5x faster than numpy scalars in a per-step hot path.
        object.__setattr__(self, "_rows", self.delta.tolist())

    def _check(self) -> None:
        """Refuse a table that is no DFA over these propositions: ``step`` indexes it as it is
        (a negative or float entry would be read as another state, or fail far from here)."""
        delta, accepting, columns = self.delta, self.accepting, 2 ** len(self.propositions)
        if not (isinstance(delta, np.ndarray) and np.issubdtype(delta.dtype, np.integer) and delta.ndim == 2
                and delta.shape[0] >= 1 and delta.shape[1] == columns):
            raise ValueError(f"delta must be an integer array of shape (n_states, {columns}) for "
                             f"{len(self.propositions)} propositions, got {getattr(delta, 'dtype', type(delta))} of "
                             f"shape {getattr(delta, 'shape', '?')}")
        n = delta.shape[0]
        if delta.min() < 0 or delta.max() >= n:
            raise ValueError(f"delta's entries must be states 0-{n - 1}, got {delta.min()}-{delta.max()}")
        if not (isinstance(accepting, np.ndarray) and accepting.dtype == bool and accepting.shape == (n,)):
            raise ValueError(f"accepting must be a bool array of shape ({n},), one per state, got "
                             f"{getattr(accepting, 'dtype', type(accepting))} of shape "
                             f"{getattr(accepting, 'shape', '?')}")
        if type(self.initial) is not int or not 0 <= self.initial < n:
            raise ValueError(f"initial must be a state 0-{n - 1}, got {self.initial!r}")

    # -- structure ---------------------------------------------------------------------------
    @property
    def n_states(self) -> int:
        return self.delta.shape[0]

    @cached_property
    def rejecting(self) -> np.ndarray:
        """Rejecting sinks: non-accepting states that no label leaves."""
        stay = (self.delta == np.arange(self.n_states)[:, None]).all(axis=1)
        return stay & ~self.accepting

    @cached_property
    def satisfiable(self) -> bool:
        """Whether some trace satisfies the formula: an accepting state is reachable from
        the initial one."""
        seen, frontier = {self.initial}, [self.initial]
        while frontier:
            state = frontier.pop()
            if self.accepting[state]:
                return True
            new = set(self._rows[state]) - seen
            seen |= new
            frontier += new
        return False

    @cached_property
    def fingerprint(self) -> str:
        """Identity of the language and its encoding (propositions, table, acceptance)."""
        h = hashlib.sha256()
        h.update("\0".join(self.propositions).encode())
        h.update(np.ascontiguousarray(self.delta, dtype=np.int32).tobytes())
        h.update(self.accepting.tobytes())
        return h.hexdigest()[:16]

    def edges(self, include_sink: bool = False) -> list[tuple[int, int]]:
        """Distinct (source, target) pairs, self-loops included, as the paper counts them."""
        pairs = set()
        for s in range(self.n_states):
            if not include_sink and self.rejecting[s]:
                continue
            for t in np.unique(self.delta[s]).tolist():
                if include_sink or not self.rejecting[t]:
                    pairs.add((s, t))
        return sorted(pairs)

    def size(self) -> tuple[int, int]:
        """(states, transitions) without the rejecting sink: the paper's way of counting."""
        return int((~self.rejecting).sum()), len(self.edges())

    # -- running ---------------------------------------------------------------------------
    def mask(self, labels) -> int:
        """Bitmask of a set of proposition names."""
        if isinstance(labels, str):  # its letters would be read as names
            raise ValueError(f"labels must be a collection of proposition names, got the string {labels!r}: give "
                             f"{{{labels!r}}}")
        bits = 0
        for name in labels:
            try:
                bits |= 1 << self.propositions.index(name)
            except ValueError:
                raise unknown_name("proposition", name, self.propositions, "(this automaton's)") from None
        return bits

    def labels(self, mask: int) -> frozenset[str]:
        if not 0 <= mask < 2 ** len(self.propositions):  # (Python would read a negative one's bits)
            raise ValueError(f"mask must be a label bitmask 0-{2 ** len(self.propositions) - 1}, got {mask!r}")
        return frozenset(p for i, p in enumerate(self.propositions) if mask >> i & 1)

    def step(self, state: int, mask: int) -> int:
        return self._rows[state][mask]

    def run(self, masks, state: int | None = None) -> int:
        s = self.initial if state is None else state
        for m in masks:
            s = self._rows[s][m]
        return s

    def accepts(self, masks) -> bool:
        """Whether the finite trace of label masks satisfies the formula."""
        return bool(self.accepting[self.run(masks)])

    # -- reading ---------------------------------------------------------------------------
    def guard(self, source: int, target: int, sink_free: bool = False) -> str:
        """A short Boolean expression over the propositions for the labels from -> to.

        ``sink_free``: treat labels that lead to the rejecting sink as don't-cares, which
        shortens guards a lot; right where the sink is not shown (any label on no edge
        leads there).
        """
        row = self.delta[source]
        dont_care = self.rejecting[row] if sink_free and not self.rejecting[target] else None
        return boolean_cover(row == target, self.propositions, dont_care)

    def describe(self) -> str:
        """A text table of states and guarded transitions."""
        lines = [f"{self.formula}", f"propositions (bit order): {', '.join(self.propositions)}"]
        for s in range(self.n_states):
            tags = [t for t, on in (("initial", s == self.initial), ("accepting", self.accepting[s]),
                                    ("rejecting sink", self.rejecting[s])) if on]
            lines.append(f"state {s}" + (f" ({', '.join(tags)})" if tags else ""))
            for t in np.unique(self.delta[s]).tolist():
                lines.append(f"  -> {t}: {self.guard(s, t)}")
        return "\n".join(lines)


def minimize(delta: np.ndarray, accepting: np.ndarray, initial: int = 0):
    """Moore partition refinement, then breadth-first renumbering from the initial state.

    Returns ``(delta, accepting)`` of the minimal DFA of the reachable part, initial 0.
    """
    classes = accepting.astype(np.int64)
    n_classes = len(np.unique(classes))
    while True:
        signature = np.concatenate([classes[:, None], classes[delta]], axis=1)
        _, refined = np.unique(signature, axis=0, return_inverse=True)
        refined = refined.reshape(-1)
        n_refined = int(refined.max()) + 1
        classes = refined
        if n_refined == n_classes:
            break
        n_classes = n_refined
    representative = np.zeros(n_classes, dtype=np.int64)
    representative[classes[::-1]] = np.arange(len(classes))[::-1]  # first member of each class
    small = classes[delta[representative]]
    small_accepting = accepting[representative]

    order, seen = [], {int(classes[initial])}
    frontier = [int(classes[initial])]
    while frontier:  # breadth first, targets in order of first occurrence
        order.extend(frontier)
        nxt = []
        for s in frontier:
            for t in dict.fromkeys(small[s].tolist()):
                if t not in seen:
                    seen.add(t)
                    nxt.append(t)
        frontier = nxt
    new_id = np.full(n_classes, -1, dtype=np.int64)
    new_id[order] = np.arange(len(order))
    dtype = np.int16 if len(order) < 2**15 else np.int32
    return new_id[small[order]].astype(dtype), small_accepting[order].copy()


def boolean_cover(onset: np.ndarray, names, dont_care: np.ndarray | None = None) -> str:
    """A small sum-of-products for a Boolean function given as its truth table.

    ``onset[mask]`` is the function on the assignment whose bit i is ``names[i]``;
    ``dont_care[mask]`` marks assignments the expression may cover or not. Cubes come from
    a decision-tree split, are expanded to primes greedily and redundant ones dropped (the
    EXPAND and IRREDUNDANT steps of Espresso): short, readable guards.
    """
    n = len(names)
    allowed = onset if dont_care is None else onset | dont_care
    if allowed.all():
        return "true"
    if not onset.any():
        return "false"
    masks = np.arange(1 << n)
    cubes: list[tuple[int, int]] = []  # (care bits, value bits)

    def split(care: int, value: int, var: int):
        inside = (masks & care) == value
        if not onset[inside].any():
            return
        if allowed[inside].all():
            cubes.append((care, value))
            return
        while var < n:
            bit = 1 << var
            lo = inside & (masks & bit == 0)
            hi = inside & (masks & bit != 0)
            if not (np.array_equal(onset[lo], onset[hi]) and np.array_equal(allowed[lo], allowed[hi])):
                split(care | bit, value, var + 1)
                split(care | bit, value | bit, var + 1)
                return
            var += 1

    split(0, 0, 0)

    def covered(care, value):
        return allowed[(masks & care) == value].all()

    primes = []
    for care, value in cubes:
        for var in range(n):
            bit = 1 << var
            if care & bit and covered(care & ~bit, value & ~bit):
                care, value = care & ~bit, value & ~bit
        if (care, value) not in primes:
            primes.append((care, value))
    primes.sort(key=lambda c: bin(c[0]).count("1"))
    kept = list(primes)
    for cube in sorted(primes, key=lambda c: -bin(c[0]).count("1")):
        rest = [c for c in kept if c != cube]
        if rest and _union(rest, masks)[((masks & cube[0]) == cube[1]) & onset].all():
            kept = rest

    def text(care, value):
        lits = [("" if value >> i & 1 else "!") + names[i] for i in range(n) if care >> i & 1]
        return " & ".join(lits) if lits else "true"

    parts = [text(*c) for c in kept]
    return " | ".join(f"({p})" if " & " in p and len(parts) > 1 else p for p in parts)


def _union(cubes, masks) -> np.ndarray:
    out = np.zeros(len(masks), dtype=bool)
    for care, value in cubes:
        out |= (masks & care) == value
    return out
