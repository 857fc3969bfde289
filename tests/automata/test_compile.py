"""The LTLf compiler against flloat (language equivalence) and the paper's automaton sizes."""

from __future__ import annotations

import random
from collections import deque

import numpy as np
import pytest

from craftsuite.automata import LTLfSyntaxError, compile_ltlf
from craftsuite.automata.ltlf import atoms, parse, to_string
from craftsuite.spec import builtin_specs

TOY = ("F(sword) & F(shield)", ("sword", "shield"))
TWO_TRACES = ("F(b | e) & (!F(a) | !F(c)) & (a R !b) & (c R !d) & (d R !e)", tuple("abcde"))


def flloat_equivalent(formula: str, props: tuple[str, ...], reference: str | None = None) -> tuple[bool, str]:
    """Walk our DFA and flloat's side by side over every label; compare acceptance.

    Only non-empty words are compared: flloat (LDLf semantics) accepts the empty trace for
    some formulas (``G a``), CraftSuite never does (LTLf traces are non-empty).
    """
    from flloat.parser.ltlf import LTLfParser

    ours = compile_ltlf(formula, props, cache=False)
    theirs = LTLfParser()(reference or formula).to_automaton()
    symbols = [{p: bool(m >> i & 1) for i, p in enumerate(props)} for m in range(1 << len(props))]

    def their_step(q, m):
        return None if q is None else theirs.get_successor(q, symbols[m])

    def their_accepts(q):
        return q is not None and q in theirs.accepting_states

    start = (ours.initial, theirs.initial_state)
    seen = {start}
    queue = deque([(start, ())])
    while queue:
        (s, q), word = queue.popleft()
        for m in range(1 << len(props)):
            pair = (ours.step(s, m), their_step(q, m))
            if bool(ours.accepting[pair[0]]) != their_accepts(pair[1]):
                return False, f"differ on word {[sorted(ours.labels(x)) for x in word + (m,)]}"
            if pair not in seen:
                seen.add(pair)
                queue.append((pair, word + (m,)))
    return True, ""


def test_equivalence_check_detects_a_difference():
    ok, why = flloat_equivalent("F(a) & F(b)", ("a", "b"), reference="F(a) | F(b)")
    assert not ok and "differ on word" in why


@pytest.mark.parametrize("task", ["BlindCraftsman", "DungeonQuest"])
def test_equivalent_to_flloat_on_paper_tasks(task):
    spec = builtin_specs()[task]
    ok, why = flloat_equivalent(spec.formula, spec.proposition_names)
    assert ok, why


@pytest.mark.parametrize("formula, props", [TOY, pytest.param(*TWO_TRACES, marks=pytest.mark.slow)],
                         ids=["toy", "two-traces"])  # flloat takes seconds on five propositions
def test_equivalent_to_flloat_on_paper_figures(formula, props):
    ok, why = flloat_equivalent(formula, props)
    assert ok, why


_UNARY = ["not", "X", "WX", "F", "G"]
_BINARY = ["and", "or", "implies", "U", "R"]


def random_formula(rng: random.Random, props, depth: int):
    if depth == 0 or rng.random() < 0.25:
        return ("ap", rng.choice(props))
    if rng.random() < 0.4:
        return (rng.choice(_UNARY), random_formula(rng, props, depth - 1))
    return (rng.choice(_BINARY), random_formula(rng, props, depth - 1),
            random_formula(rng, props, depth - 1))


def _random_cases(n=40, seed=7):
    rng = random.Random(seed)
    cases, used = [], set()
    while len(cases) < n:
        ast = random_formula(rng, ["a", "b", "c"], depth=3)
        text = to_string(ast)
        if text not in used:
            used.add(text)
            cases.append(text)
    return cases


def test_random_formulas_cover_every_operator():
    seen = set()

    def walk(node):
        seen.add(node[0])
        for child in node[1:]:
            if isinstance(child, tuple):
                walk(child)

    for text in _random_cases():
        walk(parse(text))
    assert set(_UNARY + _BINARY) <= seen


@pytest.mark.parametrize("formula", _random_cases())
def test_equivalent_to_flloat_on_random_formulas(formula):
    props = tuple(sorted(atoms(parse(formula))))
    ok, why = flloat_equivalent(formula, props)
    assert ok, f"{formula}: {why}"


@pytest.mark.parametrize("task, size", [
    ("BlindCraftsman", (4, 12)), ("DungeonQuest", (7, 17)), ("DiamondMine", (15, 29)),
])
def test_paper_automaton_sizes(task, size):
    spec = builtin_specs()[task]
    automaton = compile_ltlf(spec.formula, spec.proposition_names, cache=False)
    assert automaton.size() == size


def test_minimal():
    # F a & F a & (F a | F a) is F a: two states, whatever the syntax.
    automaton = compile_ltlf("F a & F a & (F a | F a)", ("a",), cache=False)
    assert automaton.n_states == 2


def test_rejecting_sink_and_traces():
    spec = builtin_specs()["DiamondMine"]
    a = spec.automaton
    assert a.rejecting.sum() == 1
    wood_then_gold = [a.mask(["wood"]), a.mask(["gold1"])]
    assert a.rejecting[a.run(wood_then_gold)]
    golds = [a.mask([f"gold{k}"]) for k in range(1, 11)]
    assert a.accepts(golds + [a.mask(["home"])])
    assert not a.accepts(golds)
    assert a.rejecting[a.run([a.mask(["home"])])]  # home before the goal


def test_empty_trace_rejected():
    a = compile_ltlf("G a", ("a",), cache=False)
    assert not a.accepting[a.initial]
    assert a.accepts([1]) and not a.accepts([1, 0])


def test_unused_propositions_are_dont_care():
    a = compile_ltlf("F a", ("z", "a"), cache=False)
    assert a.delta.shape == (2, 4)
    assert a.accepts([0b10]) and a.accepts([0b11]) and not a.accepts([0b01])


@pytest.mark.parametrize("bad, message", [
    ("F(wood", "expected ')'"),
    ("wood &", "end of the formula"),
    ("G(wood -> F factory) $ home", "unexpected character '$'"),
    ("U wood", "left operand"),
    ("", "empty"),
])
def test_syntax_errors_name_the_problem(bad, message):
    with pytest.raises(LTLfSyntaxError, match=message.replace("(", r"\(").replace(")", r"\)").replace("$", r"\$")):
        compile_ltlf(bad, ("wood", "factory", "home"), cache=False)


@pytest.mark.parametrize("deep", ["(" * 2000 + "a" + ")" * 2000, "!" * 3000 + "a", " & ".join(["a"] * 3000)])
def test_a_formula_nested_past_pythons_stack_is_a_syntax_error(deep):
    with pytest.raises(LTLfSyntaxError, match=r"^the formula nests too deeply \(operators within operators\)"):
        compile_ltlf(deep, ("a",), cache=False)
    assert parse("(" * 20 + "a" + ")" * 20) == ("ap", "a")


def test_unknown_proposition_is_named():
    with pytest.raises(ValueError,
                       match=r"^unknown proposition 'gold'; propositions: wood \(declared for formula 'F\(gold\)'\)$"):
        compile_ltlf("F(gold)", ("wood",), cache=False)


def test_bad_proposition_lists():
    with pytest.raises(ValueError, match="duplicate"):
        compile_ltlf("F a", ("a", "a"), cache=False)
    with pytest.raises(ValueError, match="at most 16"):
        compile_ltlf("F a", ("a",) + tuple(f"p{i}" for i in range(16)), cache=False)
    with pytest.raises(ValueError, match="lower-case identifier"):
        compile_ltlf("F a", ("a", "Tools>=3"), cache=False)
    for text in ("wood", "ab"):  # tuple() of a string is its letters: 'ab' was read as a and b
        with pytest.raises(ValueError, match=rf"^propositions must be a sequence of names, got the string '{text}'"):
            compile_ltlf("F wood", text, cache=False)


def test_a_table_that_is_no_dfa_and_labels_out_of_range_are_refused():
    import dataclasses

    from craftsuite.automata import Automaton

    good = compile_ltlf("F a & F b", ("a", "b"), cache=False)
    delta, accepting = np.array(good.delta), np.array(good.accepting)
    for field, value, message in [
        ("delta", delta[:, :2], r"delta must be an integer array of shape \(n_states, 4\) for 2 propositions"),
        ("delta", delta.astype(float), "delta must be an integer array"),
        ("delta", np.where(delta == 0, -1, delta), r"delta's entries must be states 0-3, got -1-3"),
        ("delta", np.where(delta == 0, 9, delta), r"delta's entries must be states 0-3, got 1-9"),
        ("accepting", accepting[:2], r"accepting must be a bool array of shape \(4,\)"),
        ("initial", 4, "initial must be a state 0-3, got 4"),
    ]:
        with pytest.raises(ValueError, match=message):
            Automaton(**{"formula": good.formula, "propositions": good.propositions, "delta": delta,
                         "accepting": accepting, field: value})
    assert Automaton(good.formula, good.propositions, delta, accepting).fingerprint == good.fingerprint
    with pytest.raises(ValueError, match=r"^labels must be a collection of proposition names, got the string 'a'"):
        good.mask("a")
    for mask in (-1, 4):
        with pytest.raises(ValueError, match=rf"^mask must be a label bitmask 0-3, got {mask}$"):
            good.labels(mask)
    assert good.labels(3) == {"a", "b"} and dataclasses.is_dataclass(good)


def test_parse_roundtrip():
    rng = random.Random(3)
    for _ in range(50):
        ast = random_formula(rng, ["p", "q"], 4)
        assert parse(to_string(ast)) == ast


def test_precedence_matches_flloat():
    # unary binds tighter than R, R than U, U than &, & than |, | than ->
    assert parse("!a R b U c & d | e -> f") == (
        "implies",
        ("or", ("and", ("U", ("R", ("not", ("ap", "a")), ("ap", "b")), ("ap", "c")), ("ap", "d")),
         ("ap", "e")),
        ("ap", "f"),
    )


@pytest.mark.parametrize("task", ["DungeonQuest", "DiamondMine"])
@pytest.mark.parametrize("sink_free", [False, True])
def test_guards_are_exact(task, sink_free):
    """A guard holds on exactly the labels of its edge (sink_free: labels to the sink are free)."""
    a = builtin_specs()[task].automaton
    names = a.propositions
    masks = np.arange(1 << len(names))
    bits = {p: (masks >> i & 1).astype(bool) for i, p in enumerate(names)}
    for s in range(a.n_states):
        for t in np.unique(a.delta[s]).tolist():
            guard = a.guard(s, t, sink_free=sink_free)
            expr = guard.replace("!", " ~").replace("true", "ALL")
            value = eval(expr, {"ALL": np.ones(len(masks), bool)}, bits)
            to_t = a.delta[s] == t
            free = a.rejecting[a.delta[s]] if sink_free and not a.rejecting[t] else np.zeros_like(to_t)
            assert (value[to_t]).all() and not (value & ~to_t & ~free).any(), (s, t, guard)
    if task == "DiamondMine":
        assert a.guard(0, int(a.delta[0, a.mask(["gold1"])]), sink_free=True) == "gold1"
