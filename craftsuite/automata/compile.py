"""Compile an LTLf formula over named propositions into a minimal Automaton, with a cache.

This package is the only place in CraftSuite that knows how LTLf becomes a DFA.
"""

from __future__ import annotations

import hashlib
import logging
import re
import zipfile
from pathlib import Path

import numpy as np

from ..files import atomic_path
from ..names import unknown_name
from ..paths import cache_dir as cache_folder
from .dfa import MAX_PROPOSITIONS, Automaton, minimize
from .ltlf import LTLfSyntaxError, atoms, parse
from .progression import progress_to_dfa

log = logging.getLogger(__name__)

# Bump when the compiler's output for a formula could change: old cache entries then miss.
COMPILER_VERSION = 1
_NAME = re.compile(r"[a-z_][a-z0-9_]*\Z")


def cache_dir() -> Path:
    """Where compiled automata are cached: $CRAFTSUITE_CACHE_DIR/automata, else the XDG cache's."""
    return cache_folder("automata")


def _check(formula: str, propositions) -> tuple[tuple[str, ...], tuple]:
    if isinstance(propositions, str):  # tuple("wood") is its letters
        raise ValueError(f"propositions must be a sequence of names, got the string {propositions!r}: give "
                         f"[{propositions!r}], or a list of several")
    props = tuple(propositions)
    if len(set(props)) != len(props):
        dup = sorted({p for p in props if props.count(p) > 1})
        raise ValueError(f"duplicate propositions: {dup}")
    for p in props:
        if not isinstance(p, str) or not _NAME.match(p):
            raise ValueError(
                f"proposition {p!r} is not a lower-case identifier (letters, digits, '_')"
            )
    if len(props) > MAX_PROPOSITIONS:
        raise ValueError(
            f"{len(props)} propositions: at most {MAX_PROPOSITIONS} are supported "
            "(the transition table has 2**n columns)"
        )
    ast = parse(formula)
    unknown = atoms(ast) - set(props)
    if unknown:
        raise unknown_name("proposition", sorted(unknown), props, f"(declared for formula {formula!r})")
    return props, ast


def compile_ltlf(formula: str, propositions, *, cache: bool = True) -> Automaton:
    """The minimal DFA of an LTLf formula over the given propositions (in bit order).

    Args:
        formula: LTLf text, e.g. ``"G(wood -> F factory) & F(tools3 & home)"``.
        propositions: names in bit order; every atom of the formula must be among them.
        cache: read and write the on-disk cache (``cache_dir()``), keyed by the compiler
            version, the formula and the propositions.

    Raises:
        LTLfSyntaxError: the formula does not parse.
        ValueError: unknown, duplicate, malformed or too many propositions.
    """
    try:
        return _compile(formula, propositions, cache)
    except RecursionError:  # the parser and the tree's readers recurse: Python's stack ends first
        raise LTLfSyntaxError("the formula nests too deeply (operators within operators) for Python's stack: "
                              "write it with fewer levels") from None


def _compile(formula: str, propositions, cache: bool) -> Automaton:
    props, ast = _check(formula, propositions)
    path = None
    if cache:
        key = hashlib.sha256(f"{COMPILER_VERSION}\n{formula}\n{','.join(props)}".encode())
        path = cache_dir() / f"{key.hexdigest()[:32]}.npz"
        loaded = _load(path, formula, props)
        if loaded is not None:
            return loaded
    delta, accepting = minimize(*progress_to_dfa(ast, props))
    automaton = Automaton(formula=formula, propositions=props, delta=delta, accepting=accepting)
    if path is not None:
        _save(path, automaton)
    return automaton


def _load(path: Path, formula: str, props: tuple[str, ...]) -> Automaton | None:
    try:
        with np.load(path, allow_pickle=False) as f:
            if str(f["formula"]) != formula or tuple(f["propositions"].tolist()) != props:
                return None  # a hash collision: recompile rather than trust it
            delta, accepting = f["delta"], f["accepting"]
        return Automaton(  # (which refuses a damaged table: a ValueError, so recompiled)
            formula=formula, propositions=props, delta=delta, accepting=accepting)
    except FileNotFoundError:
        return None
    except (OSError, ValueError, KeyError, zipfile.BadZipFile) as err:
        log.warning("ignoring unreadable automaton cache %s (%s); recompiling", path, err)
        return None


def _save(path: Path, automaton: Automaton) -> None:
    """Atomic write (``craftsuite.files``: a temporary file of its own, then a rename): safe for parallel processes."""
    try:
        with atomic_path(path) as tmp, open(tmp, "wb") as f:
            np.savez(
                f,
                formula=np.array(automaton.formula),
                propositions=np.array(automaton.propositions),
                delta=automaton.delta,
                accepting=automaton.accepting,
            )
    except OSError as err:  # a read-only home must not stop anyone from compiling
        log.warning("could not write automaton cache %s (%s)", path, err)


__all__ = ["compile_ltlf", "cache_dir", "LTLfSyntaxError", "COMPILER_VERSION"]
