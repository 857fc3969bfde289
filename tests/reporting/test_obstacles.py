"""What training episodes reached, read back from episodes.csv: the shares of propositions
and automaton states, the furthest state, completed episodes per 100k transitions; old
records (without the columns) and archived ones (gzipped)."""

import gzip
import json

import numpy as np
import pytest

from craftsuite.automata import Automaton
from craftsuite.reporting.obstacles import completed_per_100k, distances, episode_progress, method_progress, pool
from craftsuite.reporting.obstacles import summarize
from craftsuite.runs import EPISODE_CORE, EPISODE_FIELDS, RunError, write_csv
from craftsuite.task_registry import resolve_task

from .fakes import fake_run


def _hand_made() -> Automaton:
    """Propositions a (bit 0) and b (bit 1). 0 -a-> 1 -b-> 2 (accepting); 0 -b-> 4 -a-> 1 (a
    detour); a and b together from 0 or 4: 3, the rejecting sink."""
    delta = np.array([[0, 1, 4, 3],   # 0: nothing stays, a, b, a & b
                      [1, 1, 2, 2],   # 1
                      [2, 2, 2, 2],   # 2: accepting
                      [3, 3, 3, 3],   # 3: the sink
                      [4, 1, 4, 3]],  # 4
                     dtype=np.int16)
    return Automaton("hand-made", ("a", "b"), delta, np.array([False, False, True, False, False]))


def summarize_rows(automaton, task, budget, episodes):
    """``summarize`` of episodes written as (completed, seen, states) rows, None where a row
    has no mask (logged before the columns came)."""
    completed = [won for won, _, _ in episodes]
    marked = [seen is not None and states is not None for _, seen, states in episodes]
    seen = [mask or 0 for _, mask, _ in episodes]
    states = [mask or 0 for _, _, mask in episodes]
    return summarize(automaton, task, budget, completed, seen, states, marked)


def test_distances_count_edges_to_acceptance_without_self_loops_or_the_sink():
    automaton = _hand_made()
    assert automaton.rejecting.tolist() == [False, False, False, True, False]
    assert distances(automaton) == [2, 1, 0, None, 2]
    assert distances(automaton, forward=True) == [0, 1, 2, None, 1]  # from the start


def test_furthest_is_the_visited_state_closest_to_acceptance():
    automaton = _hand_made()
    # (completed, seen, states): one reached 1, one wandered to 4 and died in the sink, one stayed at 0
    episodes = [(0, 0b01, 0b00011), (0, 0b11, 0b11001), (0, 0b00, 0b00001)]
    progress = summarize_rows(automaton, "hand-made", 1_000, episodes)
    assert (progress.furthest.state, progress.furthest.distance) == (1, 1)
    assert progress.furthest.share == pytest.approx(1 / 3)
    assert progress.closest_share == pytest.approx({1: 1 / 3, 2: 2 / 3})
    assert progress.state_share == pytest.approx({0: 1.0, 1: 1 / 3, 2: 0.0, 3: 1 / 3, 4: 1 / 3})
    assert progress.seen_share == pytest.approx({"a": 2 / 3, "b": 1 / 3})
    # the sink, whatever it is next to, is never the furthest: it cannot get to acceptance
    stuck = summarize_rows(automaton, "hand-made", 1_000, [(0, 0b11, 0b01001)])
    assert (stuck.furthest.state, stuck.furthest.distance, stuck.furthest.share) == (0, 2, 1.0)
    # an accepted episode: distance 0, whatever the others reached
    done = summarize_rows(automaton, "hand-made", 1_000, [(1, 0b11, 0b00111), (0, 0b10, 0b10001), (0, 0b10, 0b10001)])
    assert (done.furthest.state, done.furthest.distance) == (2, 0) and done.furthest.share == pytest.approx(1 / 3)
    assert done.completed_per_100k == pytest.approx(100.0)
    # 0 and 4 are both 2 away: 4, a step from the start, is further along
    tie = summarize_rows(automaton, "hand-made", 1_000, [(0, 0b10, 0b10001)])
    assert (tie.furthest.state, tie.furthest.distance, tie.furthest.share) == (4, 2, 1.0)
    with pytest.raises(ValueError, match="episode 1 .*states 32"):
        summarize_rows(automaton, "hand-made", 1_000, [(0, 0, 0b100000)])  # a state the automaton does not have
    # rows without a mask (either of the two) are episodes, but not in the shares; an episode's
    # number counts them all
    partly = summarize_rows(automaton, "hand-made", 1_000, [(1, None, 0b00111), (0, 0b01, None), (0, 0b01, 0b00011)])
    assert (partly.episodes, partly.completed, partly.marked) == (3, 1, 1)
    assert partly.state_share == pytest.approx({0: 1.0, 1: 1.0, 2: 0.0, 3: 0.0, 4: 0.0})
    with pytest.raises(ValueError, match=r"episode 3 \(line 4: seen -9223372036854775808"):
        summarize_rows(automaton, "hand-made", 1_000, [(0, None, None), (0, 0b01, 0b00011), (0, -2**63, 0b1)])
    with pytest.raises(ValueError, match="one entry an episode in each array, got completed 2, seen 2, states 1"):
        summarize(automaton, "hand-made", 1_000, [0, 1], [0b01, 0b11], [0b00011])


def _run(root, task="Reach", world="Grid10", budget=1_000, rows=(), fields=EPISODE_FIELDS, seed=0, **config):
    run = fake_run(root, "dqn", seed, [(budget, 0.0)], [], budget=budget, task=task, world=world, **config)
    write_csv(run / "episodes.csv", fields, [dict(zip(EPISODE_FIELDS, r)) for r in rows])
    return run


REACH = [(300, -20.0, 200, 0, 0, 0b01), (420, 95.0, 120, 1, 1, 0b11), (800, -20.0, 200, 0, 0, 0b01),
         (990, 90.0, 150, 1, 1, 0b11)]


def test_a_run_reads_from_its_log_and_from_the_archives_gzipped_one(tmp_path):
    run = _run(tmp_path, rows=REACH)
    progress = episode_progress(run)
    assert (progress.task, progress.runs, progress.budget, progress.episodes, progress.completed) == \
        ("Reach", 1, 1_000, 4, 2)
    assert progress.completed_per_100k == pytest.approx(200.0)
    assert progress.seen_share == {"wood": 0.5} and progress.state_share == {0: 1.0, 1: 0.5}
    assert (progress.furthest.state, progress.furthest.distance, progress.furthest.share) == (1, 0, 0.5)
    packed = run / "episodes.csv.gz"
    packed.write_bytes(gzip.compress((run / "episodes.csv").read_bytes(), mtime=0))
    (run / "episodes.csv").unlink()
    assert episode_progress(run) == progress


def test_a_record_made_before_the_columns_reads_as_none(tmp_path):
    old = _run(tmp_path, rows=[r[:4] for r in REACH], fields=EPISODE_CORE)
    assert episode_progress(old) is None
    assert method_progress([old]) is None
    # a run resumed since: the first session's rows have the columns empty, and are not counted in the shares
    resumed = _run(tmp_path, rows=[r[:4] for r in REACH[:2]] + REACH[2:], seed=1)
    progress = episode_progress(resumed)
    assert (progress.episodes, progress.completed, progress.marked) == (4, 2, 2)
    assert progress.seen_share == {"wood": 0.5}
    # no episode at all (a budget shorter than one): nothing reached, nothing unknown
    empty = episode_progress(_run(tmp_path, rows=[], seed=2))
    assert (empty.episodes, empty.marked, empty.furthest, empty.completed_per_100k) == (0, 0, None, 0.0)


def test_the_seeds_of_a_method_pool(tmp_path):
    a = _run(tmp_path, rows=REACH)  # 2 completed in 1,000 transitions
    b = _run(tmp_path, rows=[(500, -20.0, 200, 0, 0, 0b01), (1000, -20.0, 200, 0, 0, 0b01)], seed=1)  # none
    pooled = method_progress([a, b])
    assert (pooled.runs, pooled.budget, pooled.episodes, pooled.completed, pooled.marked) == (2, 2_000, 6, 2, 6)
    assert pooled.completed_per_100k == pytest.approx(100.0)  # the mean of 200 and 0
    assert pooled.seen_share == pytest.approx({"wood": 1 / 3})
    assert pooled.state_share == pytest.approx({0: 1.0, 1: 1 / 3})
    assert (pooled.furthest.state, pooled.furthest.distance) == (1, 0) and pooled.furthest.share == pytest.approx(1 / 3)
    assert pool([episode_progress(b)]).furthest.state == 0  # alone, b never got past the start
    with pytest.raises(ValueError, match="one task"):
        pool([episode_progress(a), episode_progress(_run(tmp_path, task="FirstWood", rows=REACH))])


def test_a_board_keeps_each_runs_tally_and_the_obstacles_read_no_log_again(tmp_path):
    from craftsuite.reporting.board import build

    # one run with a resumed session's unmarked rows, one with every row marked, one old record
    runs = [_run(tmp_path, rows=[r[:4] for r in REACH[:2]] + REACH[2:]),
            _run(tmp_path, rows=REACH + [(995, -20.0, 5, 0, 0, 0b01)] * 3, seed=1),
            _run(tmp_path, rows=[r[:4] for r in REACH], fields=EPISODE_CORE, seed=2)]
    (entry,) = build(tmp_path).entries
    tallied = [(c.episodes[:, 2], c.reached) for c in entry.curves]
    assert entry.curves[1].reached == {("0", "1"): 5, ("1", "3"): 2}  # seven episodes in two pairs
    expected = [episode_progress(run) for run in entry.runs]
    assert expected[2] is None and expected[0].marked == 2
    for run in runs:
        (run / "episodes.csv").unlink()  # the board's tally alone: the log is not read again
    assert [episode_progress(run, t) for run, t in zip(entry.runs, tallied)] == expected
    assert method_progress(entry.runs, tallied) == pool(expected[:2])


def test_a_tallied_cell_at_fault_is_named_by_its_line_in_the_log(tmp_path):
    from craftsuite.reporting.board import build

    _run(tmp_path, rows=REACH + [(995, -20.0, 5, 0, 0, "1\x00")])
    # Reach has one proposition; the tally's order would make the wrong row its 5th episode
    _run(tmp_path, rows=REACH[:3] + [(900, -20.0, 5, 0, 0b10, 0b01)] + REACH[3:], seed=1)
    (entry,) = build(tmp_path).entries
    (garbled, wrong), (run_garbled, run_wrong) = entry.curves, entry.runs
    with pytest.raises(RunError, match=r"line 6: states '1\\x00' is not an integer"):
        episode_progress(run_garbled, (garbled.episodes[:, 2], garbled.reached))
    with pytest.raises(RunError, match=r"episode 4 \(line 5: seen 2, states 1\) .*another automaton"):
        episode_progress(run_wrong, (wrong.episodes[:, 2], wrong.reached))
    # a log rewritten since the board read it is not read as the episodes it tallied
    (run_wrong / "episodes.csv").unlink()
    with pytest.raises(RunError, match=r"episodes.csv holds 0 episodes where it held 5 when it was read"):
        episode_progress(run_wrong, (wrong.episodes[:, 2], wrong.reached))


def test_bad_records_are_named(tmp_path):
    wrong = _run(tmp_path, rows=[(300, -20.0, 200, 0, 0b10, 0b01)])  # Reach has one proposition
    with pytest.raises(RunError, match=r"episodes.csv: episode 1 .*another automaton"):
        episode_progress(wrong)
    garbled = _run(tmp_path, rows=[(300, -20.0, 200, 0, "x", 0b01)], seed=1)
    with pytest.raises(RunError, match=r"episodes.csv does not read as a run's log"):
        episode_progress(garbled)
    huge = _run(tmp_path, rows=[(300, -20.0, 200, 0, 0, 1), (420, -20.0, 200, 0, 0, 2**63)], seed=6)
    with pytest.raises(RunError, match=r"episodes.csv does not read as a run's log .*line 3: states "
                                       "9223372036854775808 is beyond a signed 64-bit mask"):
        episode_progress(huge)
    nul = _run(tmp_path, rows=[(300, -20.0, 200, 0, 0, "1\x00")], seed=8)  # what a crash leaves in a torn file
    with pytest.raises(RunError, match=r"line 2: states '1\\x00' is not an integer"):
        episode_progress(nul)
    # a completion is 0 or 1, as the record format has it (the board refuses the same log)
    half = _run(tmp_path, rows=[(300, -20.0, 200, 0.5, 0, 0b01)], seed=7)
    for read in (episode_progress, completed_per_100k):
        with pytest.raises(RunError, match=r"episodes.csv: line 2: success 0.5 is not 0 or 1: the record breaks"):
            read(half)
    unknown = _run(tmp_path, task="NoSuchTask", rows=REACH, seed=2)
    with pytest.raises(RunError, match=r"config.json: task 'NoSuchTask' is unknown here"):
        episode_progress(unknown)
    rules = resolve_task("Reach").digest()
    other = _run(tmp_path, rows=REACH, seed=3, effective={"world": {"rules": "0" * len(rules)}})
    with pytest.raises(RunError, match="ran under other rules"):
        episode_progress(other)
    same = _run(tmp_path, rows=REACH, seed=4, effective={"world": {"rules": rules}})
    assert episode_progress(same).completed == 2
    teacher = _run(tmp_path, rows=REACH, seed=5)
    record = json.loads((teacher / "config.json").read_text())
    del record["steps"]
    (teacher / "config.json").write_text(json.dumps({**record, "max_steps": 1_000}))
    with pytest.raises(RunError, match=r"config.json is a teacher's \(max_steps, not steps\), not a student's record"):
        episode_progress(teacher)
    (teacher / "config.json").write_text(json.dumps(record))  # neither: a student's record with its budget lost
    with pytest.raises(RunError, match=r"config.json: lacks steps: the record breaks the record format"):
        episode_progress(teacher)


def test_a_state_is_named_by_the_fewest_edges_that_reach_it():
    from craftsuite.reporting.obstacles import route
    from craftsuite.task_registry import resolve_task

    automaton = resolve_task("KeySwordDragon").automaton
    named = {q: route(automaton, q) for q in range(automaton.n_states)}
    assert named[automaton.initial] == []
    assert ["key", "sword", "dragon"] in named.values()  # acceptance: each step a proposition of its own
    sink = int(automaton.rejecting.nonzero()[0][0])
    assert named[sink] is None  # the rejecting sink is reached by no edge the route takes
