"""The on-disk automaton cache and Graphviz drawing."""

from __future__ import annotations

import multiprocessing as mp
import shutil

import numpy as np
import pytest

from craftsuite.automata import compile as compile_module
from craftsuite.automata import compile_ltlf, to_dot, write_image
from craftsuite.spec import builtin_specs

FORMULA = "G(wood -> F factory) & F(tools3 & home)"
PROPS = ("wood", "factory", "tools3", "home")


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("CRAFTSUITE_CACHE_DIR", str(tmp_path))
    return tmp_path / "automata"


def test_second_compile_loads_from_cache(cache, monkeypatch):
    first = compile_ltlf(FORMULA, PROPS)
    assert len(list(cache.glob("*.npz"))) == 1

    def no_compiling(*args):
        raise AssertionError("compiled again instead of loading the cache")

    monkeypatch.setattr(compile_module, "progress_to_dfa", no_compiling)
    second = compile_ltlf(FORMULA, PROPS)
    assert np.array_equal(first.delta, second.delta)
    assert second.fingerprint == first.fingerprint


def test_cache_key_includes_propositions(cache):
    a = compile_ltlf("F a", ("a", "b"))
    b = compile_ltlf("F a", ("b", "a"))
    assert len(list(cache.glob("*.npz"))) == 2
    assert a.fingerprint != b.fingerprint


def test_corrupt_cache_is_recompiled_and_rewritten(cache, caplog):
    good = compile_ltlf(FORMULA, PROPS)
    (path,) = cache.glob("*.npz")
    path.write_bytes(b"not an npz file")
    again = compile_ltlf(FORMULA, PROPS)
    assert np.array_equal(again.delta, good.delta)
    assert "unreadable automaton cache" in caplog.text
    with np.load(path) as f:  # rewritten whole
        assert f["delta"].shape == good.delta.shape


def test_a_cached_table_that_is_no_dfa_is_recompiled(cache, caplog):
    good = compile_ltlf(FORMULA, PROPS)
    (path,) = cache.glob("*.npz")
    np.savez(path, formula=good.formula, propositions=np.array(good.propositions), delta=good.delta[:, :1],
             accepting=good.accepting)
    assert np.array_equal(compile_ltlf(FORMULA, PROPS).delta, good.delta)
    assert "unreadable automaton cache" in caplog.text and "delta must be an integer array of shape" in caplog.text


def test_unwritable_cache_still_compiles(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("a file where the cache directory should be")
    monkeypatch.setenv("CRAFTSUITE_CACHE_DIR", str(blocker))
    assert compile_ltlf("F a", ("a",)).n_states == 2


def _compile_in_child(args):
    cache_dir, formula, props = args
    import os
    os.environ["CRAFTSUITE_CACHE_DIR"] = cache_dir
    return compile_ltlf(formula, props).fingerprint


@pytest.mark.slow  # four spawned processes
def test_parallel_processes_share_the_cache(cache):
    spec = builtin_specs()["DiamondMine"]
    args = [(str(cache.parent), spec.formula, spec.proposition_names)] * 4
    with mp.get_context("spawn").Pool(4) as pool:
        prints = pool.map(_compile_in_child, args)
    assert len(set(prints)) == 1
    assert len(list(cache.glob("*.npz"))) == 1
    assert not list(cache.glob("*.tmp"))  # no half-written files left behind
    assert compile_ltlf(spec.formula, spec.proposition_names).fingerprint == prints[0]


def test_dot_has_states_guards_and_no_sink():
    a = builtin_specs()["DungeonQuest"].automaton
    dot = to_dot(a, title="Dungeon Quest")
    sink = int(np.flatnonzero(a.rejecting)[0])
    assert f"q{sink} " not in dot and f"-> q{sink}" not in dot
    assert dot.count("doublecircle") == 1
    assert "labels on no edge lead to the rejecting sink" in dot
    key = int(a.delta[0, a.mask(["key"])])
    assert f'q0 -> q{key} [label="key & !shield"]' in dot
    assert f"q{sink}" in to_dot(a, show_sink=True)


def test_edge_notes_and_dotted_edges():
    a = builtin_specs()["BlindCraftsman"].automaton
    dot = to_dot(a, edge_notes={(0, 1): "Q=3.5"}, dotted={(0, 2)})
    assert "Q=3.5" in dot
    assert "style=dotted" in dot


@pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz 'dot' is not installed")
@pytest.mark.parametrize("suffix, magic", [(".png", b"\x89PNG"), (".svg", b"<?xml")])
def test_write_image(tmp_path, suffix, magic):
    a = builtin_specs()["DiamondMine"].automaton
    out = write_image(a, tmp_path / f"diamond{suffix}")
    assert out.read_bytes().startswith(magic)


def test_write_image_rejects_unknown_format(tmp_path):
    a = builtin_specs()["BlindCraftsman"].automaton
    with pytest.raises(ValueError, match="use a .png"):
        write_image(a, tmp_path / "x.jpg")
