"""The configurations of teacher and student runs, as dataclasses: what the command line
fills in, what a run directory records (``config.json``) and hashes into its run key.

Kept apart from ``training`` (which imports torch and stable-baselines3) so that building,
reading or listing configs stays cheap, e.g. in the suites' driver process and the
leaderboard.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from pathlib import Path

from .ids import env_id, grid_id, grid_world, world_kind
from .envs.grid import layout_kwargs
from .hyperparameters import algorithm_settings
from .methods import METHODS, check_methods, methods_for
from .runs import config_key
from .task_registry import resolve_task


ENGINES = ("sb3", "population")
DEFAULT_ENGINE = "population"  # what trains a run that names no engine: configs, the command line, suites
# A record without an ``engine`` was an SB3 run (made before the field existed): its key
# leaves "sb3" out, and reading it back gives "sb3" (``runs.config_from``).
ENGINE_FIELD = {"omit_if": "sb3"}


@dataclass(frozen=True)
class TeacherConfig:
    task: str = "BlindCraftsman"
    size: int = 7
    layout_seed: int | None = 0  # one fixed grid instance, as in the paper (None: a new one per episode)
    seed: int = 0
    max_steps: int = 300_000
    target_success: float = 0.9
    eval_every: int = 5_000
    eval_episodes: int = 50
    hyperparameters: dict = field(default_factory=dict)  # overrides of DQN_DEFAULTS
    # envs stepped side by side: each agent step collects n_envs transitions (the authors' 10)
    n_envs: int = field(default=1, metadata={"omit_if_default": True})
    # what trains it (as StudentConfig's engine): a part of the run key
    engine: str = field(default=DEFAULT_ENGINE, metadata=ENGINE_FIELD)

    # A teacher is a product-DQN run on its grid that stops at a greedy-success target: what
    # a trainer reads of a student's config, it reads of a teacher's under the same names.
    method = "product-dqn"
    product = True
    table = None
    automaton_state = None

    def __post_init__(self):
        _check_n_envs(self.n_envs)
        _check_engine(self.engine)
        layout_kwargs(self.layout_seed)  # a ValueError for a bad seed

    @property
    def steps(self) -> int:
        return self.max_steps

    @property
    def world(self) -> str:
        return grid_world(self.size)

    @property
    def env_id(self) -> str:
        return grid_id(self.task, self.size)

    @property
    def env_kwargs(self) -> dict:
        return layout_kwargs(self.layout_seed)

    def effective(self) -> dict:
        """The settings the teacher trains with beyond its fields: DQN's defaults merged with
        ``hyperparameters``, its method's row and its world (recorded and hashed)."""
        return _effective("product-dqn", self.hyperparameters, self.env_id, self.env_kwargs, self.task)

    def run_name(self) -> str:
        return f"teacher-{self.task}-{grid_world(self.size)}-s{self.seed}-{config_key(self)}"


@dataclass(frozen=True)
class StudentConfig:
    task: str = "BlindCraftsman"
    method: str = "td3-dynamic"
    world: str = "Cont"  # "Cont" (MuJoCo) or "Grid10" / "Grid7"
    seed: int = 0
    steps: int = 20_000  # the budget in transitions (env steps over all n_envs envs)
    table: str | None = None  # a teacher's table.npz (the methods that distil one: Method.needs_table)
    eval_every: int = 2_000
    eval_episodes: int = 10
    hyperparameters: dict = field(default_factory=dict)
    layout_seed: int | None = None  # grid worlds: one fixed instance (None: a new one per episode)
    # more gymnasium.make keywords for the student's world, e.g. {"frame_skip": 2, "max_episode_steps": 1000}
    world_kwargs: dict = field(default_factory=dict, metadata={"omit_if_default": True})
    # envs stepped side by side: each agent step collects n_envs transitions, then takes
    # the algorithm's gradient_steps updates (the authors' students used 10)
    n_envs: int = field(default=1, metadata={"omit_if_default": True})
    # whether the policy sees the automaton state (None: as its method's row says); only a
    # distilled student may differ from its row (the paper's authors' students did not see it)
    automaton_state: bool | None = field(default=None, metadata={"omit_if_default": True})
    # what trains it: "population" (the seeds of a cell in one process: craftsuite.population);
    # "sb3" (one SB3 agent per run) names the runs SB3 trained before, which are reused, not
    # trained; a part of the run key, since the two were equal in their update but not in
    # their random streams
    engine: str = field(default=DEFAULT_ENGINE, metadata=ENGINE_FIELD)

    def __post_init__(self):
        _check_n_envs(self.n_envs)
        _check_engine(self.engine)
        kind = world_kind(self.world)  # a ValueError naming the worlds there are
        if self.method in METHODS:  # an unknown method is named where it is used (check_methods)
            row = METHODS[self.method]
            if row.world != kind:  # DQN needs discrete moves, TD3 continuous thrust
                worlds = "e.g. Grid10" if row.world == "Grid" else "Cont or Kinematic"
                raise ValueError(f"method {self.method!r} runs in the {row.world} worlds, not in {self.world}; "
                                 f"give a {row.world} world ({worlds}), or one of {self.world}'s methods: "
                                 f"{methods_for(self.world)}")
            row.observes(self.automaton_state)  # a MethodError naming both
            if self.automaton_state == row.product:  # what the method does anyway: one run key
                object.__setattr__(self, "automaton_state", None)
        if layout_kwargs(self.layout_seed) and world_kind(self.world) != "Grid":  # also checks the seed
            raise ValueError(f"layout_seed fixes a grid instance; the {self.world} world has none "
                             "(its objects are placed anew every episode)")
        if not isinstance(self.world_kwargs, dict):
            raise ValueError(f"world_kwargs must be a dict of gymnasium.make keywords, got {self.world_kwargs!r}")
        owned = sorted({"product", "layout_seed"} & set(self.world_kwargs))
        if owned:
            raise ValueError(f"world_kwargs may not set {', '.join(owned)}: the method sets product, layout_seed its "
                             "own field")

    @property
    def env_id(self) -> str:
        return env_id(self.task, self.world)

    @property
    def product(self) -> bool:
        """Whether the student sees the automaton state (``Method.observes``)."""
        return METHODS[self.method].observes(self.automaton_state)

    @property
    def env_kwargs(self) -> dict:
        return {**layout_kwargs(self.layout_seed), **self.world_kwargs}

    def effective(self) -> dict:
        """The settings the student trains with beyond its fields: its algorithm's defaults
        merged with ``hyperparameters`` (the replay buffer no larger than the budget), its
        method's row and its world (recorded and hashed)."""
        out = _effective(self.method, {"buffer_size": min(self.steps, 1_000_000), **self.hyperparameters},
                         self.env_id, self.env_kwargs, self.task)
        out["method"]["product"] = self.product
        if self.table is not None:  # the teacher, by its run's name (its settings' hash), not by where it lies
            out["teacher"] = f"{Path(self.table).parent.name}/{Path(self.table).name}"
        return out

    def run_name(self) -> str:
        return f"student-{self.task}-{self.world}-{self.method}-s{self.seed}-{config_key(self)}"

    def cell(self) -> dict:
        """Every field but the seed: what the seeds of one suite cell share (a population)."""
        return {k: v for k, v in asdict(self).items() if k != "seed"}


def _check_engine(engine) -> None:
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {', '.join(ENGINES)}, got {engine!r}")


def _check_n_envs(n_envs) -> None:
    if not isinstance(n_envs, int) or isinstance(n_envs, bool) or n_envs < 1:
        raise ValueError(f"n_envs must be a positive integer, got {n_envs!r}")


def _effective(method: str, hyperparameters: dict, env_id: str, env_kwargs: dict, task: str) -> dict:
    check_methods([method])
    row = METHODS[method]
    return {"method": row.settings(), "hyperparameters": algorithm_settings(row.algorithm, hyperparameters),
            "world": {"id": env_id, "kwargs": env_kwargs, "rules": resolve_task(task).digest()}}


def student_result(config: StudentConfig, algorithm: str, steps: int, updates: int,
                   seconds: tuple[float, float | None], **more) -> dict:
    """A finished student's ``result.json``, whichever engine trained it (``more``: what
    that engine adds, e.g. the population's size); ``seconds``: see ``_timing``."""
    return {"kind": "student", "env_id": config.env_id, "method": config.method, "algorithm": algorithm,
            "task": config.task, "seed": config.seed, "steps": int(steps), "updates": int(updates),
            "product": config.product, "env_kwargs": config.env_kwargs, "model": "model.zip",
            **more, **_timing(seconds)}


def teacher_result(config: TeacherConfig, algorithm: str, steps: int, updates: int, success: float,
                   seconds: tuple[float, float | None], **more) -> dict:
    """A finished teacher's ``result.json``, whichever engine trained it: its last greedy
    ``success`` and whether that reached its target, beside its model and table."""
    return {"kind": "teacher", "env_id": config.env_id, "algorithm": algorithm, "steps": int(steps),
            "updates": int(updates), "success": success, "reached_target": success >= config.target_success,
            **more, **_timing(seconds), "table": "table.npz", "model": "teacher.zip"}


def _timing(seconds: tuple[float, float | None]) -> dict:
    """A result's training time: the wall time of the session that finished it (its
    population's), the run's share of every session's since step 0 (each session's wall time
    divided among its population's members; absent where an earlier session's is not known)
    and the machine it finished on."""
    from .provenance import machine

    this, share = seconds
    return {"seconds_this_session": round(this, 1),
            **({} if share is None else {"seconds_share": round(share, 1)}), "machine": machine()}
