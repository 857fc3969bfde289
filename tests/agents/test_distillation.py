"""Distillation tables and the distilled target's settings, against hand-computed numbers
(the target applied: ``tests/population/test_targets.py``)."""

from __future__ import annotations

import numpy as np
import pytest

from craftsuite.agents import (AutomatonQTable, DistillationError, DistilledTarget, dynamic_distillation,
                               static_distillation)
from craftsuite.automata import compile_ltlf

TOY = compile_ltlf("F(sword) & F(shield)", ("sword", "shield"), cache=False)
SWORD, SHIELD, BOTH = 0b01, 0b10, 0b11


def toy_state(labels):
    return TOY.run([TOY.mask(labels)])


def table(values: dict, shape=TOY.delta.shape) -> AutomatonQTable:
    q = np.zeros(shape)
    counts = np.zeros(shape, dtype=np.int64)
    for (w, s), v in values.items():
        q[w, s], counts[w, s] = v, 1
    return AutomatonQTable(q, counts, TOY.fingerprint, TOY.propositions, "dynamic")


def test_the_target_takes_a_rho_in_0_1_and_self_loops_as_a_bool():
    values = {(0, 0): 50.0, (0, SWORD): 10.0}
    with pytest.raises(ValueError, match="self_loops must be true or false"):
        DistilledTarget(table(values), TOY, self_loops="no")  # e.g. a string from --hyper
    with pytest.raises(ValueError, match=r"rho must be a number in \[0, 1\], got 1.5"):
        DistilledTarget(table(values), TOY, rho=1.5)
    progress_only = DistilledTarget(table(values), TOY, self_loops=False)
    assert progress_only.seen[0].tolist() == [False, True, False, False]  # the self-loop {} left to the student


def test_dynamic_distillation_averages_taken_action_q():
    w = np.array([0, 0, 1, 0])
    sigma = np.array([SWORD, SWORD, 0, 0])
    q = np.array([2.0, 4.0, 5.0, -1.0])
    t = dynamic_distillation(TOY, w, sigma, q)
    assert t.q[0, SWORD] == pytest.approx(3.0) and t.counts[0, SWORD] == 2
    assert t.q[1, 0] == pytest.approx(5.0) and t.q[0, 0] == pytest.approx(-1.0)
    assert t.counts.sum() == 4 and not t.seen[2, BOTH]


def test_static_distillation_matches_hand_value_iteration():
    t = static_distillation(TOY, gamma=0.99)
    s0, s_sword, s_done = TOY.initial, toy_state(["sword"]), toy_state(["sword", "shield"])
    # from 'sword held', the shield completes: -0.1 + 1 (progress) + 100, episode over
    assert t.q[s_sword, SHIELD] == pytest.approx(100.9)
    v1 = 100.9
    assert t.q[s0, BOTH] == pytest.approx(100.9)
    assert t.q[s0, SWORD] == pytest.approx(-0.1 + 1 + 0.99 * v1)
    assert t.q[s0, 0] == pytest.approx(-0.1 + 0.99 * v1)  # no progress, V(0) = 100.9
    assert not t.seen[s_done].any()  # accepting states end the episode: no values


def test_static_sink_is_terminal_and_no_progress():
    a = compile_ltlf("F(b) & (a R !b)", ("a", "b"), cache=False)
    t = static_distillation(a)
    sink = int(np.flatnonzero(a.rejecting)[0])
    to_sink = a.delta[a.initial] == sink
    assert np.allclose(t.q[a.initial, to_sink], -0.1)


def test_save_load_and_clear_errors(tmp_path):
    t = static_distillation(TOY)
    path = t.save(tmp_path / "toy.npz")
    back = AutomatonQTable.load(path, TOY)
    assert np.array_equal(back.q, t.q) and back.kind == "static"
    other = compile_ltlf("F(sword)", ("sword", "shield"), cache=False)
    with pytest.raises(DistillationError, match="distilled for automaton"):
        AutomatonQTable.load(path, other)
    with pytest.raises(DistillationError, match="distilled for automaton"):
        DistilledTarget(t, other)
    path.write_bytes(b"garbage")
    with pytest.raises(DistillationError, match="not a CraftSuite distilled table"):
        AutomatonQTable.load(path)
    with pytest.raises(FileNotFoundError):
        AutomatonQTable.load(tmp_path / "missing.npz")
    diverged = table({(0, SWORD): 0.5, (1, SHIELD): np.nan, (2, SWORD): np.inf})
    with pytest.raises(DistillationError, match=r"^the table's values are not all finite \(2 of \d+, the first nan on "
                                                r"the edge from automaton state 1 under label 2\)"):
        diverged.save(tmp_path / "diverged.npz")
    assert not (tmp_path / "diverged.npz").exists()
    np.savez(tmp_path / "edited.npz", q=diverged.q, counts=diverged.counts,  # (written by hand: save refuses it)
             meta=np.load(t.save(tmp_path / "good.npz"))["meta"])
    with pytest.raises(DistillationError, match=r"edited.npz's values are not all finite \(2 of"):
        AutomatonQTable.load(tmp_path / "edited.npz", TOY)


def test_describe_lists_edges():
    text = static_distillation(TOY).describe(TOY)
    assert "100.90" in text and "->" in text


def test_distill_writes_neither_drawing_nor_table_of_values_that_are_not_finite(tmp_path):
    from types import SimpleNamespace

    from craftsuite.cli import _write_table

    diverged = table({(0, SWORD): np.nan})
    args = SimpleNamespace(draw=str(tmp_path / "values.png"), out=str(tmp_path / "table.npz"))
    with pytest.raises(DistillationError, match="^the table's values are not all finite"):
        _write_table(diverged, TOY, args)
    assert list(tmp_path.iterdir()) == []
