"""``craftsuite.reached``: how far along the task an episode got, as bits of the automaton's
states (what a student logs of its episodes: ``tests/population/test_reached.py``)."""

import numpy as np
import pytest


def test_an_automaton_too_large_for_the_states_bits_is_refused():
    from craftsuite.automata import Automaton
    from craftsuite.reached import MAX_STATES, Reached, check_automaton

    def chain(n):  # n states, one proposition: each step moves to the next, the last accepts
        delta = np.array([[q, min(q + 1, n - 1)] for q in range(n)], dtype=np.int16)
        return Automaton(f"chain of {n}", ("p",), delta, np.arange(n) == n - 1)

    check_automaton(chain(MAX_STATES), "Long")  # states 0 to 62: bit 62 of a signed 64-bit integer
    reached = Reached(chain(MAX_STATES), 2)
    reached.step(np.array([1, 0]), np.array([MAX_STATES - 1, 0]))
    assert reached.take(np.array([True, False])) == ([1], [1 | 1 << (MAX_STATES - 1)])
    assert reached.states.tolist() == [1, 1] and reached.seen.tolist() == [0, 0]  # env 0 starts anew
    with pytest.raises(ValueError, match=r"task 'Longer': its automaton has 64 states.*states 0 to 62"):
        Reached(chain(MAX_STATES + 1), 1, "Longer")
