"""A recorder for any training loop: the run directory a suite's run writes, for an agent
trained outside CraftSuite.

``Recorder`` is a gymnasium wrapper around the suite's env of a rung: a user's own loop
steps it as it would the env, and calls ``evaluate(policy)`` when ``evaluation_due`` says
the suite's schedule has come (every 20th of the budget, ``craftsuite.evaluate``'s
protocol), and ``finish(policy, updates=...)`` at the budget. It writes what the suites'
runs write, in their record format (``craftsuite.runs``): ``config.json`` (the method's
name, the library, the budget, the settings as given, whether the agent observed the
automaton state, the task's rules digest, provenance and the user's commit),
``episodes.csv`` (every training episode, with how far along the task it got),
``evals.csv`` and, last, ``result.json`` (transitions and gradient updates). Its records are
marked ``self_reported``: CraftSuite did not train them, and says so wherever it shows them.

    env = craftsuite.Recorder("CraftSuite/ToolHome-Cont-v0", "my_runs", method="my-sac", seed=0)
    obs, _ = env.reset(seed=0)
    while not env.done:
        obs, reward, terminated, truncated, info = env.step(agent.act(obs))
        ...  # learn
        if terminated or truncated:
            obs, _ = env.reset()
        if env.evaluation_due:
            env.evaluate(agent.act)
    env.finish(agent.act, updates=agent.updates)

A step past the budget is refused: a library that collects in rollouts (SB3's PPO, say) stops
at it through a callback that returns ``not env.done``. An evaluation called late is recorded
at its scheduled step (its seeds are that step's), and ``finish`` warns of any, and of any
skipped: a late one plays a policy that trained on more transitions than its step says. An
episode cut short by ``reset`` is recorded as one a time limit ends (not completed). A
recording closed before ``finish`` stays, unfinished, where it wrote anything: the
leaderboard leaves it out, and a second recording of that run is refused until it is deleted.
"""

from __future__ import annotations

import operator
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import gymnasium as gym
import numpy as np

from .ids import env_id
from .envs.grid import layout_kwargs
from .runs import EPISODE_FIELDS, EVAL_FIELDS, RunDir, RunError, config_key, evaluation_steps


@dataclass(frozen=True)
class RecordedConfig:
    """A self-reported run's configuration: what its ``config.json`` records and hashes
    into its run key (the world's settings as the suite's; the learner's as given)."""

    task: str
    method: str  # the user's own name (not one of CraftSuite's METHODS rows)
    world: str
    seed: int
    steps: int  # the budget in transitions
    eval_every: int
    eval_episodes: int
    suite: str = "standard"
    library: str = ""  # what trained it, e.g. "stable-baselines3 2.4 SAC"
    settings: dict = field(default_factory=dict)  # the learner's settings, as given (not read by CraftSuite)
    commit: str | None = None  # the user's code's commit, where given
    layout_seed: int | None = None
    world_kwargs: dict = field(default_factory=dict)
    # whether the agent observed the automaton state (recorded where it did: a plain run keeps the key it had)
    product: bool = field(default=False, metadata={"omit_if_default": True})
    rules: str | None = None  # the digest of the task's rules (a task edited since records under another key)
    self_reported: bool = True

    @property
    def env_id(self) -> str:
        return env_id(self.task, self.world)

    @property
    def env_kwargs(self) -> dict:
        return {**layout_kwargs(self.layout_seed), **self.world_kwargs}

    def run_name(self) -> str:
        return f"student-{self.task}-{self.world}-{self.method}-s{self.seed}-{config_key(self)}"


def _count(value) -> int | None:
    """``value`` as an integer where it is one (numpy's and torch's too; not a bool), else None."""
    if isinstance(value, bool):
        return None
    try:
        return operator.index(value)
    except TypeError:
        return None


def recorded_config(env_id: str, method: str, seed: int = 0, suite: str = "standard", library: str = "",
                    settings: dict | None = None, commit: str | None = None,
                    steps: int | None = None, product: bool = False) -> RecordedConfig:
    """The record of a run of ``method`` on ``env_id`` under ``suite``'s protocol
    (``steps``: another budget than the suite's for the rung, evaluated on the suite's
    schedule for it; the leaderboard never compares it with runs of another budget;
    ``product``: whether the agent observes the automaton state). Its task's rules digest
    is recorded: runs of a task edited between them are never pooled.

    Raises:
        ValueError: a method named as one of CraftSuite's (its runs would pool with the
            archive's), a bad seed, id or suite, a world the suite does not run; each named
            with its fix.
    """
    from .evaluation import protocol
    from .methods import METHODS

    if not isinstance(method, str) or not method or any(c in method for c in "/\\ "):
        raise ValueError(f"method must be a name without spaces or slashes, e.g. my-sac, got {method!r}")
    if method in METHODS:
        raise ValueError(f"method {method!r} is one of CraftSuite's own methods: name yours (e.g. my-{method}), "
                         "so that its runs never pool with the archive's")
    count = _count(seed)  # numpy's integers too, as a loop over np.arange gives them
    if count is None or count < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    seed = count
    if not isinstance(library, str):
        raise ValueError(f"library must be a string naming what trained the run, e.g. 'stable-baselines3 2.4 SAC', "
                         f"got {library!r}")
    if commit is not None and not isinstance(commit, str):
        raise ValueError(f"commit must be the commit of your code as a string (or None), got {commit!r}")
    if not isinstance(product, (bool, np.bool_)):
        raise ValueError(f"product must be True (the observation carries the automaton state) or False, "
                         f"got {product!r}")
    from .suites import SUITES
    from .task_registry import resolve_task

    suite_config, _ = protocol(env_id, suite)
    if suite_config.world not in SUITES[suite].worlds:  # its runs would sit beside none of the suite's
        from .ids import env_id as env_id_of  # (this function's argument is named env_id)
        from .ids import world_kind

        alike = [w for w in SUITES[suite].worlds if world_kind(w) == world_kind(suite_config.world)]
        raise ValueError(f"the {suite!r} suite runs no {suite_config.world} world (its worlds: "
                         f"{', '.join(SUITES[suite].worlds)}): record in one of them"
                         + (f", e.g. {env_id_of(suite_config.task, alike[0])}" if alike else ""))
    if steps is not None:
        if not isinstance(steps, int) or isinstance(steps, bool) or steps < 1:
            raise ValueError(f"steps (the budget in transitions) must be a positive integer, got {steps!r}")
        eval_every = SUITES[suite].eval_interval(steps, suite_config.world)
    else:
        steps, eval_every = suite_config.steps, suite_config.eval_every
    return RecordedConfig(task=suite_config.task, method=method, world=suite_config.world, seed=seed,
                          steps=steps, eval_every=eval_every,
                          eval_episodes=suite_config.eval_episodes, suite=suite, library=library,
                          settings=recorded_settings(settings), commit=commit, layout_seed=suite_config.layout_seed,
                          world_kwargs=dict(suite_config.world_kwargs), product=bool(product),
                          rules=resolve_task(suite_config.task).digest())


def recorded_settings(settings) -> dict:
    """The learner's settings as ``config.json`` keeps them: a mapping of JSON's values
    (numpy's scalars as the numbers they hold, integer keys as the strings JSON makes them).
    Anything else (a class, a function, a NaN) is named by its key, with what to record
    instead: the record is JSON, and its key hashes it.

    Raises:
        ValueError: settings that are not a mapping of JSON values, naming the first key at fault.
    """
    if settings is None:
        return {}
    if not isinstance(settings, Mapping):
        raise ValueError(f"settings must be a dict of the learner's settings, e.g. {{'learning_rate': 3e-4}}, "
                         f"got {type(settings).__name__} {settings!r:.60}")

    def plain(value, where: str):
        if isinstance(value, np.floating):  # np.float32(0.99): the number as numpy prints it, 0.99
            value = float(str(value))
        elif isinstance(value, np.generic):  # np.int64(256), np.bool_: the value it holds
            value = value.item()
        if value is None or isinstance(value, (bool, int, str)):
            return value
        if isinstance(value, float):
            if not np.isfinite(value):
                raise ValueError(f"settings {where} holds {value}, not a finite number, which JSON cannot hold; "
                                 f"record it as a string ({str(value)!r}) or leave it out")
            return value
        if isinstance(value, (list, tuple)):
            return [plain(v, f"{where}[{i}]") for i, v in enumerate(value)]
        if isinstance(value, Mapping):
            return mapping(value, where)
        # a class or function by its name; any other object as it prints (a path: its text)
        named = isinstance(value, type) or callable(value) and hasattr(value, "__qualname__")
        text = value.__qualname__ if named else str(value)
        raise ValueError(f"settings {where} holds {text} (a {type(value).__name__}), which a JSON record cannot "
                         f"hold; record it as a string, e.g. {text!r}")

    def mapping(value: Mapping, where: str) -> dict:
        name = f"settings {where}" if where else "settings"
        odd = [k for k in value if isinstance(k, bool) or not isinstance(k, (str, int))]
        if odd:
            raise ValueError(f"{name}: its keys must be strings or integers, got {odd[0]!r}")
        texts = [str(k) for k in value]
        if len(set(texts)) < len(texts):  # 1 and "1": one key in JSON, and one would be lost
            twice = next(t for t in texts if texts.count(t) > 1)
            raise ValueError(f"{name}: the keys {twice!r} and {int(twice)!r} are one key in a JSON record; keep one")
        return {str(k): plain(v, f"{where}[{k!r}]" if where else repr(k)) for k, v in value.items()}

    return mapping(settings, "")


_RECORDING: set[Path] = set()  # the runs being recorded in this process


class Recorder(gym.Wrapper):
    """The suite's env of a rung, recording a user's training run into ``out`` (see the
    module's docstring). The run's directory is ``out/<run name>``, as the suites' runs'."""

    def __init__(self, env_id: str, out, *, method: str, seed: int = 0, suite: str = "standard",
                 library: str = "", settings: dict | None = None, commit: str | None = None,
                 product: bool = False, steps: int | None = None):
        """Open the recording of one run (``out/<run name>``, which must not exist yet).

        Args:
            env_id: the rung, as a CraftSuite id (``CraftSuite/ToolHome-Cont-v0``).
            out: the directory of the user's runs (the leaderboard reads it).
            method: the user's own name for what trained it (not one of CraftSuite's rows).
            seed: the run's seed (each seed is one run).
            suite: the suite whose protocol (budget, schedule, world settings) it follows.
            library: what trained it, e.g. ``"stable-baselines3 2.4 SAC"``: part of the record.
            settings: the learner's settings, recorded as given (part of the run's key).
            commit: the user's code's commit.
            product: whether the env's observation carries the automaton state.
            steps: another budget than the suite's for the rung, on the suite's schedule for it.

        Raises:
            ValueError: bad settings (see ``recorded_config``), each named with its fix, or an
                empty ``out``.
            TypeError: ``out`` is no path.
            OSError: ``out`` cannot be a directory to write in (a file, no permission), named.
            RunError: the run being recorded in this process already, or recorded before.
        """
        from .files import directory_to_write
        from .reached import Reached
        from .task_registry import resolve_task

        self.config = recorded_config(env_id, method, seed, suite, library, settings, commit, steps, product)
        self.path = directory_to_write(out, "out") / self.config.run_name()
        if self.path.resolve() in _RECORDING:
            raise RunError(f"{self.path} is being recorded by another Recorder in this process: a Recorder records "
                           "one run from one env (to collect from several envs, record each seed's run apart)")
        if self.path.exists():  # a recording is one session: a second would mix two runs' logs
            state = "finished" if (self.path / "result.json").exists() else "unfinished"
            raise RunError(f"{self.path} holds a recording already ({state}): choose another seed or output "
                           "directory, or delete it to record again")
        super().__init__(gym.make(self.config.env_id, product=self.config.product, **self.config.env_kwargs))
        self.product = self.config.product
        self.run = RunDir(self.path, self.config).__enter__()  # held until finish() or close()
        _RECORDING.add(self.path.resolve())
        self.transitions = 0
        self.evaluated: list[int] = []  # the steps evaluated so far
        self.late: list[int] = []  # for each evaluation made after its step, the transitions it was late by
        self._episode = None  # (return, length) of the episode being played
        self._pending: list[dict] = []
        self._reached = Reached(resolve_task(self.config.task).automaton, 1, self.config.task)

    # -- the env ----------------------------------------------------------------------------------
    def reset(self, **kwargs):
        if self._episode is not None and self._episode[1]:  # one cut short: recorded as a time limit ends one
            self._end_episode(success=False)
        self._episode = [0.0, 0]
        self._reached.take([0])
        return self.env.reset(**kwargs)

    def step(self, action):
        self._check_open()
        if self._episode is None:
            raise RuntimeError("step() before reset(): reset the env first, as gymnasium envs need")
        if self.done:  # a transition past the budget would train the policy the budget's evaluation plays
            raise RuntimeError(f"{self.path}: the budget's {self.budget:,} transitions are collected: stop stepping "
                               "when done says so (in SB3, a callback whose _on_step returns not env.done), and "
                               "call finish(policy, updates=...)")
        obs, reward, terminated, truncated, info = self.env.step(action)
        self.transitions += 1
        self._episode[0] += float(reward)
        self._episode[1] += 1
        self._reached.step(np.array([info["label_mask"]], dtype=np.int64),
                           np.array([info["automaton_state"]], dtype=np.int64))
        if terminated or truncated:
            self._end_episode(bool(info.get("is_success")))
        return obs, reward, terminated, truncated, info

    def _end_episode(self, success: bool) -> None:
        (seen,), (states,) = self._reached.take([0])
        self._pending.append({"step": self.transitions, "return": round(self._episode[0], 4),
                              "length": self._episode[1], "success": int(success), "seen": seen, "states": states})
        self._episode = None

    def _check_open(self) -> None:
        if self.run is None:
            raise RuntimeError(f"{self.path}: the recording is finished (or closed): a Recorder records one run")

    # -- the schedule ---------------------------------------------------------------------------
    @property
    def budget(self) -> int:
        return self.config.steps

    @property
    def done(self) -> bool:
        """Whether the budget's transitions have been collected."""
        return self.transitions >= self.budget

    @property
    def next_evaluation(self) -> int:
        """The step of the next evaluation the suite's schedule holds (the budget: the last)."""
        done = self.evaluated[-1] if self.evaluated else 0
        return next((step for step in self.scheduled if step > done), self.budget)

    @property
    def scheduled(self) -> list[int]:
        """The steps of the suite's evaluations of this run: every ``eval_every`` transitions
        and at the budget."""
        return evaluation_steps(self.budget, self.config.eval_every)

    @property
    def evaluation_due(self) -> bool:
        return self.transitions >= self.next_evaluation and self.next_evaluation not in self.evaluated

    def _due_step(self) -> int:
        """The latest step of the schedule that the transitions have reached: an evaluation
        called late is that step's (a step skipped leaves the run's curve short: the board
        reads its AUC as not measured). Called when one is due, so one has been reached."""
        return [step for step in self.scheduled if step <= self.transitions][-1]

    def evaluate(self, policy):
        """The suite's evaluation at the schedule's step now due (its seeds are that
        step's), recorded; the episodes so far are written with it. Returns the
        ``craftsuite.Evaluation``."""
        from .evaluation import evaluate

        self._check_open()
        if not self.evaluation_due:
            raise RuntimeError(f"no evaluation is due at {self.transitions:,} transitions (the next is at "
                               f"{self.next_evaluation:,}): call it when evaluation_due says so")
        step = self._due_step()
        result = evaluate(policy, self.config.env_id, suite=self.config.suite, step=step,
                          episodes=self.config.eval_episodes, product=self.product)
        self._flush()
        self.run.append("evals.csv", EVAL_FIELDS, [{"step": step, "success": result.success,
                                                    "return": round(result.mean_return, 4),
                                                    "episodes": self.config.eval_episodes,
                                                    "length": round(result.mean_length, 2)}])
        self.evaluated.append(step)
        if self.transitions > step:
            self.late.append(self.transitions - step)
        return result

    def finish(self, policy, updates: int) -> Path:
        """The last evaluation (at the budget) if not yet made, then ``result.json``: the
        run is finished, and the leaderboard reads it. Returns the run's directory.

        Raises:
            ValueError: the budget not collected yet, or a bad count of gradient updates.
        """
        self._check_open()
        if not self.done:
            raise ValueError(f"{self.transitions:,} transitions of the budget's {self.budget:,}: a run is finished "
                             "at its budget (step the env until done)")
        count = _count(updates)
        if count is None or count < 0:
            raise ValueError(f"updates must be the count of gradient updates made (an integer >= 0), got {updates!r}")
        updates = count
        if self.budget not in self.evaluated:  # the last evaluation, at the budget
            self.evaluate(policy)
        skipped = sorted(set(self.scheduled) - set(self.evaluated))
        if skipped:  # said now, while the loop can still be mended, not first on a board
            warnings.warn(f"{self.path}: {len(skipped)} of the suite's {len(self.scheduled)} evaluations were not made "
                          f"(the first at step {skipped[0]:,}): the leaderboard reads this run's AUC as not measured; "
                          "call evaluate(policy) whenever evaluation_due says so", stacklevel=2)
        if self.late:  # recorded at their steps, of a policy that had trained longer: the curve reads early
            warnings.warn(f"{self.path}: {len(self.late)} of the suite's {len(self.scheduled)} evaluations were made "
                          f"after their step (by up to {max(self.late):,} transitions): each is recorded at its "
                          "step though its policy had trained on more, so the curve credits learning too early; "
                          "check evaluation_due after every step and call evaluate(policy) then", stacklevel=2)
        self._flush()
        self.run.write_result({"kind": "student", "env_id": self.config.env_id, "method": self.config.method,
                               "task": self.config.task, "seed": self.config.seed, "steps": self.transitions,
                               "updates": updates, "product": self.product, "env_kwargs": self.config.env_kwargs,
                               "self_reported": True, "library": self.config.library})
        self.close()
        return self.path

    def close(self):
        if getattr(self, "run", None) is not None:
            self._flush()
            # closed before finish(): a recording that wrote nothing but its config is removed, as
            # a run that failed at once is, so that the same script can record it again
            unfinished = not self.run.result_path.exists()
            self.run.__exit__(RuntimeError if unfinished else None, None, None)
            self.run = None
            _RECORDING.discard(self.path.resolve())
        super().close()

    def _flush(self) -> None:
        if self._pending:
            self.run.append("episodes.csv", EPISODE_FIELDS, self._pending)
            self._pending = []
