"""``craftsuite.Recorder``: a user's own training loop writes a run directory in the suites'
record format, on the suite's budget and evaluation schedule, marked self-reported, which the
leaderboard reads; bad use is refused in one line and leaves nothing behind."""

import json
from pathlib import Path

import numpy as np
import pytest

import craftsuite
from craftsuite.recorder import recorded_config
from craftsuite.reporting.board import build
from craftsuite.runs import RunError, read_csv
from craftsuite.suites import SUITES

ENV = "CraftSuite/Reach-Grid10-v0"


def _random_loop(env, rng, evaluate=True):
    env.reset(seed=0)
    while not env.done:
        _, _, terminated, truncated, _ = env.step(int(rng.integers(env.action_space.n)))
        if terminated or truncated:
            env.reset()
        if evaluate and env.evaluation_due:
            env.evaluate(lambda obs: int(rng.integers(4)))


def test_a_users_loop_writes_a_run_the_leaderboard_reads(tmp_path):
    rng = np.random.default_rng(0)
    env = craftsuite.Recorder(ENV, tmp_path, method="my-random", seed=3, library="numpy", settings={"p": 0.25},
                              commit="abc123")
    _random_loop(env, rng)
    path = env.finish(lambda obs: int(rng.integers(4)), updates=0)
    standard = SUITES["standard"]
    budget = standard.budget(craftsuite.resolve_task("Reach"), "Grid10")
    config = json.loads((path / "config.json").read_text())
    assert (config["method"], config["seed"], config["steps"], config["library"], config["commit"]) == \
        ("my-random", 3, budget, "numpy", "abc123")
    assert config["self_reported"] is True and config["layout_seed"] == standard.grid_layout_seed
    assert config["provenance"]  # the session that recorded it
    every = standard.eval_interval(budget, "Grid10")
    assert [int(r["step"]) for r in read_csv(path / "evals.csv")] == list(range(every, budget + 1, every))
    episodes = read_csv(path / "episodes.csv")
    assert episodes and all(int(e["states"]) & 1 for e in episodes)  # the initial state, in every episode
    result = json.loads((path / "result.json").read_text())
    assert (result["steps"], result["updates"], result["self_reported"]) == (budget, 0, True)
    (entry,) = build(tmp_path)
    assert (entry.method, entry.regime, entry.budget, entry.seeds) == ("my-random", "self-reported", budget, [3])


def test_an_evaluation_called_late_is_the_latest_step_reached(tmp_path):
    env = craftsuite.Recorder(ENV, tmp_path, method="my-late")
    env.reset(seed=0)
    every = env.config.eval_every
    for _ in range(2 * every + 5):
        _, _, terminated, truncated, _ = env.step(0)
        if terminated or truncated:
            env.reset()
    assert env.evaluation_due
    env.evaluate(lambda obs: 0)
    assert env.evaluated == [2 * every] and not env.evaluation_due and env.late == [5]
    with pytest.raises(RuntimeError, match="no evaluation is due"):
        env.evaluate(lambda obs: 0)
    env.close()


def test_finishing_a_run_with_late_evaluations_says_so(tmp_path):
    env = craftsuite.Recorder(ENV, tmp_path, method="my-tardy", steps=1_000)
    env.reset(seed=0)
    while not env.done:
        _, _, terminated, truncated, _ = env.step(0)
        if terminated or truncated:
            env.reset()
        if env.evaluation_due and (env.transitions % 50 == 3 or env.transitions == 1_000):  # 3 late, but the last
            env.evaluate(lambda obs: 0)
    assert env.late == [3] * 19
    with pytest.warns(UserWarning, match=r"19 of the suite's 20 evaluations were made after their step \(by up to 3 "
                                         r"transitions\): each is recorded at its step"):
        env.finish(lambda obs: 0, updates=0)


@pytest.mark.parametrize("method, message", [
    ("td3", "method 'td3' is one of CraftSuite's own methods: name yours"),
    ("my sac", "method must be a name without spaces or slashes"),
])
def test_a_method_named_as_craftsuites_own_is_refused(tmp_path, method, message):
    with pytest.raises(ValueError, match=message):
        craftsuite.Recorder(ENV, tmp_path / "out", method=method)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("settings, message", [
    ({"policy_kwargs": {"activation_fn": np.tanh}}, r"settings 'policy_kwargs'\['activation_fn'\] holds tanh \(a "
     r"ufunc\), which a JSON record cannot hold; record it as a string, e.g. 'tanh'"),
    ({"lr": float("nan")}, "settings 'lr' holds nan, not a finite number, which JSON cannot hold; record it as "
     "a string"),
    ("lr=1", "settings must be a dict of the learner's settings"),
    ({(1, 2): 3}, r"settings: its keys must be strings or integers, got \(1, 2\)"),
    ({"net": {1: "a", "1": "b"}}, r"settings 'net': the keys '1' and 1 are one key in a JSON record; keep one"),
    ({"log": {"dir": Path("runs/x")}}, r"settings 'log'\['dir'\] holds runs/x \(a PosixPath\), which a JSON record "
     r"cannot hold; record it as a string, e.g. 'runs/x'"),
])
def test_settings_a_json_record_cannot_hold_are_named_by_key(tmp_path, settings, message):
    with pytest.raises(ValueError, match=message):
        craftsuite.Recorder(ENV, tmp_path / "out", method="my-sac", settings=settings)
    assert not (tmp_path / "out").exists()


def test_settings_are_recorded_as_json_reads_them_back():
    """numpy's numbers as the numbers they print, any mapping as a dict, integer keys as the
    strings JSON makes of them."""
    from types import MappingProxyType

    settings = MappingProxyType({"gamma": np.float32(0.99), "net": (np.int64(64), 64), "by_state": {3: 0.5}})
    config = recorded_config(ENV, "my-sac", settings=settings)
    assert config.settings == {"gamma": 0.99, "net": [64, 64], "by_state": {"3": 0.5}}
    assert json.loads(json.dumps(config.settings)) == config.settings


def test_finishing_before_the_budget_is_refused_and_a_second_recording_too(tmp_path):
    env = craftsuite.Recorder(ENV, tmp_path, method="my-short")
    env.reset(seed=0)
    env.step(0)
    with pytest.raises(ValueError, match=r"1 transitions of the budget's 30,000: a run is finished at its budget"):
        env.finish(lambda obs: 0, updates=0)
    env.reset()  # the episode cut short is recorded: the unfinished recording holds something
    env.close()
    with pytest.raises(RunError, match="holds a recording already \\(unfinished\\)"):
        craftsuite.Recorder(ENV, tmp_path, method="my-short")


def test_a_recording_closed_before_it_wrote_anything_leaves_nothing_behind(tmp_path):
    """A script that failed at its first step runs again as it is, once mended."""
    env = craftsuite.Recorder(ENV, tmp_path / "runs", method="my-first")
    env.reset(seed=0)
    with pytest.raises(ValueError):
        env.step(7)  # no such action
    env.close()
    assert list(tmp_path.iterdir()) == []  # nor the folders it made
    craftsuite.Recorder(ENV, tmp_path / "runs", method="my-first").close()


def test_an_episode_cut_short_by_reset_is_recorded_as_a_time_limit_ends_one(tmp_path):
    env = craftsuite.Recorder(ENV, tmp_path, method="my-cut", steps=60)
    seeds = iter(range(3))  # starts from which 20 moves up reach no wood (1 in 20 of them would)
    while not env.done:
        env.reset(seed=next(seeds))
        for _ in range(20):
            _, _, terminated, truncated, _ = env.step(0)
            if env.evaluation_due:
                env.evaluate(lambda obs: 0)
            if terminated or truncated or env.done:
                break
    path = env.finish(lambda obs: 0, updates=0)
    rows = read_csv(path / "episodes.csv")
    assert [(r["step"], r["length"], r["success"]) for r in rows] == [("20", "20", "0"), ("40", "20", "0")]
    assert all(int(r["states"]) & 1 for r in rows)  # what each reached, as an ended episode's


def test_a_step_past_the_budget_is_refused_and_the_run_still_finishes_at_it(tmp_path):
    env = craftsuite.Recorder(ENV, tmp_path, method="my-greedy", steps=50)
    _random_loop(env, np.random.default_rng(0), evaluate=False)
    with pytest.raises(RuntimeError, match="the budget's 50 transitions are collected: stop stepping when done"):
        env.step(0)
    with pytest.warns(UserWarning, match="12 of the suite's 13 evaluations were not made"):  # evaluate=False
        path = env.finish(lambda obs: 0, updates=0)
    assert json.loads((path / "result.json").read_text())["steps"] == 50
    assert sum(int(r["length"]) for r in read_csv(path / "episodes.csv")) <= 50


def test_another_budget_keeps_the_suites_schedule_for_it():
    config = recorded_config("CraftSuite/ToolHome-Cont-v0", "my-sac", steps=4_000)
    assert (config.steps, config.eval_every) == (4_000, SUITES["standard"].eval_interval(4_000, "Cont"))
    with pytest.raises(ValueError, match="steps .* must be a positive integer, got 0"):
        recorded_config("CraftSuite/ToolHome-Cont-v0", "my-sac", steps=0)


def test_the_record_is_the_suites_protocol_for_the_rung():
    config = recorded_config("CraftSuite/ToolHome-Cont-v0", "my-sac", seed=1)
    suite = SUITES["standard"]
    mine = suite.student_config(craftsuite.resolve_task("ToolHome"), "Cont", "td3", 1)
    assert (config.steps, config.eval_every, config.eval_episodes, config.env_kwargs) == \
        (mine.steps, mine.eval_every, mine.eval_episodes, mine.env_kwargs)


def test_the_leaderboard_sets_self_reported_runs_beside_every_regimes_own(tmp_path):
    from craftsuite.cli import main

    from .reporting.fakes import fake_run

    archive, mine, out = tmp_path / "archive", tmp_path / "mine", tmp_path / "board"
    for seed in range(3):
        fake_run(archive, "td3", seed, [(1000, 0.0)], [(995, 1.0)], hyperparameters={})
        fake_run(archive, "td3", seed, [(1000, 0.5)], [(995, 1.0)], hyperparameters={"n_steps": 3})
        fake_run(mine, "my-sac", seed, [(1000, 1.0)], [(995, 1.0)], self_reported=True, library="sb3 2.4 SAC")
        fake_run(mine, "my-long", seed, [(2000, 1.0)], [(1995, 1.0)], budget=2000, self_reported=True)
    assert main(["leaderboard", str(mine), str(archive), "--out", str(out)]) == 0
    md = (out / "leaderboard.md").read_text()
    # the legend says what a self-reported method is, with the library its records name
    assert ("- `my-sac`: self-reported: trained outside CraftSuite (sb3 2.4 SAC), its records written by "
            "craftsuite.Recorder") in md
    assert "- `my-long`: self-reported: trained outside CraftSuite, its records written by craftsuite.Recorder" in md
    one_step, n_step = md.split("## Learner regime `n-step`")
    for part in (one_step, n_step):
        assert "| my-sac *(self-reported)* | 3 | 1.00" in part
        assert "`my-long` not compared: 2,000 transitions against 1,000" in part
    from craftsuite.stats import difference

    # 3 seeds all at 1 against 3 at 0 (or at 0.5): the exact interval of the side at a bound, squared and added
    apart, half = difference([1.0] * 3, [0.0] * 3, bounds=(0, 1)), difference([1.0] * 3, [0.5] * 3, bounds=(0, 1))
    assert f"`my-sac` +1.00 [{apart.low:+.2f}, +1.00], P(> `td3`) 1.00" in one_step
    assert "self-reported runs: compared with these per rung, not aggregated with them" in one_step
    assert f"`my-sac` +0.50 [{half.low:+.2f}, +0.50], P(> `td3`) 1.00" in n_step
    rows = read_csv(out / "seeds.csv")
    assert {(r["method"], r["regime"], r["self_reported"]) for r in rows} == {
        ("my-sac", "self-reported", "1"), ("my-long", "self-reported", "1"), ("td3", "one-step", "0"),
        ("td3", "n-step", "0")}
    assert {r["budget_transitions"] for r in rows if r["method"] == "my-long"} == {"2000"}


@pytest.mark.parametrize("env,suite,message", [
    # the quick suite runs Reach in MuJoCo alone: its protocol has no grid budget to follow
    ("CraftSuite/Reach-Grid10-v0", "quick", "Reach in Grid10 is not a rung of the 'quick' suite, whose protocol "
     "(budget, evaluations) an evaluation follows: give suite= one of 'standard', 'paper'"),
    # the standard suite has a grid budget, but runs no Grid7: a record there would sit beside none of its runs
    ("CraftSuite/Reach-Grid7-v0", "standard", "the 'standard' suite runs no Grid7 world (its worlds: Grid10, Cont): "
     "record in one of them, e.g. CraftSuite/Reach-Grid10-v0"),
    # a continuous agent is pointed to the continuous world, not the first the suite lists
    ("CraftSuite/KeySwordDragon-Kinematic-v0", "standard", "the 'standard' suite runs no Kinematic world (its "
     "worlds: Grid10, Cont): record in one of them, e.g. CraftSuite/KeySwordDragon-Cont-v0"),
])
def test_a_world_the_suite_does_not_run_is_refused_naming_its_worlds(tmp_path, env, suite, message):
    with pytest.raises(ValueError) as err:
        craftsuite.Recorder(env, tmp_path, method="my-random", suite=suite)
    assert str(err.value) == message and list(tmp_path.iterdir()) == []


def test_a_budget_off_the_schedule_is_evaluated_at_the_budget_once(tmp_path):
    env = craftsuite.Recorder(ENV, tmp_path, method="my-odd", steps=1_234)
    _random_loop(env, np.random.default_rng(0))
    assert env.evaluated[-1] == 1_234 and not env.evaluation_due and len(set(env.evaluated)) == len(env.evaluated)
    path = env.finish(lambda obs: 0, updates=np.int64(5))  # numpy's integers are counts too
    assert json.loads((path / "result.json").read_text())["updates"] == 5
    with pytest.raises(RuntimeError, match="the recording is finished \\(or closed\\)"):
        env.finish(lambda obs: 0, updates=5)
    with pytest.raises(RuntimeError, match="a Recorder records one run"):
        env.step(0)
    (entry,) = build(tmp_path)
    assert np.isfinite(entry.values["auc"][0])  # every scheduled evaluation made


def test_a_run_that_skipped_scheduled_evaluations_has_no_auc(tmp_path):
    env = craftsuite.Recorder(ENV, tmp_path, method="my-lazy", steps=1_000)
    _random_loop(env, np.random.default_rng(0), evaluate=False)
    assert env.scheduled == [*range(50, 1_000, 50), 1_000]
    with pytest.warns(UserWarning, match=r"19 of the suite's 20 evaluations were not made \(the first at step 50\): "
                                         "the leaderboard reads this run's AUC as not measured"):
        env.finish(lambda obs: 0, updates=0)  # only the last evaluation
    (entry,) = build(tmp_path)
    assert np.isnan(entry.values["auc"][0]) and np.isfinite(entry.values["success"][0])


def test_two_recorders_of_one_run_are_refused(tmp_path):
    first = craftsuite.Recorder(ENV, tmp_path, method="my-vec")
    with pytest.raises(RunError, match="being recorded by another Recorder in this process"):
        craftsuite.Recorder(ENV, tmp_path, method="my-vec")
    first.close()


def test_after_close_the_recording_refuses_more_by_name_and_counts_may_be_numpys(tmp_path):
    env = craftsuite.Recorder(ENV, tmp_path, method="my-late-eval", seed=np.int64(1), steps=50)
    assert env.config.seed == 1 and type(env.config.seed) is int
    env.reset(seed=0)
    while not env.done:
        env.step(0)
    env.close()
    for call in (lambda: env.evaluate(lambda obs: 0), lambda: env.step(0), lambda: env.finish(lambda obs: 0, 0)):
        with pytest.raises(RuntimeError, match="the recording is finished \\(or closed\\): a Recorder records one"):
            call()


@pytest.mark.parametrize("fields, message", [
    ({"library": None}, "library must be a string naming what trained the run"),
    ({"commit": 123}, "commit must be the commit of your code as a string \\(or None\\), got 123"),
    ({"seed": 1.0}, "seed must be a non-negative integer, got 1.0"),
])
def test_what_the_record_holds_is_checked_before_anything_is_written(tmp_path, fields, message):
    with pytest.raises(ValueError, match=message):
        craftsuite.Recorder(ENV, tmp_path, method="mine", **fields)
    assert list(tmp_path.iterdir()) == []


def test_an_out_that_is_no_path_is_named(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(TypeError, match=r"^out must be a path, got None$"):  # pathlib's own named no argument
        craftsuite.Recorder(ENV, None, method="mine")
    assert list(tmp_path.iterdir()) == []


def test_updates_that_are_no_count_are_named_as_given(tmp_path):
    env = craftsuite.Recorder(ENV, tmp_path, method="my-updates", steps=50)
    env.reset(seed=0)
    while not env.done:
        env.step(0)
    for bad in ("5", 2.0, None, True, -1):
        with pytest.raises(ValueError, match=f"gradient updates made \\(an integer >= 0\\), got {bad!r}$"):
            env.finish(lambda obs: 0, updates=bad)
    env.close()


def test_several_directories_need_an_output_of_their_own(tmp_path, capsys):
    from craftsuite.cli import main

    from .reporting.fakes import fake_run

    for root in ("a", "b"):
        fake_run(tmp_path / root, "td3", 0, [(1000, 1.0)], [(995, 1.0)])
    assert main(["leaderboard", str(tmp_path / "a"), str(tmp_path / "b")]) == 2
    assert "give --out DIR" in capsys.readouterr().err
    assert not (tmp_path / "a" / "leaderboard.md").exists()


def _record_standing_still(out, env_id, **kwargs):
    env = craftsuite.Recorder(env_id, out, method="my-still", suite="paper", steps=100, **kwargs)
    env.reset(seed=0)
    while not env.done:
        _, _, terminated, truncated, _ = env.step(0)
        if terminated or truncated:
            env.reset()
        if env.evaluation_due:
            env.evaluate(lambda obs: 0)
    return env.finish(lambda obs: 0, updates=0)


def test_runs_of_a_user_task_edited_between_them_are_never_pooled(tmp_path, treasure_spec):
    from craftsuite.reporting.obstacles import episode_progress

    path = treasure_spec("EditedTreasure", size=10, max_steps=20)
    craftsuite.register_task(path)
    first = _record_standing_still(tmp_path / "runs", "CraftSuite/EditedTreasure-Grid10-v0")
    path.write_text(path.read_text().replace("count = 1", "count = 2"))  # the same name, other rules
    with pytest.warns(UserWarning, match="task 'EditedTreasure' was registered already, with other rules: this "
                                         "spec replaces it"):
        craftsuite.register_task(path)
    second = _record_standing_still(tmp_path / "runs", "CraftSuite/EditedTreasure-Grid10-v0")
    digests = [json.loads((run / "config.json").read_text())["rules"] for run in (first, second)]
    assert first != second and digests[1] == craftsuite.resolve_task("EditedTreasure").digest() != digests[0]
    entries = build(tmp_path / "runs")
    assert sorted((e.variant, e.seeds) for e in entries) == [("a", [0]), ("b", [0])]
    assert {e.differs["rules"] for e in entries} == set(digests)
    assert episode_progress(second) is not None
    with pytest.raises(RunError, match="task 'EditedTreasure' ran under other rules"):
        episode_progress(first)  # its episodes' bits would be read against the edited automaton


def test_a_product_run_is_recorded_as_one_and_keyed_apart(tmp_path):
    plain = recorded_config(ENV, "my-dqn")
    product = recorded_config(ENV, "my-dqn", product=True)
    assert (plain.product, product.product) == (False, True) and plain.run_name() != product.run_name()
    with craftsuite.Recorder(ENV, tmp_path, method="my-dqn", product=True) as env, \
            craftsuite.Recorder(ENV, tmp_path, method="my-dqn") as other:  # the same method and seed: two runs
        assert json.loads((env.path / "config.json").read_text())["product"] is True
        assert env.observation_space.shape != other.observation_space.shape
    with pytest.raises(ValueError, match="product must be True .* or False, got 'yes'"):
        recorded_config(ENV, "my-dqn", product="yes")
