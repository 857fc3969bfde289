"""Draw an Automaton with Graphviz, in the style of the paper's Figure 4.

States are circles (accepting: double circles), an arrow marks the initial state, each
edge carries a short guard over the propositions. The rejecting sink is left out unless
asked for, as in the paper. ``edge_notes`` lets callers print numbers on edges (e.g.
distilled Q-values); ``dotted`` edges are drawn dotted (e.g. transitions a teacher never
saw).
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from ..files import atomic_path
from .dfa import Automaton


def _quote(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def to_dot(
    automaton: Automaton,
    *,
    title: str | None = None,
    show_sink: bool = False,
    edge_notes: dict[tuple[int, int], str] | None = None,
    dotted: set[tuple[int, int]] | None = None,
) -> str:
    """Graphviz DOT text of the automaton."""
    edge_notes = edge_notes or {}
    dotted = dotted or set()
    lines = [
        "digraph automaton {",
        "  rankdir=LR; bgcolor=white;",
        '  node [shape=circle, fontname="Helvetica", style=filled, fillcolor="#eef3fb"];',
        '  edge [fontname="Helvetica", fontsize=10];',
    ]
    if not show_sink and automaton.rejecting.any():
        note = "labels on no edge lead to the rejecting sink (not drawn)"
        title = f"{title}\n{note}" if title else note
    if title:
        lines.append(f"  labelloc=t; label={_quote(title)};")
    lines.append('  start [shape=point, width=0.08, label=""];')
    for s in range(automaton.n_states):
        if automaton.rejecting[s] and not show_sink:
            continue
        attrs = [f'label="{s}"']
        if automaton.accepting[s]:
            attrs += ["shape=doublecircle", 'fillcolor="#dff5e1"']
        elif automaton.rejecting[s]:
            attrs += ['fillcolor="#f8dddd"']
        lines.append(f"  q{s} [{', '.join(attrs)}];")
    lines.append(f"  start -> q{automaton.initial};")
    for s, t in automaton.edges(include_sink=show_sink):
        label = automaton.guard(s, t, sink_free=not show_sink)
        if (s, t) in edge_notes:
            label += f"\n{edge_notes[(s, t)]}"
        style = ", style=dotted" if (s, t) in dotted else ""
        lines.append(f"  q{s} -> q{t} [label={_quote(label)}{style}];")
    lines.append("}")
    return "\n".join(lines) + "\n"


def image_format(path) -> str:
    """The format ``write_image`` draws ``path`` in, by its suffix (checked before a command
    computes what it draws).

    Raises:
        ValueError: a suffix it cannot draw, naming the path and the ones it can.
        RuntimeError: a format Graphviz draws, where its ``dot`` is not installed.
    """
    fmt = Path(path).suffix.lstrip(".").lower()
    if fmt not in ("png", "svg", "pdf", "dot", "gv"):
        raise ValueError(f"cannot draw to {str(path)!r}: use a .png, .svg, .pdf or .dot file")
    if fmt not in ("dot", "gv") and _dot() is None:
        raise RuntimeError(f"cannot draw {path}: Graphviz 'dot' is not installed (Debian: apt-get install "
                           "graphviz); write a .dot file instead")
    return fmt


def _dot() -> str | None:
    return shutil.which("dot")


def write_image(automaton: Automaton, path, **dot_options) -> Path:
    """Render to PNG, SVG or PDF (by the file suffix) with Graphviz ``dot``; ``.dot`` writes
    text. Its folders are made where missing; a failed render leaves no file."""
    path = Path(path)
    fmt = image_format(path)
    text = to_dot(automaton, **dot_options)
    with atomic_path(path) as tmp:
        if fmt in ("dot", "gv"):
            tmp.write_text(text)
        else:
            result = subprocess.run([_dot(), f"-T{fmt}", "-o", str(tmp)], input=text.encode(), capture_output=True)
            if result.returncode != 0:
                raise RuntimeError(f"dot failed on {path}: {result.stderr.decode().strip()}")
    return path
