"""LTLf -> DFA by formula progression, filled into a dense transition table.

How it works, and why it is fast enough for 13 propositions in pure Python:

* The formula is put in negation normal form over hash-consed integer nodes, so equal
  sub-formulas are one id and every memo below is a dict lookup.
* A DFA state is "what must still hold from the next position on": a positive Boolean
  combination of *terms* ``X(psi)`` (a next position must exist) and ``WX(psi)`` (holds
  if the trace ends), kept in DNF with absorption so that the set of states is finite.
  A state accepts iff one of its clauses has only WX terms.
* A step unrolls each term once (``a U b = b | (a & X(a U b))``, ``a R b = b & (a | WX(a
  R b))``), giving a formula over current-step literals and next-step terms. Instead of
  evaluating it for each of the 2^n labels, we Shannon-expand it on its literals, one
  variable at a time, memoised per node: every node yields a numpy row ``next[mask]``
  built by one ``np.where`` from its two cofactors. Variables a node does not mention are
  never branched on.

The result is usually not minimal (syntactically different but equivalent states);
``dfa.minimize`` takes care of that.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from ..names import unknown_name
from .ltlf import atoms

TRUE, FALSE = 0, 1


class _Nodes:
    """Hash-consed NNF nodes: key tuples <-> integer ids."""

    def __init__(self):
        self.keys: list[tuple] = [("true",), ("false",)]
        self.ids: dict[tuple, int] = {k: i for i, k in enumerate(self.keys)}

    def mk(self, key: tuple) -> int:
        node = self.ids.get(key)
        if node is None:
            node = self.ids[key] = len(self.keys)
            self.keys.append(key)
        return node

    def lit(self, var: int, positive: bool) -> int:
        return self.mk(("lit", var, positive))

    def junction(self, op: str, children) -> int:
        unit, zero = (TRUE, FALSE) if op == "and" else (FALSE, TRUE)
        flat = set()
        for c in children:
            if c == zero:
                return zero
            if c == unit:
                continue
            key = self.keys[c]
            if key[0] == op:
                flat.update(key[1])
            else:
                flat.add(c)
        lits = {}
        for c in flat:
            key = self.keys[c]
            if key[0] == "lit":
                if lits.setdefault(key[1], key[2]) != key[2]:
                    return zero  # p & !p, or p | !p
        if not flat:
            return unit
        if len(flat) == 1:
            return next(iter(flat))
        return self.mk((op, frozenset(flat)))

    def conj(self, children) -> int:
        return self.junction("and", children)

    def disj(self, children) -> int:
        return self.junction("or", children)


class _Compiler:
    def __init__(self, ast, propositions: tuple[str, ...]):
        self.props = propositions
        self.var = {p: i for i, p in enumerate(propositions)}
        self.n = _Nodes()
        self.root = self.nnf(ast, False)
        self._unroll: dict[int, int] = {}
        self._support: dict[int, int] = {}
        self._cof: dict[tuple[int, int, bool], int] = {}
        self._row: dict[int, np.ndarray] = {}
        self._dnf: dict[int, frozenset] = {}
        self.masks = np.arange(1 << len(propositions), dtype=np.int64)
        self.states: list[frozenset] = []
        self.state_ids: dict[frozenset, int] = {}
        self.queue: deque[int] = deque()

    # -- negation normal form ------------------------------------------------------------
    def nnf(self, node, neg: bool) -> int:
        n, op = self.n, node[0]
        if op == "ap":
            return n.lit(self.var[node[1]], not neg)
        if op == "true":
            return FALSE if neg else TRUE
        if op == "false":
            return TRUE if neg else FALSE
        if op == "last":  # no next position: WX false (negated: X true)
            return n.mk(("X", TRUE)) if neg else n.mk(("WX", FALSE))
        if op == "not":
            return self.nnf(node[1], not neg)
        if op in ("and", "or"):
            a, b = self.nnf(node[1], neg), self.nnf(node[2], neg)
            return n.conj([a, b]) if (op == "and") != neg else n.disj([a, b])
        if op == "implies":  # a -> b  ==  !a | b
            return self.nnf(("or", ("not", node[1]), node[2]), neg)
        if op == "iff":
            a, b = node[1], node[2]
            same = ("or", ("and", a, b), ("and", ("not", a), ("not", b)))
            return self.nnf(same, neg)
        if op in ("X", "WX"):
            dual = {"X": "WX", "WX": "X"}[op]
            return n.mk((dual if neg else op, self.nnf(node[1], neg)))
        if op == "F":
            return self.nnf(("U", ("true",), node[1]), neg)
        if op == "G":
            return self.nnf(("R", ("false",), node[1]), neg)
        if op in ("U", "R"):
            dual = {"U": "R", "R": "U"}[op]
            return n.mk((dual if neg else op, self.nnf(node[1], neg), self.nnf(node[2], neg)))
        raise ValueError(f"unknown LTLf node {op!r}")

    # -- one-step unrolling ---------------------------------------------------------------
    def unroll(self, node: int) -> int:
        """The node as current-step literals combined with next-step X/WX terms."""
        done = self._unroll.get(node)
        if done is not None:
            return done
        n, key = self.n, self.n.keys[node]
        op = key[0]
        if op in ("true", "false", "lit", "X", "WX"):
            out = node
        elif op in ("and", "or"):
            out = n.junction(op, [self.unroll(c) for c in key[1]])
        elif op == "U":
            a, b = key[1], key[2]
            out = n.disj([self.unroll(b), n.conj([self.unroll(a), n.mk(("X", node))])])
        else:  # "R"
            a, b = key[1], key[2]
            out = n.conj([self.unroll(b), n.disj([self.unroll(a), n.mk(("WX", node))])])
        self._unroll[node] = out
        return out

    def support(self, node: int) -> int:
        """Bitmask of the variables in the node's current-step literals."""
        done = self._support.get(node)
        if done is None:
            key = self.n.keys[node]
            if key[0] == "lit":
                done = 1 << key[1]
            elif key[0] in ("and", "or"):
                done = 0
                for c in key[1]:
                    done |= self.support(c)
            else:
                done = 0
            self._support[node] = done
        return done

    def cofactor(self, node: int, var: int, value: bool) -> int:
        if not self.support(node) >> var & 1:
            return node
        memo = (node, var, value)
        done = self._cof.get(memo)
        if done is None:
            key = self.n.keys[node]
            if key[0] == "lit":
                done = TRUE if key[2] == value else FALSE
            else:
                done = self.n.junction(key[0], [self.cofactor(c, var, value) for c in key[1]])
            self._cof[memo] = done
        return done

    # -- states -----------------------------------------------------------------------------
    def dnf(self, node: int) -> frozenset:
        """A term-only formula as an absorbed DNF: frozenset of clauses (frozensets of terms)."""
        done = self._dnf.get(node)
        if done is not None:
            return done
        key = self.n.keys[node]
        op = key[0]
        if op == "true":
            clauses = {frozenset()}
        elif op == "false":
            clauses = set()
        elif op in ("X", "WX"):
            clauses = {frozenset([node])}
        elif op == "or":
            clauses = set().union(*(self.dnf(c) for c in key[1]))
        elif op == "and":
            clauses = {frozenset()}
            for c in key[1]:
                clauses = {a | b for a in clauses for b in self.dnf(c)}
        else:
            raise AssertionError(f"literal left in a next-state formula: {key}")
        minimal = frozenset(c for c in clauses if not any(o < c for o in clauses))
        self._dnf[node] = minimal
        return minimal

    def state_id(self, clauses: frozenset) -> int:
        sid = self.state_ids.get(clauses)
        if sid is None:
            sid = self.state_ids[clauses] = len(self.states)
            self.states.append(clauses)
            self.queue.append(sid)
        return sid

    def accepting(self, clauses: frozenset) -> bool:
        """Would the trace be accepted if it ended here? (X -> false, WX -> true)."""
        return any(all(self.n.keys[t][0] == "WX" for t in clause) for clause in clauses)

    def row(self, node: int) -> np.ndarray:
        """next_state[mask] for every label mask, by memoised Shannon expansion."""
        done = self._row.get(node)
        if done is None:
            sup = self.support(node)
            if sup == 0:
                done = np.full(len(self.masks), self.state_id(self.dnf(node)), dtype=np.int32)
            else:
                var = (sup & -sup).bit_length() - 1
                lo = self.row(self.cofactor(node, var, False))
                hi = self.row(self.cofactor(node, var, True))
                done = np.where(self.masks >> var & 1 == 1, hi, lo)
            self._row[node] = done
        return done

    def run(self):
        n = self.n
        # The formula must hold at position 0, which must exist: the empty trace is rejected.
        self.state_id(frozenset([frozenset([n.mk(("X", self.root))])]))
        rows = {}
        while self.queue:
            sid = self.queue.popleft()
            step = n.disj(
                [n.conj([self.unroll(n.keys[t][1]) for t in clause]) for clause in self.states[sid]]
            )
            rows[sid] = self.row(step)
        delta = np.stack([rows[s] for s in range(len(self.states))])
        accepting = np.array([self.accepting(c) for c in self.states], dtype=bool)
        return delta, accepting


def progress_to_dfa(ast, propositions: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Build a (not yet minimal) DFA for a parsed formula.

    Returns ``(delta, accepting)``: ``delta[state, mask]`` with bit i of ``mask`` meaning
    ``propositions[i]`` holds, and state 0 initial.
    """
    unknown = atoms(ast) - set(propositions)
    if unknown:
        raise unknown_name("proposition", sorted(unknown), propositions, "(the formula's declared ones)")
    return _Compiler(ast, propositions).run()
