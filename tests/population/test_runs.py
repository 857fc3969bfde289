"""Population members are ordinary runs: each writes the run directory the other commands
read, its model loads as an SB3 agent acting as the member did, a killed population resumes
from its checkpoint, and bad input is refused before anything is written."""

import dataclasses
import json
import warnings
from pathlib import Path

import numpy as np
import pytest
import torch as th

import craftsuite  # noqa: F401
from craftsuite import provenance
from craftsuite.agents.factory import load_agent
from craftsuite.configs import StudentConfig
from craftsuite.population import EngineError, train_population
from craftsuite.population import train as population_train
from craftsuite.runs import read_csv

TD3 = {"batch_size": 32, "learning_starts": 200, "policy_kwargs": {"net_arch": [16, 16]}, "prioritized": False,
       "action_noise": {"type": "persistent", "sigma": 0.6, "resample": 0.1}}
DQN = {"batch_size": 32, "learning_starts": 200, "policy_kwargs": {"net_arch": [16, 16]}, "gradient_steps": 2}


def _cell(method="td3", world="Kinematic", task="Reach", seeds=(0, 1, 2), steps=1_200, **kw):
    hyper = TD3 if world in ("Kinematic", "Cont") else DQN
    return [StudentConfig(task=task, method=method, world=world, seed=s, steps=steps, eval_every=400,
                          eval_episodes=3, hyperparameters=hyper, n_envs=4, engine="population", **kw)
            for s in seeds]


def test_members_write_ordinary_runs(tmp_path):
    configs = _cell()
    paths = train_population(configs, tmp_path, progress=False)
    assert [p.name for p in paths] == [c.run_name() for c in configs]
    for config, path in zip(configs, paths):
        result = json.loads((path / "result.json").read_text())
        assert (result["engine"], result["members"], result["steps"], result["seed"]) == \
            ("population", 3, 1_200, config.seed)
        assert result["updates"] == (1_200 - 200) // 4  # one update per step of 4 envs once learning starts
        assert [int(r["step"]) for r in read_csv(path / "evals.csv")] == [400, 800, 1200]
        assert json.loads((path / "config.json").read_text())["engine"] == "population"
        assert not (path / "checkpoint").exists()
    agent = load_agent(paths[1] / "model.zip")
    assert type(agent).__name__ == "AutomatonTD3" and agent.num_timesteps == 1_200
    # a second call trains nothing: every member is finished, its records left as they were
    records = [(p / "result.json").read_text() + (p / "config.json").read_text() for p in paths]
    assert train_population(configs, tmp_path, progress=False) == paths
    assert [(p / "result.json").read_text() + (p / "config.json").read_text() for p in paths] == records


@pytest.mark.parametrize("features", ["flatten", "residual-cnn"])
def test_a_members_model_acts_as_the_member(features, tmp_path, monkeypatch):
    """Also with the paper's residual CNN: its weights and batch-norm statistics saved."""
    seen = {}
    finish = population_train._finish

    def spy(pop, k, *args):
        seen["pop"] = pop
        finish(pop, k, *args)

    monkeypatch.setattr(population_train, "_finish", spy)
    cell = _cell("product-dqn", "Grid7", "FirstTool", seeds=(4, 5), layout_seed=0)
    cell = [dataclasses.replace(c, hyperparameters={**c.hyperparameters, "features_extractor": features})
            for c in cell]
    paths = train_population(cell, tmp_path, progress=False)
    pop = seen["pop"]
    obs_dim = load_agent(paths[0] / "model.zip").observation_space.shape[0]
    obs = np.random.default_rng(0).random((2, 7, obs_dim)).astype(np.float32)
    greedy = pop.greedy(obs)
    for k, path in enumerate(paths):
        agent = load_agent(path / "model.zip")
        np.testing.assert_array_equal(agent.predict(obs[k], deterministic=True)[0], greedy[k])


def _killed_at_the_second_evaluation(configs, root, monkeypatch, at: str = "_evaluate", call: int = 2) -> None:
    """The population killed at the second (``call``-th) call of ``at``: its evaluation
    (before it is made), or ``_checkpoint`` (the evaluation made and logged, its checkpoint not)."""
    real, calls = getattr(population_train, at), {"n": 0}

    def dies(*args):
        calls["n"] += 1
        if calls["n"] == call:
            raise KeyboardInterrupt
        return real(*args)

    with monkeypatch.context() as patch:
        patch.setattr(population_train, at, dies)
        with pytest.raises(KeyboardInterrupt):
            train_population(configs, root, progress=False)


def test_a_killed_population_resumes_from_its_checkpoint(tmp_path, monkeypatch):
    configs = _cell("crm", "Grid7", "FirstTool", seeds=(0, 1), layout_seed=0)
    _killed_at_the_second_evaluation(configs, tmp_path, monkeypatch)
    first = [read_csv(tmp_path / c.run_name() / "evals.csv") for c in configs]
    assert [len(e) for e in first] == [1, 1]
    loaded = {}
    load = population_train.Population.load_states

    def spy(self, states):
        loaded["steps"] = [s["num_timesteps"] for s in states]
        load(self, states)
        loaded["replay"] = self.replay.size

    monkeypatch.setattr(population_train.Population, "load_states", spy)
    # each member's share of the wall time its checkpoint records (as if the first session had
    # run long) carries over into its result, beside the resumed session's own
    for k, config in enumerate(configs):
        [step] = (tmp_path / config.run_name()).glob("*/step.json")
        saved = json.loads(step.read_text())
        assert saved["num_timesteps"] == 400 and saved["seconds_share"] > 0
        step.write_text(json.dumps({**saved, "seconds_share": 1_000.0 * (k + 1)}))
    paths = train_population(configs, tmp_path, progress=False)
    assert loaded == {"steps": [400, 400], "replay": 400}  # resumed with its replay, not from step 0
    for k, (path, before) in enumerate(zip(paths, first)):
        result = json.loads((path / "result.json").read_text())
        # two members share the resumed session's wall time
        assert result["seconds_share"] == pytest.approx(1_000.0 * (k + 1) + result["seconds_this_session"] / 2, abs=0.2)
        assert result["machine"] == provenance.machine()  # the machine it finished on
        assert result["updates"] == 2 * (1_200 - 200) // 4  # none lost
        evals = read_csv(path / "evals.csv")
        assert evals[0] == before[0] and [int(r["step"]) for r in evals] == [400, 800, 1200]
        steps = [int(r["step"]) for r in read_csv(path / "episodes.csv")]
        assert steps == sorted(steps)
        assert len(json.loads((path / "config.json").read_text())["provenance"]) == 2


def test_a_run_resumed_from_a_checkpoint_without_its_time_records_no_share(tmp_path, monkeypatch):
    """A checkpoint written before checkpoints kept the time: the run's time across the stop
    is not known, so its result says nothing of it rather than this session's alone."""
    configs = _cell(seeds=(0,))
    _killed_at_the_second_evaluation(configs, tmp_path, monkeypatch)
    [step] = (tmp_path / configs[0].run_name()).glob("*/step.json")
    step.write_text(json.dumps({"num_timesteps": json.loads(step.read_text())["num_timesteps"]}))
    [path] = train_population(configs, tmp_path, progress=False)
    result = json.loads((path / "result.json").read_text())
    assert "seconds_share" not in result and result["seconds_this_session"] > 0


def test_a_checkpoint_written_but_not_committed_is_committed_when_resumed(tmp_path, monkeypatch):
    """A kill between a member's checkpoint-new and its commit: the population resumes from
    it and commits it, so that the next checkpoint keeps the one resumed from."""
    from craftsuite.runs import RunDir

    configs = _cell(seeds=(0, 1))
    _killed_at_the_second_evaluation(configs, tmp_path, monkeypatch)
    member = tmp_path / configs[0].run_name()
    (member / "checkpoint").rename(member / "checkpoint-new")
    folders = {}

    def stop(self, step):  # after the resume's commits, before training on
        folders[self.path.name] = sorted(p.name for p in self.path.glob("checkpoint*"))
        raise KeyboardInterrupt

    monkeypatch.setattr(RunDir, "trim_logs", stop)
    with pytest.raises(KeyboardInterrupt):
        train_population(configs, tmp_path, progress=False)
    assert folders[member.name] == ["checkpoint"]


def test_a_damaged_checkpoint_is_passed_over_for_the_populations_step_before(tmp_path, monkeypatch):
    """Checkpoints at 400 and 800, member 1's newest damaged: every member resumes from 400
    (a warning names the file), the damaged one kept aside, member 0's 800 out of the
    rotation (so the next commit keeps the 400 resumed from), and the runs finish."""
    configs = _cell(seeds=(0, 1))
    _killed_at_the_second_evaluation(configs, tmp_path, monkeypatch, call=3)
    member = tmp_path / configs[1].run_name()
    (member / "checkpoint" / "population.pt").write_bytes(b"not a checkpoint")
    loaded = {}
    load = population_train.Population.load_states

    def spy(self, states):
        loaded["steps"] = [s["num_timesteps"] for s in states]
        loaded["folders"] = [sorted(p.name for p in (tmp_path / c.run_name()).glob("checkpoint*")) for c in configs]
        load(self, states)

    monkeypatch.setattr(population_train.Population, "load_states", spy)
    # the file's own error (not mapped: it is no zip archive), not torch's advice on mapping
    with pytest.warns(RuntimeWarning, match=r"resuming from step 400.*population.pt cannot be loaded "
                                            r"\(UnpicklingError"):
        paths = train_population(configs, tmp_path, progress=False)
    assert loaded["steps"] == [400, 400]
    assert loaded["folders"] == [["checkpoint-old"], ["checkpoint-old", "checkpoint-unloadable"]]
    assert (member / "checkpoint-unloadable" / "population.pt").read_bytes() == b"not a checkpoint"
    for path in paths:
        assert [int(r["step"]) for r in read_csv(path / "evals.csv")] == [400, 800, 1200]


def test_a_population_that_cannot_resume_says_so_and_deletes_nothing(tmp_path, monkeypatch):
    from craftsuite.runs import CheckpointError

    configs = _cell(seeds=(0, 1))
    _killed_at_the_second_evaluation(configs, tmp_path, monkeypatch)
    damaged = tmp_path / configs[1].run_name() / "checkpoint" / "population.pt"
    damaged.write_bytes(b"not a checkpoint")
    with pytest.raises(CheckpointError, match=f"{damaged}.* cannot be loaded"):
        train_population(configs, tmp_path, progress=False)
    (tmp_path / configs[1].run_name() / "checkpoint" / "step.json").write_text('{"num_timesteps": 800}')
    with pytest.raises(CheckpointError, match=r"different steps \(\[400\], \[800\]\)"):
        train_population(configs, tmp_path, progress=False)
    assert all(len(read_csv(tmp_path / c.run_name() / "evals.csv")) == 1 for c in configs)  # logs kept


def test_a_population_is_reproducible(tmp_path):
    configs = [c.__class__(**{**c.__dict__,
                              "hyperparameters": {**TD3, "action_noise": {"type": "normal", "sigma": 0.3}}})
               for c in _cell(seeds=(0, 1), steps=800)]
    first = train_population(configs, tmp_path / "a", progress=False)
    again = train_population(configs, tmp_path / "b", progress=False)
    for a, b in zip(first, again):
        assert (a / "episodes.csv").read_text() == (b / "episodes.csv").read_text()
        assert (a / "evals.csv").read_text() == (b / "evals.csv").read_text()


def test_bad_input_leaves_nothing_behind(tmp_path):
    with pytest.raises(EngineError, match="train_freq \\[4, 'episode'\\].*; leave it out of the run's settings$"):
        train_population([StudentConfig(task="Reach", method="dqn", world="Grid7", steps=100, engine="population",
                                        hyperparameters={"train_freq": [4, "episode"]})], tmp_path)
    with pytest.raises(EngineError, match="differ in \\['steps'\\]"):
        train_population(_cell(seeds=(0,)) + _cell(seeds=(1,), steps=800), tmp_path)
    with pytest.raises(EngineError, match="seeds must differ"):
        train_population(_cell(seeds=(0, 0)), tmp_path)
    with pytest.raises(EngineError, match="not a torch device"):
        train_population(_cell(), tmp_path, device="gpu0")
    if not th.cuda.is_available():
        with pytest.raises(EngineError, match="no CUDA GPU; use --device cpu"):
            train_population(_cell(), tmp_path, device="cuda")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not th.cuda.is_available(), reason="needs a CUDA GPU")
def test_a_population_trains_on_the_gpu(tmp_path):
    paths = train_population(_cell(), tmp_path, progress=False, device="cuda")
    assert json.loads((paths[0] / "result.json").read_text())["device"] == "cuda"
    load_agent(paths[0] / "model.zip")


@pytest.mark.parametrize("argv,message", [
    (["transfer", "--suite", "quick", "--device", "gpu0"], "--device 'gpu0' is not a torch device"),
    (["student", "Reach", "--world", "Grid10", "--method", "dqn", "--engine", "sb3"],
     ": the sb3 engine no longer trains (finished sb3 runs are reused, and this one is not finished); train it with "
     "--engine population"),
    (["student", "Reach", "--world", "Grid10", "--method", "dqn", "--engine", "population", "--hyper",
      '{"train_freq": [1, "episode"]}'], "does not support train_freq [1, 'episode']"),
])
def test_the_command_line_refuses_what_the_engine_cannot_run(argv, message, tmp_path, capsys):
    from craftsuite.cli import main

    assert main([*argv, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]
    assert not (tmp_path / "out").exists()


def test_suites_train_each_cell_as_one_population():
    from craftsuite.suite_runner import cells
    from craftsuite.suites import SUITES

    from craftsuite.task_registry import resolve_task

    standard = SUITES["standard"]
    jobs = cells(standard.student_configs("teachers"))
    assert all(len(job) == standard.seeds_for(resolve_task(job[0].task), job[0].world) for job in jobs)
    assert {len(job) for job in jobs} == {10, 20}  # 20 on the Grid10 middle rungs
    assert all(sorted(c.seed for c in job) == list(range(len(job))) for job in jobs)
    assert {c.engine for s in SUITES.values() for c in s.student_configs("teachers")} == {"population"}
    sb3 = [dataclasses.replace(c, engine="sb3") for c in SUITES["paper"].student_configs("teachers")]
    assert len(cells(sb3)) == len(sb3)  # one job per SB3 run: each reused alone


def test_a_cell_splits_into_populations_of_at_most_members_seeds_in_seed_order():
    from craftsuite.suite_runner import cells
    from craftsuite.suites import SUITES

    configs = SUITES["standard"].student_configs("teachers")
    whole, split = cells(configs), cells(configs, members=3)
    assert [len(job) for job in split[:4]] == [3, 3, 3, 1]  # 10 seeds
    assert [c.seed for job in split[:4] for c in job] == [c.seed for c in whole[0]]
    assert {c.cell() == whole[0][0].cell() for job in split[:4] for c in job} == {True}
    assert sorted(c.run_name() for job in split for c in job) == sorted(c.run_name() for c in configs)
    assert cells(configs, members=50) == whole


def test_seeds_added_to_a_cell_train_together_as_populations_of_members():
    from craftsuite.configs import StudentConfig
    from craftsuite.suite_runner import cells

    # 20 seeds finished, 7 asked for: one population of the 7, not seed 20 with 14-19 and then 21-26
    configs = [StudentConfig(method="dqn", world="Grid10", seed=s, steps=1000) for s in range(27)]
    jobs = cells(configs, members=7, finished=lambda c: c.seed < 20)
    assert [c.seed for c in jobs[0]] == list(range(20, 27))
    assert [[c.seed for c in job] for job in jobs[1:]] == [list(range(0, 7)), list(range(7, 14)),
                                                            list(range(14, 20))]  # train nothing
    assert [[c.seed for c in job] for job in cells(configs, members=7)] == [
        list(range(i, min(i + 7, 27))) for i in range(0, 27, 7)]  # without the predicate: seed order


def test_each_member_logs_to_tensorboard_as_an_sb3_run_and_a_resume_drops_what_the_kill_logged(tmp_path,
                                                                                             monkeypatch):
    from ..scalars import hparams_sessions, scalar_steps

    configs = _cell("dqn", "Grid7", "FirstTool", seeds=(0, 1), layout_seed=0)
    _killed_at_the_second_evaluation(configs, tmp_path, monkeypatch, at="_checkpoint")  # 800 logged, not kept
    killed = scalar_steps(tmp_path / configs[0].run_name() / "tb" / "run_0")
    assert killed["eval/success_rate"] == [400, 800]  # logged, then lost with the kill
    paths = train_population(configs, tmp_path, progress=False)
    for config, path in zip(configs, paths):
        steps = scalar_steps(path / "tb" / "run_0")
        for tag in ("eval/mean_reward", "eval/success_rate", "eval/mean_ep_length"):  # SB3's tags
            assert steps[tag] == [400, 800, 1200]  # each once: the killed session's 800 is dropped
        assert steps["rollout/ep_rew_mean"] and all(s == sorted(set(s)) for s in steps.values())
        [settings] = hparams_sessions(path / "tb" / "run_0")  # once per run, by the session that started it
        assert settings["method"] == "dqn" and settings["seed"] == config.seed and settings["engine"] == "population"


def test_an_experiment_sees_each_evaluation_through_the_hook(tmp_path):
    seen = []

    def hook(pop, step, results):
        seen.append((step, pop.K, [round(r[0], 2) for r in results]))

    configs = _cell("dqn", "Grid7", "FirstTool", seeds=(0, 1), layout_seed=0)
    paths = train_population(configs, tmp_path, progress=False, on_evaluation=hook)
    assert [s for s, _, _ in seen] == [400, 800, 1200] and all(k == 2 for _, k, _ in seen)
    for k, path in enumerate(paths):  # the results the hook saw are the ones each run recorded
        assert [round(float(r["success"]), 2) for r in read_csv(path / "evals.csv")] == [s[2][k] for s in seen]


def test_a_cpu_population_trains_on_one_thread_with_subnormals_flushed_and_restores_both(tmp_path, monkeypatch):
    # late in a run a sixth of the Adam moments are subnormal, slow to compute with on x86
    seen, build = [], population_train.build_population

    def spy(*args, **kwargs):
        seen.append((th.get_num_threads(), population_train.flushing_subnormals()))
        return build(*args, **kwargs)

    monkeypatch.setattr(population_train, "build_population", spy)
    threads = th.get_num_threads()
    can_flush = th.set_flush_denormal(True)  # False where the CPU cannot: then nothing is flushed
    try:
        th.set_flush_denormal(False)
        th.set_num_threads(2)
        assert not population_train.flushing_subnormals()  # torch's default: subnormals kept
        train_population(_cell(seeds=(0,), steps=400), tmp_path, progress=False)
        assert seen == [(1, can_flush)]
        assert (th.get_num_threads(), population_train.flushing_subnormals()) == (2, False)  # the caller's again
    finally:
        th.set_flush_denormal(False)
        th.set_num_threads(threads)


def test_the_available_memory_is_the_machines_within_a_containers_limit(tmp_path):
    (tmp_path / "proc").mkdir()
    (tmp_path / "proc" / "meminfo").write_text("MemTotal:       24000000 kB\nMemAvailable:   16000000 kB\n")
    assert population_train._available_memory(tmp_path) == 16_000_000 * 1024  # no cgroup files: the machine's
    cgroup = tmp_path / "sys" / "fs" / "cgroup"
    cgroup.mkdir(parents=True)
    (cgroup / "memory.max").write_text("max\n")
    (cgroup / "memory.current").write_text("1000\n")
    assert population_train._available_memory(tmp_path) == 16_000_000 * 1024  # no limit
    (cgroup / "memory.max").write_text(f"{8 * 2**30}\n")
    (cgroup / "memory.current").write_text(f"{2**30}\n")
    assert population_train._available_memory(tmp_path) == 7 * 2**30  # the container's limit, less its use
    (tmp_path / "proc" / "meminfo").write_text("MemTotal:       24000000 kB\n")
    assert population_train._available_memory(tmp_path) is None  # not said: not known


def test_a_population_whose_full_replay_exceeds_the_available_memory_is_warned_of_as_sb3_does(monkeypatch):
    from types import SimpleNamespace

    pop = SimpleNamespace(K=10, total_steps=1_000_000, replay=SimpleNamespace(nbytes=12 * 2**30, capacity=1_000_000))
    with pytest.warns(RuntimeWarning, match=r"12\.0 GiB at its budget \(10 members x 1,000,000 transitions\), "
                                            r"more than the 8\.0 GiB .*--members.*--workers"):
        population_train.warn_if_replay_exceeds_memory(pop, available=8 * 2**30)
    short = SimpleNamespace(K=10, total_steps=500_000, replay=pop.replay)  # fills half its replay
    with pytest.warns(RuntimeWarning, match=r"6\.0 GiB at its budget \(10 members x 500,000 transitions\)"):
        population_train.warn_if_replay_exceeds_memory(short, available=5 * 2**30)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        population_train.warn_if_replay_exceeds_memory(pop, available=16 * 2**30)  # fits: nothing said
        monkeypatch.setattr(population_train, "_available_memory", lambda: None)
        population_train.warn_if_replay_exceeds_memory(pop)  # not known: nothing said


def test_populations_training_at_once_are_warned_of_where_together_they_exceed_the_memory(monkeypatch):
    """Each population alone fits; side by side (a suite's --workers) they would not."""
    member = {"Grid10": int(1.2 * 2**30), "Cont": int(0.6 * 2**30)}  # one member's replay at its budget, by world
    monkeypatch.setattr(population_train, "member_replay_bytes", lambda c: member[c.world])
    grid = [[StudentConfig(method="dqn", world="Grid10", seed=s) for s in range(10 * i, 10 * i + 10)] for i in (0, 1)]
    cont = [[StudentConfig(method="td3", world="Cont", seed=s) for s in range(10)]]
    with pytest.warns(RuntimeWarning) as said:
        population_train.warn_if_replays_exceed_memory(cont + grid, 2, available=20 * 2**30)
    [warning] = said
    assert str(warning.message) == (
        "the 2 largest populations, training at once, will hold 24.0 GiB of replay at their budgets (1.20 GiB a "
        "member at most), more than the 20.0 GiB this machine has available, and may be killed for memory hours "
        "in: train with fewer seeds a population (--members 8 --workers 2) or fewer populations at once (--workers 1)")
    with pytest.warns(RuntimeWarning, match=r"^the largest population will hold 12\.0 GiB of replay at its budget "
                                            r".* train with fewer seeds a population \(--members 8 --workers 1\)$"):
        population_train.warn_if_replays_exceed_memory(grid, 1, available=10 * 2**30)
    with pytest.warns(RuntimeWarning, match=r"train with a smaller replay \(buffer_size"):  # one member too many
        population_train.warn_if_replays_exceed_memory(grid, 1, available=2**30)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        population_train.warn_if_replays_exceed_memory(cont + grid, 2, available=25 * 2**30)  # fits: nothing said
        population_train.warn_if_replays_exceed_memory(cont + grid, 1, available=20 * 2**30)
        population_train.warn_if_replays_exceed_memory([], 2, available=0)
        monkeypatch.setattr(population_train, "_available_memory", lambda: None)
        population_train.warn_if_replays_exceed_memory(cont + grid, 2)  # not known: nothing said


@pytest.mark.parametrize("method, world, steps", [("td3-static", "Kinematic", 1_200), ("crm", "Grid7", 900)])
def test_a_members_replay_is_told_before_its_population_is_built(method, world, steps):
    """What the transfer's memory check reads per member is what each member of the built
    population holds at the budget (a CRM replay's counterfactual rows and its sum trees too)."""
    from craftsuite.population.envs import make_envs
    from craftsuite.task_registry import resolve_task

    configs = _cell(method=method, world=world, steps=steps, seeds=(0, 1, 2))
    config, spec = configs[0], resolve_task(configs[0].task)
    envs = make_envs(config.env_id, 3 * config.n_envs, config.env_kwargs, config.product)
    try:
        pop = population_train.build_population(config, [0, 1, 2], config.effective()["hyperparameters"], spec,
                                                None, th.device("cpu"), envs)
    finally:
        envs.close()
    held = population_train.held_at_budget(pop.replay, steps)
    assert held > 0 and held == 3 * population_train.member_replay_bytes(config)


def test_a_checkpoint_is_read_mapped_so_that_a_resume_holds_no_member_rows_twice(tmp_path):
    """A resume reads every member's state before copying its rows into the replay: read
    into memory, every member's rows would be held twice until then."""
    status = Path("/proc/self/status")
    if not status.exists():
        pytest.skip("reads the process's anonymous memory from Linux's /proc")

    def anonymous() -> int:
        return next(int(line.split()[1]) * 1024 for line in status.read_text().splitlines()
                    if line.startswith("RssAnon:"))

    rows = np.random.default_rng(0).random(25_000_000, dtype=np.float32)  # 100 MB
    th.save({"replay": {"rewards": th.from_numpy(rows)}}, tmp_path / "population.pt")
    replay = np.zeros_like(rows)
    replay[:] = 1.0  # resident already, as a population's replay is when it resumes
    before = anonymous()
    state = population_train.read_member_state(tmp_path / "population.pt")
    replay[:] = state["replay"]["rewards"].numpy()
    held = anonymous() - before  # before the comparison below allocates
    assert (replay == rows).all()
    assert held < 0.1 * rows.nbytes  # read into memory: about 1.0x


def test_a_resumed_population_keeps_no_checkpoint_mapped(tmp_path, monkeypatch):
    """Nothing of the states read at a resume outlives it: a tensor kept from a mapped
    checkpoint would keep the whole file mapped (and its disk space, once rotated away)."""
    maps = Path("/proc/self/maps")
    if not maps.exists():
        pytest.skip("reads the process's mappings from Linux's /proc")
    configs = _cell(seeds=(0, 1))
    _killed_at_the_second_evaluation(configs, tmp_path, monkeypatch)
    mapped, evaluate = [], population_train._evaluate

    def looks(*args):
        mapped.append([line for line in maps.read_text().splitlines() if population_train.CHECKPOINT in line])
        return evaluate(*args)

    monkeypatch.setattr(population_train, "_evaluate", looks)
    train_population(configs, tmp_path, progress=False)
    assert mapped and all(lines == [] for lines in mapped)


@pytest.mark.parametrize("task, same", [("Reach", True), ("FirstTool", False)])
def test_crm_trains_as_the_product_dqn_where_the_automaton_has_one_live_state(tmp_path, task, same):
    """CRM adds a counterfactual experience for each other live automaton state: on a rung
    whose automaton has one (Reach), there is none, and its runs are product-dqn's seed for
    seed (the methods' legend says so; a reader took the equal rows for a bug); with more
    (FirstTool), they are not."""
    from craftsuite.population.replay import CounterfactualView
    from craftsuite.task_registry import resolve_task

    assert (CounterfactualView(resolve_task(task).automaton, 100.0, 8).n_live == 1) == same  # CRM's own count
    runs = {m: train_population(_cell(m, "Grid10", task, seeds=(0,), steps=800), tmp_path / m, progress=False)
            for m in ("crm", "product-dqn")}
    (crm,), (product,) = runs["crm"], runs["product-dqn"]
    assert ((crm / "episodes.csv").read_text() == (product / "episodes.csv").read_text()) == same


def test_a_crm_members_model_is_saved_and_loaded_without_a_replay_of_its_size(tmp_path, monkeypatch):
    """A member's model.zip holds no replay, yet SB3 builds one of the run's size to save it
    and again to load it: a CRM student's holds a row per live automaton state (35 GiB on
    Diamond Mine's grid, which stopped a population of 1M-transition runs as it finished).
    Both are built at one row (CRM's: one a live state); the model still says the run's size."""
    import zipfile

    from craftsuite.agents import factory
    from craftsuite.agents.crm import CRMReplayBuffer

    built = []
    make = factory.make_agent

    def spy(*args, **kwargs):
        agent = make(*args, **kwargs)
        built.append(agent.replay_buffer)
        return agent

    monkeypatch.setattr(factory, "make_agent", spy)
    [path] = train_population(_cell("crm", "Grid10", "FirstTool", seeds=(0,), steps=600), tmp_path, progress=False)
    asked = json.loads((path / "config.json").read_text())["effective"]["hyperparameters"]["buffer_size"]
    [replay] = built
    assert isinstance(replay, CRMReplayBuffer) and replay.observations.shape[:2] == (1, replay.n_live)  # SB3's rows
    agent = load_agent(path / "model.zip")
    assert isinstance(agent.replay_buffer, CRMReplayBuffer) and agent.replay_buffer.observations.shape[0] == 1
    assert json.loads(zipfile.ZipFile(path / "model.zip").read("data"))["buffer_size"] == asked > 1
