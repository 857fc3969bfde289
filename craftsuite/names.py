"""The one wording of a name CraftSuite does not know (a task, suite, method, algorithm,
learner regime, tag; a spec's key, place, inventory name or proposition; a world's keyword):
the name as given, the known names closest to it, and every known one, on one line, as
``gym.make`` answers an unknown id with the ids it knows.

``UnknownName`` is both a ``KeyError`` (a lookup by name failed, as ``dict[name]`` would say)
and a ``ValueError`` (bad input, as the rest of CraftSuite's refusals are), so code catching
either keeps working; its ``str()`` is the message itself, where a ``KeyError``'s would print
it quoted.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Mapping
from typing import TypeVar

T = TypeVar("T")


class UnknownName(KeyError, ValueError):
    """A name that is none of the known ones (see the module's docstring)."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


def closest(name: object, known: Iterable[str]) -> list[str]:
    """The known names a misspelling of ``name`` most likely meant, best first: the known
    spellings of difflib's 3 best above its 0.6 similarity, case aside (so two known names
    that differ only in case are both named)."""
    by_lower: dict[str, list[str]] = {}
    for k in known:
        spellings = by_lower.setdefault(k.lower(), [])
        if k not in spellings:
            spellings.append(k)
    return [k for lower in difflib.get_close_matches(str(name).lower(), by_lower) for k in by_lower[lower]]


def suggested(name: object, known: Iterable[str]) -> str:
    """``name`` quoted, with the known names it most likely meant: ``'ToolHme' (did you mean ToolHome?)``."""
    near = closest(name, known)
    return f"{name!r}" + (f" (did you mean {' or '.join(near)}?)" if near else "")


def unknown_text(kind: str, names: object, known: Iterable[str], hint: str = "", plural: str | None = None) -> str:
    """The sentence for ``names`` (a list of names, in the order to name them; anything else
    is one name), none of them among ``known``: ``unknown task 'ToolHme' (did you mean
    ToolHome?); tasks: A, B, ...``, then ``hint`` (how to add one of one's own, say).
    ``plural``: ``kind``'s plural, where an ``s`` does not make it."""
    known = [str(k) for k in known]
    names = names if isinstance(names, list) else [names]
    plural = plural or f"{kind}s"
    listed = ", ".join(suggested(n, known) for n in names)
    return f"unknown {kind if len(names) == 1 else plural} {listed}; {plural}: {', '.join(known)}" + (
        f" {hint}" if hint else "")


def unknown_keywords(keywords: list, accepted: Iterable[str], world: str) -> str:
    """The sentence for keywords a world's constructor does not take (``world``: which,
    e.g. ``the MuJoCo world``): in ``gymnasium.make``'s terms, keyword arguments, not names
    looked up in a table."""
    accepted = [str(k) for k in accepted]
    return (f"unknown keyword{'s' if len(keywords) > 1 else ''} {', '.join(suggested(k, accepted) for k in keywords)} "
            f"for {world}; it accepts {', '.join(accepted)}")


def unknown_name(kind: str, names: object, known: Iterable[str], hint: str = "",
                 plural: str | None = None) -> UnknownName:
    """``unknown_text``'s sentence as the error to raise."""
    return UnknownName(unknown_text(kind, names, known, hint, plural))


def look_up(table: Mapping[str, T], name: str, kind: str) -> T:
    """``table[name]``, or an ``UnknownName`` naming the ``kind``'s known names (``table``'s, in its order)."""
    if name not in table:
        raise unknown_name(kind, name, table)
    return table[name]
