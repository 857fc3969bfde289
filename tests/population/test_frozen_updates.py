"""Frozen updates: every learning rule computes today what it computed when its fixture
was frozen (``frozen/<case>.npz``, made by ``frozen/make.py``, whose docstring says what a
case runs, what a fixture holds and when regenerating one is right).

The population engine holds every learning rule CraftSuite trains with, once; these
fixtures are its rules' record. Until commit 85ab46c the SB3 agents (``craftsuite.agents``)
had rules of their own and were driven on the same inputs (the same replay contents,
sampling draws, torch seeds and initial networks) to reproduce every fixture their rules
covered (all but the residual CNN, n-step CRM and reward shaping). Also: the grid
students' sparse replay, and member 0 of a population of three, reproduce the one-member
fixture.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
import torch as th

from .frozen import make

# rtol 1e-5, atol 1e-6 times the array's largest magnitude: other kernels (the sparse
# replay's sum of weight rows, another member's batch shapes) round otherwise. When the SB3
# stack still reproduced the fixtures with its own kernels (nn.Linear, not baddbmm), its
# largest difference was 1.8e-7 of the array's scale (a loss), 3e-8 on parameters
RTOL, ATOL = 1e-5, 1e-6


@pytest.fixture(autouse=True)
def _one_thread():
    """One torch thread and deterministic kernels: the fixtures were made so."""
    threads, deterministic = th.get_num_threads(), th.are_deterministic_algorithms_enabled()
    th.set_num_threads(1)
    th.use_deterministic_algorithms(True)
    yield
    th.set_num_threads(threads)
    th.use_deterministic_algorithms(deterministic)


@functools.cache
def _fixture(name: str) -> dict:
    with np.load(make.path(name), allow_pickle=False) as f:
        return {k: f[k] for k in f.files if k != "about"}


@functools.cache
def _population(name: str, sparse: bool = False, members: int = 1) -> dict:
    return make.run(name, sparse=sparse, members=members)


def _differences(got: dict, want: dict, rtol: float = RTOL, atol: float = ATOL, keys=None) -> list[str]:
    """What of ``want`` ``got`` does not reproduce, one line each: integers and booleans
    exactly, floats to ``rtol`` and ``atol`` times the array's largest magnitude (at least 1)."""
    out = []
    for key in keys if keys is not None else want:
        if key not in got:
            out.append(f"{key}: missing")
            continue
        a, b = np.asarray(got[key]), np.asarray(want[key])
        if a.shape != b.shape:
            out.append(f"{key}: shape {a.shape}, frozen {b.shape}")
        elif b.dtype.kind in "biu":
            wrong = a != b
            if wrong.any():
                out.append(f"{key}: {int(wrong.sum())} of {a.size} differ{_from(wrong)}")
        else:
            scale = max(1.0, float(np.abs(b).max(initial=0.0)))
            wrong = ~np.isclose(a, b, rtol=rtol, atol=atol * scale)
            if wrong.any():
                worst = np.abs(a.astype(np.float64) - b).max()
                out.append(f"{key}: largest difference {worst:.3g} (scale {scale:.3g}){_from(wrong)}")
    return out


def _from(wrong: np.ndarray) -> str:
    """For a per-update array ``(UPDATES, ...)``: the first update it differs at."""
    if wrong.ndim < 2 or wrong.shape[0] != make.UPDATES:
        return ""
    return f", from update {int(wrong.reshape(make.UPDATES, -1).any(axis=1).argmax())}"


def _report(differences: list[str], name: str, who: str) -> str:
    return (f"{who} no longer reproduces frozen case {name!r} ({make.CASES[name]}):\n  " + "\n  ".join(differences)
            + "\n(inputs first: automaton_*/input_digest/init_digest differ when the inputs changed, not a rule; "
              "batch_* when sampling, n-step returns, CRM or shaping did; targets/td/losses when the target or "
              "loss did. Regenerate only for a deliberate change of a learning rule: frozen/make.py)")


def test_every_case_has_a_small_fixture():
    sizes = {name: make.path(name).stat().st_size for name in make.CASES}
    assert sum(sizes.values()) < 400_000, sizes


@pytest.mark.parametrize("name", list(make.CASES))
def test_the_population_engine_reproduces_the_frozen_update(name):
    want = _fixture(name)
    differences = _differences(_population(name), want)
    assert not differences, _report(differences, name, "the population engine")


@pytest.mark.parametrize("name", ["dqn", "crm-n3", "crm-edges", "dqn-residual-cnn"])
def test_a_sparse_replay_reproduces_the_dense_fixture(name):
    """The grid students' replay (observations as their nonzero entries, the first layer a
    sum of weight rows, or planes made whole again for a CNN; CRM's one-hot moved in them)
    learns as the dense one."""
    differences = _differences(_population(name, sparse=True), _fixture(name))
    assert not differences, _report(differences, name, "the sparse replay")


@pytest.mark.parametrize("name", ["dqn", "dqn-transitions", "crm-edges-n3", "td3", "td3-dynamic",
                                  "dqn-residual-cnn"])
def test_member_zero_of_a_population_of_three_reproduces_the_fixture(name):
    """Members learn apart: member 0, beside two members with other minibatches (their own
    counts, gradient norms, priorities), learns as the one-member population did."""
    want = {k: v for k, v in _fixture(name).items() if not k.endswith("losses")}  # summed over members
    differences = _differences(_population(name, members=3), want)
    assert not differences, _report(differences, name, "member 0 of three")
