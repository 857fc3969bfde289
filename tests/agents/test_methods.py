"""Every method's agent as a member is saved (built, saved, loaded), its table, its row."""

from __future__ import annotations

import numpy as np
import pytest

from craftsuite.agents import AutomatonQTable, static_distillation
from craftsuite.agents.factory import load_agent, make_agent
from craftsuite.methods import METHODS, Method, MethodError, methods_for
from craftsuite.task_registry import resolve_task

GRID, CONT = "CraftSuite/DungeonQuest-Grid7-v0", "CraftSuite/DungeonQuest-Cont-v0"
SMALL_DQN = dict(learning_starts=50, buffer_size=2_000, target_update_interval=100)
SMALL_TD3 = dict(learning_starts=50, buffer_size=2_000, policy_kwargs=dict(net_arch=[32, 32]))


@pytest.fixture(scope="module")
def table():
    spec = resolve_task("DungeonQuest")
    return static_distillation(spec.automaton, completion_reward=spec.completion_reward)


@pytest.fixture(scope="module")
def teacher():
    return make_agent("product-dqn", GRID, seed=0, n_envs=2, **SMALL_DQN)


@pytest.mark.parametrize("method", methods_for("Grid10") + methods_for("Cont"))
def test_every_method_builds_the_agent_its_members_are_saved_as(method, table):
    row = METHODS[method]
    world = "CraftSuite/DungeonQuest-Grid10-v0" if row.world == "Grid" else CONT
    agent = make_agent(method, world, table=table, seed=1, **(SMALL_DQN if row.algorithm == "dqn" else SMALL_TD3))
    assert agent.algorithm == row.algorithm and agent.num_timesteps == 0
    assert (agent.distill is not None) == bool(row.distill)
    assert (type(agent.replay_buffer).__name__ == "CRMReplayBuffer") == bool(row.crm)
    if row.algorithm == "td3":
        assert agent.policy_delay_at(100) == 4 and agent.policy_delay_at(25_000) == 2
    agent.get_env().close()


def test_method_and_world_must_match(table):
    with pytest.raises(ValueError, match="'td3' is for Cont worlds, not CraftSuite/DungeonQuest-Grid7-v0"):
        make_agent("td3", GRID)
    with pytest.raises(ValueError, match="is not a CraftSuite id"):
        make_agent("td3", "Pendulum-v1")
    with pytest.raises(ValueError, match="needs a teacher's table"):
        make_agent("dynamic", GRID)
    with pytest.raises(KeyError, match="unknown method"):
        make_agent("ppo", GRID)


def test_save_load_identical_q_values(teacher, tmp_path):
    path = tmp_path / "teacher.zip"
    teacher.save(path)
    back = load_agent(path)
    obs = np.stack([teacher.observation_space.sample() for _ in range(100)])
    assert np.array_equal(back.q_values(obs), teacher.q_values(obs))


def test_load_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        load_agent(tmp_path / "nope.zip")
    bad = tmp_path / "bad.zip"
    bad.write_bytes(b"garbage")
    with pytest.raises(ValueError, match="not a saved agent"):
        load_agent(bad)


def test_table_round_trip(table, tmp_path):
    a = resolve_task("DungeonQuest").automaton
    back = AutomatonQTable.load(table.save(tmp_path / "t.npz"), a)
    assert np.array_equal(back.q, table.q) and np.array_equal(back.counts, table.counts)


def test_every_method_is_a_row_for_a_world_that_exists():
    assert set(methods_for("Grid10")) | set(methods_for("Cont")) == set(METHODS)
    assert methods_for("Grid7") == methods_for("Grid10")
    with pytest.raises(MethodError, match="METHODS row 'moon-dqn': world 'Moon' does not exist; worlds: Grid, Cont$"):
        Method("moon-dqn", "Moon", "dqn", False)
    with pytest.raises(MethodError, match="algorithm 'dqn' does not run in the Cont world"):
        Method("cont-dqn", "Cont", "dqn", False)
    with pytest.raises(MethodError, match="target takes"):
        Method("td3-nearly", "Cont", "td3", False, target={"rho": 0.5})  # a target without distillation
    with pytest.raises(TypeError):  # the table's rows are read-only, their target too
        METHODS["td3-dynamic-edges"].target["rho"] = 0.5
    assert METHODS["td3-dynamic-edges"].target["rho"] == 1.0 and hash(METHODS["td3-dynamic-edges"])


def test_the_edges_variant_is_the_paper_target_on_edges_never_faded(table):
    paper = make_agent("td3-dynamic", CONT, table=table, **SMALL_TD3).distill
    edges = make_agent("td3-dynamic-edges", CONT, table=table, **SMALL_TD3).distill
    assert (paper.rho, paper.self_loops) == (0.999, True)
    assert (edges.rho, edges.self_loops) == (1.0, False)
    assert edges.seen.sum() < paper.seen.sum()  # the self-loop values are left to the student
    # a keyword still overrides the row, as --hyper does
    assert make_agent("td3-dynamic-edges", CONT, table=table, rho=0.99, **SMALL_TD3).distill.rho == 0.99


def test_each_env_of_a_vector_explores_with_its_own_persistent_noise():
    agent = make_agent("td3", CONT, n_envs=3, action_noise={"type": "persistent", "sigma": 0.6, "resample": 0.1},
                       **SMALL_TD3)
    draws = agent.action_noise()
    assert draws.shape == (3, 2) and len({tuple(d) for d in draws}) == 3


@pytest.mark.parametrize("method, world", [("crm-edges", "CraftSuite/DungeonQuest-Grid10-v0"), ("td3-crm-edges", CONT)])
def test_the_transfer_method_is_counterfactual_experiences_with_the_edges_target(method, world, table):
    # the row composes two components: CRM's replay and the edges-only, never-faded target
    small = SMALL_DQN if METHODS[method].algorithm == "dqn" else SMALL_TD3
    agent = make_agent(method, world, table=table, seed=2, **small)
    assert type(agent.replay_buffer).__name__ == "CRMReplayBuffer"
    assert (agent.distill.rho, agent.distill.self_loops) == (1.0, False)


def test_the_transfer_method_cannot_go_without_the_automaton_state_its_replay_rewrites(table):
    # distilled, yet CRM: its counterfactuals write the one-hot into the observation's last entries
    for method, world in (("crm-edges", "CraftSuite/DungeonQuest-Grid10-v0"), ("td3-crm-edges", CONT)):
        with pytest.raises(MethodError, match=f"method '{method}' cannot run with automaton_state=False: its "
                                              "counterfactual experiences relabel"):
            make_agent(method, world, table=table, automaton_state=False, **SMALL_TD3)
    assert METHODS["td3-dynamic-edges"].observes(False) is False  # a distilled student without CRM still may
