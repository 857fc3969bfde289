"""The SB3 trainer logs how far along the task each training episode got (episodes.csv's
``seen`` and ``states``), in every world: checked against what the training envs' objective
trackers read, step by step."""

import collections

import numpy as np
import pytest

import craftsuite  # noqa: F401
from craftsuite.configs import StudentConfig
from craftsuite.runs import read_csv
from craftsuite.task_registry import resolve_task
from craftsuite.tracking import ObjectiveTracker
from craftsuite.training import train_student

# learning never starts: every action is a seeded random one, so that some episodes complete the task
RANDOM = {"learning_starts": 100_000, "policy_kwargs": {"net_arch": [8]}}


@pytest.mark.parametrize("task,method,world,hyper,kwargs", [
    ("FirstTool", "dqn", "Grid7", RANDOM, {"layout_seed": 0, "world_kwargs": {"max_episode_steps": 60}}),
    ("Reach", "td3", "Kinematic", RANDOM, {"world_kwargs": {"max_episode_steps": 40}}),
    ("Reach", "td3", "Cont", RANDOM, {"world_kwargs": {"frame_skip": 10, "max_episode_steps": 40}}),
])
def test_a_student_logs_what_its_episodes_reached(tmp_path, monkeypatch, task, method, world, hyper, kwargs):
    import craftsuite.agents.factory as factory

    # each tracker made while the agent is built (its training envs'): its episodes' (length, seen, states)
    episodes: dict[int, list[list[int]]] = {}
    building = {"now": False}
    automaton = resolve_task(task).automaton
    start, init, reset, advance = 1 << automaton.initial, ObjectiveTracker.__init__, ObjectiveTracker.reset, \
        ObjectiveTracker.advance

    def spy_init(self, spec):
        init(self, spec)
        if building["now"]:
            episodes[id(self)] = []

    def spy_reset(self):
        if id(self) in episodes:
            episodes[id(self)].append([0, 0, start])
        return reset(self)

    def spy_advance(self, mask):
        out = advance(self, mask)
        if id(self) in episodes:
            episode = episodes[id(self)][-1]
            episode[0] += 1
            episode[1] |= mask
            episode[2] |= 1 << self.state
        return out

    def make_agent(*args, **kw):
        building["now"] = True
        try:
            return real_make(*args, **kw)
        finally:
            building["now"] = False

    real_make = factory.make_agent
    monkeypatch.setattr(ObjectiveTracker, "__init__", spy_init)
    monkeypatch.setattr(ObjectiveTracker, "reset", spy_reset)
    monkeypatch.setattr(ObjectiveTracker, "advance", spy_advance)
    monkeypatch.setattr(factory, "make_agent", make_agent)
    config = StudentConfig(task=task, method=method, world=world, steps=1_200, eval_every=1_200, eval_episodes=1,
                           hyperparameters=hyper, n_envs=2, engine="sb3", **kwargs)  # its agent's envs spied on
    path = train_student(config, tmp_path, progress=False)
    assert len(episodes) == 2  # the two training envs
    # every episode but each env's last, still running when training stopped (or never stepped)
    ended = [tuple(e) for played in episodes.values() for e in played[:-1] if e[0]]
    logged = [(int(e["length"]), int(e["seen"]), int(e["states"]), int(e["success"]))
              for e in read_csv(path / "episodes.csv")]
    assert len(logged) >= 2
    assert collections.Counter(row[:3] for row in logged) == collections.Counter(ended)
    accepting = sum(1 << q for q in np.flatnonzero(automaton.accepting).tolist())
    for _, seen, states, success in logged:
        assert states & start  # every episode starts in the initial state
        assert bool(states & accepting) == bool(success)  # these worlds end an episode where it is accepted
        if success:  # completed: each of the task's propositions held on the way
            assert seen == (1 << len(automaton.propositions)) - 1
    assert 0 < sum(row[3] for row in logged) < len(logged)  # random moves complete some episodes, not all


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
