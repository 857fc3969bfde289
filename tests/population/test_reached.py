"""The population engine logs how far along the task each training episode got
(episodes.csv's ``seen`` and ``states``), in every world: checked against what the envs
said, step by step, through another door (their infos' labels and states, the final infos
where an episode ended)."""

import numpy as np
import pytest

import craftsuite  # noqa: F401
from craftsuite.configs import StudentConfig
from craftsuite.population import train_population
from craftsuite.population import train as population_train
from craftsuite.runs import read_csv
from craftsuite.task_registry import resolve_task

# learning never starts: every action is the engine's seeded random one, so that some
# episodes complete the task whatever torch computes
RANDOM = {"batch_size": 32, "learning_starts": 100_000, "policy_kwargs": {"net_arch": [8]}}
TD3 = {**RANDOM, "prioritized": False, "action_noise": {"type": "normal", "sigma": 0.1}}


class Recorder:
    """A vector env that notes, per step and env, the label mask and automaton state the
    step ended in, and whether the env's episode ended there."""

    def __init__(self, envs):
        self.envs, self.steps = envs, []

    def __getattr__(self, name):
        return getattr(self.envs, name)

    def step(self, actions):
        out = self.envs.step(actions)
        ended, info = out[2] | out[3], out[4]
        masks, states = info["label_mask"].copy(), info["automaton_state"].copy()
        if ended.any():  # the infos are the next episode's start there; the ending step's are final_info's
            final = info["final_info"]
            masks[ended], states[ended] = final["label_mask"][ended], final["automaton_state"][ended]
        self.steps.append((masks, states, ended))
        return out


def _expected(steps, n_envs, automaton):
    """Each env's ended episodes' (seen, states), in the order the engine logs them."""
    seen, states = [0] * n_envs, [1 << automaton.initial] * n_envs
    rows = []
    for masks, reached, ended in steps:
        for i in range(n_envs):
            seen[i] |= int(masks[i])
            states[i] |= 1 << int(reached[i])
            if ended[i]:
                rows.append((i, seen[i], states[i]))
                seen[i], states[i] = 0, 1 << automaton.initial
    return rows


@pytest.mark.parametrize("task,method,world,hyper,kwargs", [
    ("FirstTool", "dqn", "Grid7", RANDOM, {"layout_seed": 0, "world_kwargs": {"max_episode_steps": 60}}),
    ("Reach", "td3", "Kinematic", TD3, {"world_kwargs": {"max_episode_steps": 40}}),
    ("Reach", "td3", "Cont", TD3, {"world_kwargs": {"frame_skip": 10, "max_episode_steps": 40}}),
])
def test_members_log_what_their_episodes_reached(tmp_path, monkeypatch, task, method, world, hyper, kwargs):
    n, seeds = 3, (0, 1)
    configs = [StudentConfig(task=task, method=method, world=world, seed=s, steps=1_200, eval_every=1_200,
                             eval_episodes=1, hyperparameters=hyper, n_envs=n, engine="population", **kwargs)
               for s in seeds]
    made, make_envs = [], population_train.make_envs

    def recording(*args, **kw):
        made.append(Recorder(make_envs(*args, **kw)))
        return made[-1]

    monkeypatch.setattr(population_train, "make_envs", recording)
    paths = train_population(configs, tmp_path, progress=False)
    automaton = resolve_task(task).automaton
    expected = _expected(made[0].steps, len(seeds) * n, automaton)  # made[0]: the training envs
    accepting = sum(1 << q for q in np.flatnonzero(automaton.accepting).tolist())
    logged = []
    for k, path in enumerate(paths):
        episodes = read_csv(path / "episodes.csv")
        assert len(episodes) >= n  # at least one episode of each env
        assert [(int(e["seen"]), int(e["states"])) for e in episodes] == \
            [(s, q) for i, s, q in expected if i // n == k]
        logged += [(int(e["success"]), int(e["seen"]), int(e["states"])) for e in episodes]
    for success, seen, states in logged:
        assert states >> automaton.initial & 1  # every episode starts in the initial state
        assert bool(states & accepting) == bool(success)  # these worlds end an episode where it is accepted
        if success:  # completed: each of the task's propositions held on the way (F wood, F(wood & F factory))
            assert seen == (1 << len(automaton.propositions)) - 1
    assert 0 < sum(s for s, _, _ in logged) < len(logged)  # random moves complete some episodes, not all
    if task == "FirstTool":  # the factory entered before any wood: its bit is set, the automaton stays at its start
        assert (0, 0b10, 0b001) in logged
