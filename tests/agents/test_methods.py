"""Smoke training of every method, teacher distillation, save/load."""

from __future__ import annotations

import numpy as np
import pytest

from craftsuite.agents import AutomatonQTable
from craftsuite.agents.factory import distill_from_replay, load_agent, make_agent
from craftsuite.methods import METHODS, Method, MethodError, methods_for

GRID, CONT = "CraftSuite/DungeonQuest-Grid7-v0", "CraftSuite/DungeonQuest-Cont-v0"
SMALL_DQN = dict(learning_starts=50, buffer_size=2_000, target_update_interval=100)
SMALL_TD3 = dict(learning_starts=50, buffer_size=2_000, policy_kwargs=dict(net_arch=[32, 32]))


@pytest.fixture(scope="module")
def teacher():
    agent = make_agent("product-dqn", GRID, seed=0, n_envs=2, **SMALL_DQN)
    agent.learn(400)
    return agent


@pytest.fixture(scope="module")
def table(teacher):
    return distill_from_replay(teacher)


def test_teacher_distills_a_table(teacher, table):
    assert table.kind == "dynamic" and table.counts.sum() == 400
    a = teacher.get_env().envs[0].unwrapped.automaton
    table.check(a)
    start = a.initial
    assert table.seen[start, 0]  # 'nothing happened' from the start was certainly seen


SB3_ROWS = {world: [m for m in methods_for(world) if not METHODS[m].shaping] for world in ("Grid10", "Cont")}


@pytest.mark.parametrize("method", SB3_ROWS["Grid10"])  # shaping: the population engine's (test_shaping)
def test_grid_methods_train(method, table):
    agent = make_agent(method, "CraftSuite/DungeonQuest-Grid10-v0", table=table, seed=1, **SMALL_DQN)
    agent.learn(300)
    assert agent.num_timesteps == 300 and agent.n_updates > 0
    if METHODS[method].distill:
        assert agent.distill.student_counts.sum() > 0
    if METHODS[method].crm:
        assert agent.replay_buffer.pos == 300  # rows of real steps, each with its counterfactuals
        assert agent.replay_buffer.n_envs == agent.replay_buffer.n_live


@pytest.mark.parametrize("method", SB3_ROWS["Cont"])
def test_cont_methods_train(method, table):
    agent = make_agent(method, CONT, table=table, seed=1, **SMALL_TD3)
    agent.learn(200)
    assert agent.num_timesteps == 200 and agent.n_updates > 0
    assert agent.policy_delay_at(100) == 4 and agent.policy_delay_at(25_000) == 2


@pytest.mark.parametrize("method", ["td3-dynamic", "product-dqn"])
def test_n_step_targets_bootstrap_with_the_buffers_discounts(method, table):
    import torch as th

    world = CONT if method.startswith("td3") else GRID
    small = dict(SMALL_TD3, target_policy_noise=0.0) if method.startswith("td3") else SMALL_DQN
    agent = make_agent(method, world, table=table, seed=2, n_steps=4, gamma=0.9, **small)
    agent.learn(150)
    buf = agent.replay_buffer
    assert (buf.n_steps, buf.gamma) == (4, 0.9)
    data = buf.sample(64)
    k = np.log(data.discounts.numpy().ravel()) / np.log(0.9)  # gamma ** k after k rewards
    assert np.allclose(k, np.round(k)) and set(np.round(k)) <= {1, 2, 3, 4}
    assert (data.discounts.numpy() < 0.7).any()  # some windows run all four steps
    with th.no_grad():
        if method.startswith("td3"):
            nxt = agent.critic_target(data.next_observations, agent.actor_target(data.next_observations))
            next_q = th.min(th.cat(nxt, dim=1), dim=1, keepdim=True)[0]
        else:
            best = agent.q_net(data.next_observations).argmax(dim=1, keepdim=True)
            next_q = th.gather(agent.q_net_target(data.next_observations), 1, best)
        expected = data.rewards + (1 - data.dones) * data.discounts * next_q
        if agent.distill is not None:
            agent.distill.student_counts[:] = 10**6  # beta = 0: the student's own target alone
            expected = agent.distill(data.w, data.sigma, expected)
        assert th.allclose(agent._td_target(data), expected)
    crm = make_agent("crm", GRID, n_steps=3, **SMALL_DQN)  # built (a population member is saved so) ...
    with pytest.raises(ValueError, match="samples windows in the population engine only"):
        crm.learn(150)  # ... but its one-step counterfactual replay never samples n-step CRM


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
    obs = teacher.replay_buffer.observations[:50].reshape(100, -1)
    assert np.array_equal(back.q_values(obs), teacher.q_values(obs))


def test_load_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        load_agent(tmp_path / "nope.zip")
    bad = tmp_path / "bad.zip"
    bad.write_bytes(b"garbage")
    with pytest.raises(ValueError, match="not a saved agent"):
        load_agent(bad)


def test_table_round_trip(table, tmp_path, teacher):
    a = teacher.get_env().envs[0].unwrapped.automaton
    back = AutomatonQTable.load(table.save(tmp_path / "t.npz"), a)
    assert np.array_equal(back.q, table.q) and np.array_equal(back.counts, table.counts)


def test_every_method_is_a_row_for_a_world_that_exists():
    assert set(methods_for("Grid10")) | set(methods_for("Cont")) == set(METHODS)
    assert methods_for("Grid7") == methods_for("Grid10")
    with pytest.raises(MethodError, match="METHODS row 'moon-dqn': world 'Moon' does not exist; worlds: "
                                          r"\['Grid', 'Cont'\]"):
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
def test_the_transfer_method_distills_edges_into_counterfactual_experiences(method, world, table):
    # the row composes two components: CRM's replay and the edges-only, never-faded target
    small = SMALL_DQN if METHODS[method].algorithm == "dqn" else SMALL_TD3
    agent = make_agent(method, world, table=table, seed=2, **small)
    assert type(agent.replay_buffer).__name__ == "CRMReplayBuffer"
    assert (agent.distill.rho, agent.distill.self_loops) == (1.0, False)
    agent.learn(300)
    automaton = agent.get_env().envs[0].unwrapped.automaton
    buffer = agent.replay_buffer
    # every live automaton state has experiences, though the agent was in few of them
    assert set(np.unique(buffer.w[:buffer.pos])) == set(np.flatnonzero(~(automaton.accepting | automaton.rejecting)))
    # and the target read the teacher only on edges: the self-loops' counts carry no teacher weight
    counted = agent.distill.student_counts > 0
    loops = automaton.delta == np.arange(automaton.n_states)[:, None]
    assert counted[loops].any() and agent.distill.beta(*np.nonzero(counted & loops)).max() == 0.0


def test_the_transfer_method_cannot_go_without_the_automaton_state_its_replay_rewrites(table):
    # distilled, yet CRM: its counterfactuals write the one-hot into the observation's last entries
    for method, world in (("crm-edges", "CraftSuite/DungeonQuest-Grid10-v0"), ("td3-crm-edges", CONT)):
        with pytest.raises(MethodError, match=f"method '{method}' cannot run with automaton_state=False: its "
                                              "counterfactual experiences relabel"):
            make_agent(method, world, table=table, automaton_state=False, **SMALL_TD3)
    assert METHODS["td3-dynamic-edges"].observes(False) is False  # a distilled student without CRM still may
