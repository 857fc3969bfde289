"""Benchmark suites as data: which tasks, worlds, methods, seeds and budgets a suite runs.

A ``Suite`` row names rungs of the task ladder (by tag or name), student worlds, methods,
seeds, a budget per rung level and each world's collection regime; ``SUITES`` is the table
of the named ones. A row gives its teachers' and students' configs (``teachers``,
``student_configs``); ``craftsuite.suite_runner.transfer`` runs them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from .configs import DEFAULT_ENGINE, StudentConfig, TeacherConfig
from .ids import CONT, KINEMATIC, WORLD_KINDS, world_kind
from .methods import METHODS, check_methods, methods_for
from .names import look_up, suggested
from .regimes import check_regime
from .spec import TaskSpec
from .task_registry import ladder, resolve_task


@dataclass(frozen=True)
class Suite:
    name: str
    description: str
    tags: tuple[str, ...] = ()  # rungs: every task with any of these tags (task_registry.ladder)
    tasks: tuple[str, ...] = ()  # rungs by name, besides those by tag
    worlds: tuple[str, ...] = ("Cont",)  # student worlds: "Cont" (MuJoCo), "Grid10", "Grid7"
    methods: tuple[str, ...] = ("td3",)  # each runs in the worlds its METHODS row is for
    seeds: int = 5
    # more seeds on some rungs, by world kind and rung name ({"Grid": {"ToolHome": 20}}): where
    # a cell is cheap enough to run to the seeds its comparisons need (experiments/twenty-seeds)
    rung_seeds: dict = field(default_factory=dict)
    # each run's budget in transitions, by world kind and rung level (TaskSpec.level), e.g.
    # {"Cont": {"easy": 150_000, "hard": 100_000}, "Grid": {...}}: the two worlds' students
    # collect at different rates and learn at different rates per transition. A rung's own
    # name overrides its level ({"Cont": {"medium": 800_000, "TwoToolsHome": 1_200_000}}): the
    # middle rungs are each calibrated to a budget. student_steps, when set, is one budget for
    # every run.
    budgets: dict = field(default_factory=dict)
    student_steps: int | None = None
    teacher_max_steps: int = 300_000
    # the teachers' protocol: their grid instance (None: a new layout every episode, as the
    # paper's authors' code drew), envs per gradient step and DQN overrides
    teacher_layout_seed: int | None = 0
    teacher_n_envs: int = 1
    teacher_hyperparameters: dict = field(default_factory=dict)
    eval_every: int | None = None  # None: 20 evaluations per run (eval_interval)
    eval_episodes: int = 20
    # each world's collection regime: envs stepped side by side per agent step, and
    # overrides of its algorithm's defaults (craftsuite.hyperparameters): MuJoCo students
    # are TD3, grid students DQN, so one network size never reaches the other
    td3_hyperparameters: dict = field(default_factory=dict)
    dqn_hyperparameters: dict = field(default_factory=dict)
    td3_n_envs: int = 1
    dqn_n_envs: int = 1
    # the learner regime (craftsuite.regimes): the TD targets and networks every method's
    # students get, over the collection regime above, so that a distilled student and
    # scratch learn by the same rule
    regime: str = "one-step"
    # the command line's settings of each algorithm (--td3-hyper, --dqn-hyper): over both
    td3_overrides: dict = field(default_factory=dict)
    dqn_overrides: dict = field(default_factory=dict)
    # grid students learn one fixed instance, generated independently of the teacher's (layout 0),
    # as the paper's did; None gives them a new layout every episode
    grid_layout_seed: int | None = 1
    # whether the distilled students see the automaton state (their automaton enters through
    # the target either way; the authors' did not see it); the other methods keep their rows'
    students_see_automaton: bool = True
    # gymnasium.make keywords of the MuJoCo students' world beyond the registered one; the
    # leaderboard names each in its world label
    cont_world_kwargs: dict = field(default_factory=dict)
    # the same for the kinematic board (its ``size``)
    kinematic_world_kwargs: dict = field(default_factory=dict)
    # what trains the teachers and students: "population" (the seeds of each cell in one
    # process, craftsuite.population; a teacher is a population of one); "sb3" (one SB3 agent
    # per run) reuses the finished runs SB3 trained before and trains none
    engine: str = DEFAULT_ENGINE
    # whether ``craftsuite transfer`` keeps its runs' records in the results archive by
    # default (``craftsuite.archive``); the quick suite trains afresh every time, for its video
    archived: bool = True

    def rungs(self) -> list[TaskSpec]:
        """The suite's tasks, easiest first."""
        if not self.tags and not self.tasks:
            raise ValueError(f"suite {self.name!r} selects no rung: give it tags or tasks")
        chosen = {s.name: s for s in ladder(*self.tags)} if self.tags else {}
        chosen.update({name: resolve_task(name) for name in self.tasks})
        return sorted(chosen.values(), key=lambda s: s.rung)

    def has_budget(self, spec: TaskSpec, world: str) -> bool:
        """Whether the suite gives a student of ``spec``'s rung a budget in ``world``: one for
        every run, for the rung by name, or for its level."""
        by = self.budgets.get(world_kind(world), {})
        return self.student_steps is not None or spec.name in by or spec.level in by

    def budget(self, spec: TaskSpec, world: str) -> int:
        """A student's budget in transitions on a rung in a world: the one for every run, else
        the rung's own, else its level's."""
        kind = world_kind(world)
        if not self.has_budget(spec, world):
            raise ValueError(f"suite {self.name!r} has no {kind} budget for {spec.name}'s level {spec.level!r} "
                             f"(tags: {', '.join(spec.tags) or 'none'}); budgets: {self.budgets}. Give every run the "
                             "same budget (--steps N, Suite.student_steps) or tag the task with a level the suite has")
        if self.student_steps is not None:
            return self.student_steps
        by = self.budgets[kind]
        return by[spec.name] if spec.name in by else by[spec.level]

    def seeds_for(self, spec: TaskSpec, world: str) -> int:
        """The seeds of a rung's cells in a world."""
        return self.rung_seeds.get(world_kind(world), {}).get(spec.name, self.seeds)

    def seeds_text(self) -> str:
        return seeds_text(self.seeds, self.rung_seeds)

    def _check_rung_seeds(self) -> None:
        """``rung_seeds`` names world kinds and registered rungs, with a whole number of seeds
        each: a misspelt key would otherwise give its rung the suite's seeds, silently. (A
        rung the suite does not run now is allowed: ``--tasks`` narrows a suite, its seeds stay.)"""
        from .task_registry import tasks

        known = tasks()
        for kind, by in self.rung_seeds.items():
            if kind not in WORLD_KINDS:
                raise ValueError(f"suite {self.name!r}: rung_seeds key {kind!r} is no world kind; use "
                                 f"{' or '.join(WORLD_KINDS)}, e.g. {{'Grid': {{'ToolHome': 20}}}}")
            if not isinstance(by, dict):
                raise ValueError(f"suite {self.name!r}: rung_seeds[{kind!r}] is {by!r}; map rung names to seeds, "
                                 f"e.g. {{{kind!r}: {{'ToolHome': 20}}}}")
            for rung, seeds in by.items():
                if rung not in known:
                    raise ValueError(f"suite {self.name!r}: rung_seeds[{kind!r}] names {suggested(rung, known)}, "
                                     f"which is no registered rung; known: {', '.join(sorted(known))}")
                if isinstance(seeds, bool) or not isinstance(seeds, int) or seeds < 1:
                    raise ValueError(f"suite {self.name!r}: rung_seeds[{kind!r}][{rung!r}] is {seeds!r}; give a "
                                     "whole number of seeds, 1 or more")

    def n_envs(self, world: str) -> int:
        """The envs a student steps side by side in ``world`` (its collection regime)."""
        return self.td3_n_envs if world_kind(world) == CONT else self.dqn_n_envs

    def eval_interval(self, steps: int, world: str) -> int:
        """The transitions between a student's evaluations: the suite's ``eval_every``, else
        a 20th of its budget (every run's curve has the same resolution, whatever its budget),
        but never less than one step of its envs, the least between two evaluations."""
        return self.eval_every or max(self.n_envs(world), steps // 20)

    def teachers(self) -> dict[str, TeacherConfig]:
        """One grid teacher per rung whose students need a teacher's table."""
        if not any(METHODS[m].needs_table for w in self.worlds for m in methods_for(w) if m in self.methods):
            return {}  # e.g. grid-only distillers in a MuJoCo-only suite: no teacher would be used
        return {spec.name: TeacherConfig(task=spec.name, max_steps=self.teacher_max_steps,
                                         layout_seed=self.teacher_layout_seed, n_envs=self.teacher_n_envs,
                                         hyperparameters=dict(self.teacher_hyperparameters), engine=self.engine)
                for spec in self.rungs()}

    def student_configs(self, teacher_root) -> list[StudentConfig]:
        """Every student run; a distilled student reads its rung's teacher's table from
        under ``teacher_root`` (where ``suite_runner.transfer`` trains it first)."""
        check_methods(self.methods)
        self._check_rung_seeds()
        teachers = self.teachers()
        out = []
        for spec in self.rungs():
            for world in self.worlds:
                for method in [m for m in methods_for(world) if m in self.methods]:
                    table = None
                    if METHODS[method].needs_table:
                        table = str((Path(teacher_root) / teachers[spec.name].run_name() / "table.npz").resolve())
                    out += [self.student_config(spec, world, method, seed, table)
                            for seed in range(self.seeds_for(spec, world))]
        if not out:
            raise ValueError(f"no method of {', '.join(self.methods)} runs in the worlds {', '.join(self.worlds)} "
                             f"({'; '.join(f'{w}: ' + ', '.join(methods_for(w)) for w in self.worlds)})")
        return out

    def student_config(self, spec: TaskSpec, world: str, method: str, seed: int = 0,
                       table: str | None = None) -> StudentConfig:
        """One student run of the suite: its budget, evaluations, world settings and
        learner settings (``table``: a teacher's, for a method that needs one)."""
        steps = self.budget(spec, world)
        cont = world_kind(world) == CONT
        hyperparameters = {**(self.td3_hyperparameters if cont else self.dqn_hyperparameters),
                           **check_regime(self.regime).settings("td3" if cont else "dqn"),
                           **(self.td3_overrides if cont else self.dqn_overrides)}
        return StudentConfig(
            task=spec.name, method=method, world=world, seed=seed, steps=steps, table=table,
            eval_every=self.eval_interval(steps, world), eval_episodes=self.eval_episodes,
            hyperparameters=hyperparameters, layout_seed=None if cont else self.grid_layout_seed,
            # each continuous world its own keywords (MuJoCo's frame_skip, the board's size)
            world_kwargs=dict(self.cont_world_kwargs if world == CONT else
                              self.kinematic_world_kwargs if world == KINEMATIC else {}),
            n_envs=self.n_envs(world),
            # hidden from distilled students where the suite says so, but for those whose
            # counterfactual replay relabels it (crm-edges)
            automaton_state=None if self.students_see_automaton or not METHODS[method].distill
            or METHODS[method].crm else False, engine=self.engine)


def seeds_text(seeds: int, rung_seeds: dict, worlds=None, tasks=None) -> str:
    """``10 seeds a cell, 20 on KeySwordDragon, ToolHome in the grid worlds``: a suite's seeds
    (as defined, or as a ``suite.json`` recorded them), as a page says them; ``worlds`` and
    ``tasks``, where given, limit the rungs named to those that ran."""
    kinds = None if worlds is None else {world_kind(w) for w in worlds}
    more = []
    for kind, by in rung_seeds.items():
        by = {r: n for r, n in by.items() if tasks is None or r in tasks}
        if kinds is not None and kind not in kinds:
            continue
        for n in sorted(set(by.values())):
            where = "the grid worlds" if kind == "Grid" else f"{kind} worlds"
            more.append(f"{n} on {', '.join(r for r, m in by.items() if m == n)} in {where}")
    return f"{seeds} seed{'s' if seeds > 1 else ''} a cell" + "".join(f", {m}" for m in more)


# The collection regimes measured to learn most per wall-clock second on two cores
# (experiments/collection-regime): TD3 collects from 10 envs per gradient update (as the
# authors collected too), with batch 256, lr 1e-3, a [64, 64] network, uniform replay and a
# persistent exploration noise; DQN from 4 envs with 2 updates per step (one update per two
# transitions) and its target network updated every 100 updates.
TD3_REGIME = dict(td3_n_envs=10, td3_hyperparameters={
    "batch_size": 256, "learning_rate": 1e-3, "policy_kwargs": {"net_arch": [64, 64]}, "prioritized": False,
    "action_noise": {"type": "persistent", "sigma": 0.6, "resample": 0.1}})
DQN_REGIME = dict(dqn_n_envs=4, dqn_hyperparameters={"gradient_steps": 2, "target_update_interval": 200})

# The paper's authors' protocol, as their code ran it (the paper leaves most of it unsaid):
# a new layout every episode for teachers and students; 10 envs per gradient step; DQN with
# a constant epsilon of 0.1, a hard target update every 1,000 gradient steps, the squared TD
# error, importance exponent 0.9, lr 1e-3 and a residual CNN over the grid planes; TD3 with
# constant N(0, 0.2) exploration, actor delay 2 throughout, lr 3e-4, 800-600 networks and no
# importance weights; distilled students without the automaton state in their input.
# docs/decisions.md lists what CraftSuite still does otherwise.
AUTHORS_DQN = {"learning_rate": 1e-3, "buffer_size": 150_000, "batch_size": 64, "learning_starts": 1_000,
               "exploration_initial_eps": 0.1, "exploration_final_eps": 0.1, "target_update_interval": 1_000,
               "target_update_unit": "gradient_steps", "loss": "mse", "features_extractor": "residual-cnn",
               "replay_buffer_kwargs": {"beta": 0.9}}
AUTHORS_TD3 = {"learning_rate": 3e-4, "batch_size": 64, "tau": 0.005, "target_policy_noise": 0.2,
               "target_noise_clip": 0.5, "action_noise": {"type": "normal", "sigma": 0.2}, "policy_delay": 2,
               "policy_kwargs": {"net_arch": [800, 600]}, "replay_buffer_kwargs": {"beta": 0.0}}
PAPER_PROTOCOL = dict(teacher_layout_seed=None, teacher_n_envs=10, teacher_hyperparameters=AUTHORS_DQN,
                      grid_layout_seed=None, dqn_n_envs=10, dqn_hyperparameters=AUTHORS_DQN,
                      td3_n_envs=10, td3_hyperparameters=AUTHORS_TD3, students_see_automaton=False)

# The methods of the paper and its baselines (every row but the transfer method and
# shaping): what the paper suite compares. The transfer method's counterfactual replay holds
# one copy of each step per automaton state, which the 1M-transition TD3 buffer cannot
# afford on Diamond Mine (13 copies of 154 numbers); the transfer suite runs it.
PAPER_METHODS = tuple(name for name, m in METHODS.items() if not (m.crm and m.distill) and not m.shaping)
# the standard and hard suites add the field's shaping baseline (the paper suite keeps the
# paper's methods)
SUITE_METHODS = PAPER_METHODS + tuple(name for name, m in METHODS.items() if m.shaping)
TRANSFER_METHODS = ("dqn", "dynamic", "crm-edges", "td3", "td3-dynamic", "td3-crm-edges")

# Budgets, in transitions. TD3 students on the easy and medium rungs get enough to pass the
# collapse that follows their first success (greedy success falls for 30-80k transitions
# before it settles: experiments/collection-regime, "Stability"), so that the last
# evaluation reads what was learned. The middle rungs (tagged ``middle``) each get the
# budget at which TD3 from scratch (MuJoCo) or DQN from scratch (Grid10), in the suite's
# learner regime, lands between 20% and 80% greedy success (experiments/learner-regime, plan
# part 2): where methods can differ. The paper's tasks get 1M transitions per run in MuJoCo, in
# their own suite; on Grid10, where DQN learns some of them in a few tens of thousands, the first of
# 50k/100k/200k/500k at which DQN from scratch does (experiments/suite-campaign, its plan's item 5),
# 1M for a task whose candidates have not run or none of which learns it.
SUITES = {s.name: s for s in (
    Suite("quick", "the calibration rung and the two-stage rung in MuJoCo: TD3 from scratch and distilled "
          "(about 12 minutes on 2 cores)",
          tasks=("Reach", "FirstTool"), worlds=("Cont",), methods=("td3", "td3-dynamic-edges"), seeds=2,
          budgets={"Cont": {"easy": 200_000, "medium": 800_000}}, archived=False, **TD3_REGIME),
    Suite("standard", "the easy, medium and middle rungs x the paper's methods and baselines, Grid10 and MuJoCo, "
          "10 seeds (20 on Grid10's middle rungs), in the n-step-wide learner regime (on 2 cores many hours: run it "
          "in parts, with --worlds, --tasks or --methods; the paper's tasks are the hard suite)",
          tags=("easy", "medium"), worlds=("Grid10", "Cont"), methods=SUITE_METHODS, seeds=10,
          rung_seeds={"Grid": {"KeySwordDragon": 20, "ToolHome": 20, "TwoToolsHome": 20}},
          budgets={"Cont": {"easy": 250_000, "medium": 800_000, "KeySwordDragon": 100_000, "ToolHome": 250_000,
                            "TwoToolsHome": 300_000},
                   "Grid": {"easy": 30_000, "medium": 150_000, "KeySwordDragon": 10_000, "ToolHome": 15_000,
                            "TwoToolsHome": 15_000}},
          regime="n-step-wide", **TD3_REGIME, **DQN_REGIME),
    Suite("hard", "the paper's tasks x the paper's methods and baselines at 1M transitions per run in MuJoCo and "
          "on Grid10 at the first budget at which DQN from scratch learns the task (1M until measured), 10 seeds, "
          "in the n-step-wide learner regime (on 2 cores well over a day: run it in parts, with --worlds, --tasks "
          "or --methods, on any machines; the results archive gathers them)",
          tags=("hard",), worlds=("Grid10", "Cont"), methods=SUITE_METHODS, seeds=10,
          budgets={"Cont": {"hard": 1_000_000},
                   "Grid": {"hard": 1_000_000, "DungeonQuest": 50_000, "BlindCraftsman": 50_000,
                            "BlindCraftsmanObstacles": 50_000, "GoldMine": 100_000}},
          regime="n-step-wide", **TD3_REGIME, **DQN_REGIME),
    Suite("paper", "the paper's protocol as the authors' code ran it: the paper's methods and baselines on its tasks "
          "in the grid, MuJoCo and kinematic worlds, 20 seeds, 2M steps of 10 envs (20M transitions) per run",
          tags=("paper",), worlds=("Grid10", "Cont", "Kinematic"), methods=PAPER_METHODS, seeds=20,
          student_steps=20_000_000, eval_every=500_000, teacher_max_steps=20_000_000, **PAPER_PROTOCOL),
    # the transfer target (a distilled student at 80% greedy success in at most half the
    # transitions its algorithm needs from scratch) on the paper's three tasks: scratch, the
    # paper's method and the transfer method, in the standard suite's collection regimes, with
    # a 200k-transition replay (see PAPER_METHODS) for every TD3 method alike (a DQN's replay
    # holds its whole budget, 100k here)
    Suite("transfer", "the paper's three tasks: scratch, the paper's method and the transfer method (crm-edges), "
          "Grid10 and MuJoCo, 5 seeds",
          tasks=("BlindCraftsman", "DungeonQuest", "DiamondMine"), worlds=("Grid10", "Cont"),
          methods=TRANSFER_METHODS, seeds=5, budgets={"Cont": {"hard": 600_000}, "Grid": {"hard": 100_000}},
          td3_n_envs=TD3_REGIME["td3_n_envs"], td3_hyperparameters={**TD3_REGIME["td3_hyperparameters"],
                                                                    "buffer_size": 200_000},
          **DQN_REGIME),
)}


def suite_named(name: str) -> Suite:
    """The suite called ``name``.

    Raises:
        UnknownName: no such suite (a KeyError and a ValueError), naming the suites.
    """
    return look_up(SUITES, name, "suite")
