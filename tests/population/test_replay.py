"""The population's replay: its sum trees sum and find as brute force does, and CRM's
counterfactuals made at sampling are the hand-made ones."""

import numpy as np
import pytest

import craftsuite  # noqa: F401
from craftsuite.population.replay import CounterfactualView, PopulationReplay, SumTrees, sparse_rows
from craftsuite.task_registry import resolve_task


def test_sum_trees_sum_and_find_as_brute_force():
    rng = np.random.default_rng(0)
    trees, leaves = SumTrees(3, 100), np.zeros((3, 100))
    for _ in range(5):
        at = rng.integers(0, 100, size=(3, 17))
        values = rng.random((3, 17))
        trees.update(at, values)
        for k in range(3):
            for leaf, value in zip(at[k], values[k]):  # one at a time: repeats keep the last
                leaves[k, leaf] = value
    np.testing.assert_allclose(trees.total(), leaves.sum(axis=1))
    targets = rng.random((3, 50)) * trees.total()[:, None]
    found = trees.find(targets)
    for k in range(3):  # the leaf whose interval of the cumulative sum holds each target
        expected = np.searchsorted(np.cumsum(leaves[k]), targets[k], side="right")
        np.testing.assert_array_equal(found[k], expected)
        assert (leaves[k, found[k]] > 0).all()


def test_prioritized_sampling_follows_the_priorities():
    replay = PopulationReplay(2, 64, 1, 3, (), np.int64, prioritized=True, alpha=1.0, seed=0)
    for i in range(64):
        replay.add(np.full((2, 1, 3), i), np.zeros((2, 1, 3)), np.zeros((2, 1)), np.zeros((2, 1)),
                   np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((2, 1)))
    # member 0 puts all its mass on transition 5, member 1 spreads it evenly
    replay.update_priorities(np.arange(64)[None].repeat(2, 0), np.array([[0.0] * 64, [1.0] * 64]))
    replay.update_priorities(np.array([[5], [5]]), np.array([[1000.0], [1.0]]))
    batch = replay.sample(256)
    assert (batch.observations[0, :, 0] == 5).mean() > 0.9
    assert len(np.unique(batch.observations[1, :, 0])) > 40
    assert batch.weights.max(axis=1) == pytest.approx([1.0, 1.0])
    assert batch.weights[0].min() < 0.1  # the over-sampled transition is weighted down


@pytest.mark.parametrize("task,sparse", [("DungeonQuest", False), ("DiamondMine", False), ("DiamondMine", True)])
def test_counterfactuals_at_sampling_equal_the_stored_ones(task, sparse):
    spec = resolve_task(task)
    automaton, S = spec.automaton, spec.automaton.n_states
    view = CounterfactualView(automaton, spec.completion_reward, 6 + S)
    rng = np.random.default_rng(1)
    replay = PopulationReplay(1, 40, 1, 6 + S, (2,), crm=view, prioritized=False, seed=2,
                              sparse_width=7 if sparse else None)
    stored = []
    for _ in range(40):
        w = int(rng.choice(view.live))
        sigma = int(rng.integers(automaton.delta.shape[1]))
        obs, next_obs = rng.random(6 + S).astype(np.float32), rng.random(6 + S).astype(np.float32)
        obs[-S:], next_obs[-S:] = np.eye(S)[w], np.eye(S)[automaton.delta[w, sigma]]
        reward = -0.1 + spec.completion_reward * automaton.accepting[automaton.delta[w, sigma]]
        action = rng.random(2)
        terminal = bool(automaton.accepting[automaton.delta[w, sigma]]
                        or automaton.rejecting[automaton.delta[w, sigma]])
        replay.add(obs[None, None], next_obs[None, None], action[None, None], np.array([[reward]]),
                   np.array([[terminal]]), np.array([[w]]), np.array([[sigma]]))
        stored.append(_by_hand(automaton, spec.completion_reward, obs, next_obs, reward, w, sigma))
    batch = replay.sample(300)
    if sparse:  # back to dense rows, to compare
        batch = batch._replace(observations=dense(batch.observations, 6 + S),
                               next_observations=dense(batch.next_observations, 6 + S))
    index, j = np.divmod(batch.leaves[0], view.n_live)
    assert len(np.unique(j)) == view.n_live  # every live state is read
    for b in range(300):
        live, obs_u, next_u, rewards, dones = stored[index[b]]
        np.testing.assert_array_equal(batch.observations[0, b], obs_u[j[b]])
        np.testing.assert_array_equal(batch.next_observations[0, b], next_u[j[b]])
        assert batch.rewards[0, b] == pytest.approx(rewards[j[b]])
        assert batch.terminals[0, b] == dones[j[b]]
        assert batch.w[0, b] == live[j[b]]


def _by_hand(automaton, completion: float, obs, next_obs, reward: float, w: int, sigma: int):
    """One real step read from every live automaton state u, in order: (u, observation and
    next observation with u's and u''s one-hot, reward, terminal)."""
    S = automaton.n_states
    live = np.flatnonzero(~(automaton.accepting | automaton.rejecting))
    rows = []
    for u in live:
        after = automaton.delta[u, sigma]
        o, n = obs.copy(), next_obs.copy()
        o[-S:], n[-S:] = np.eye(S)[u], np.eye(S)[after]
        # the world's own reward without the real completion bonus, then u's
        world = reward - completion * automaton.accepting[automaton.delta[w, sigma]]
        own = world + completion * automaton.accepting[after]
        rows.append((o, n, own, bool(automaton.accepting[after] or automaton.rejecting[after])))
    obs_u, next_u, rewards, dones = (np.array(column) for column in zip(*rows))
    return live, obs_u, next_u, rewards, dones


def dense(rows, width):
    index, value = rows.index.reshape(-1, rows.index.shape[-1]), rows.value.reshape(-1, rows.index.shape[-1])
    out = np.zeros((len(index), width), dtype=np.float32)
    np.add.at(out, (np.arange(len(index))[:, None], index), value)  # padding adds 0 to column 0
    return out.reshape(*rows.index.shape[:-1], width)


def test_sparse_rows_round_trip_and_refuse_overflow():
    rng = np.random.default_rng(3)
    x = (rng.random((4, 5, 30)) < 0.15) * rng.random((4, 5, 30)).astype(np.float32)
    x[0, 0, 0] = 0.5  # a nonzero in column 0, where padding points
    rows = sparse_rows(x, 30)
    np.testing.assert_array_equal(dense(rows, 30), x)
    with pytest.raises(ValueError, match="more than the 2 the replay stores"):
        sparse_rows(x, 2)


def test_crm_memory_holds_each_step_once():
    spec = resolve_task("DiamondMine")
    view = CounterfactualView(spec.automaton, spec.completion_reward, 10)
    replay = PopulationReplay(1, 1000, 1, 10, (2,), crm=view)
    assert replay.observations.shape == (1, 1000, 10)  # not 1000 x the live states
    assert replay.trees.leaves >= 1000 * view.n_live


def _filled(members: int, steps: int, seed: int) -> PopulationReplay:
    """A prioritized n-step replay of sparse observations, ``steps`` steps of 2 envs each."""
    rng = np.random.default_rng(seed)
    replay = PopulationReplay(members, 4_000, 2, 30, (), np.int64, sparse_width=12, n_steps=3, seed=seed)
    for _ in range(steps):
        obs = (rng.random((members, 2, 30)) < 0.05) * rng.random((members, 2, 30))
        obs[..., 12:] = 0  # at most the replay's sparse width of nonzeros
        replay.add(obs, obs[:, :, ::-1], rng.integers(0, 4, (members, 2)), rng.random((members, 2)),
                   rng.random((members, 2)) < 0.1, rng.integers(0, 3, (members, 2)), rng.integers(0, 5, (members, 2)),
                   ended=rng.random((members, 2)) < 0.2)
    replay.update_priorities(rng.integers(0, 2 * steps, (members, 16)), rng.random((members, 16)))
    return replay


def test_a_member_state_saves_its_rows_as_the_replay_memory_itself(tmp_path):
    """A checkpoint's rows are tensors over the replay's own arrays, which ``torch.save``
    writes as they are: a NumPy array would be pickled whole in memory first (several
    copies of a member's replay, and a larger file)."""
    import torch as th

    replay = _filled(2, 1_500, seed=4)
    state = replay.member_state(1)
    rows = {name: value for name, value in state.items() if name not in ("pos", "full", "max_priority")}
    assert rows and all(th.is_tensor(value) for value in rows.values())
    for name in replay._arrays:  # the member's slice of the array, not a copy
        assert rows[name].data_ptr() == getattr(replay, name)[1].ctypes.data
    th.save(state, tmp_path / "member.pt")
    row_bytes = sum(value.numel() * value.element_size() for value in rows.values())
    # the member's rows alone, not the whole arrays' storage (about 2.7x here)
    assert (tmp_path / "member.pt").stat().st_size < 1.02 * row_bytes + 20_000


@pytest.mark.parametrize("form", ["tensors", "numpy"])
def test_a_member_resumes_the_rows_it_saved_from_tensors_and_from_an_older_checkpoints_arrays(tmp_path, form):
    import torch as th

    replay = _filled(2, 1_500, seed=5)
    state = replay.member_state(1)
    if form == "numpy":  # as checkpoints were written before their rows became tensors
        state = {name: value.numpy() if th.is_tensor(value) else value for name, value in state.items()}
    th.save(state, tmp_path / "member.pt")
    resumed = PopulationReplay(1, 4_000, 2, 30, (), np.int64, sparse_width=12, n_steps=3, seed=0)
    resumed.load_member(0, th.load(tmp_path / "member.pt", weights_only=False))
    n = replay.size
    assert resumed.size == n == 3_000 and resumed.pos == replay.pos
    for name in replay._ARRAYS + replay._observation_arrays:
        np.testing.assert_array_equal(getattr(resumed, name)[0, :n], getattr(replay, name)[1, :n])
    np.testing.assert_array_equal(resumed.trees.tree[0], replay.trees.tree[1])
    assert resumed.max_priority[0] == replay.max_priority[1]


def test_a_replay_counts_the_bytes_it_holds_once_full():
    replay = PopulationReplay(2, 4_000, 2, 30, (), np.int64, sparse_width=12, n_steps=3)
    # a row: observation and next observation as 12 int64 indexes and 12 float32 values each,
    # an int64 action, float32 reward and terminal, int64 automaton state and label, a bool end
    row = 2 * 12 * (8 + 4) + 8 + 4 + 4 + 8 + 8 + 1
    assert replay.nbytes == 2 * 4_000 * row + 2 * 2 * replay.trees.leaves * 8  # and one sum tree a member
    uniform = PopulationReplay(2, 4_000, 2, 30, (2,), prioritized=False)
    assert uniform.nbytes == 2 * 4_000 * (2 * 30 * 4 + 2 * 4 + 4 + 4 + 8 + 8)
