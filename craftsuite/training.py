"""Teachers and students as runs: a config dataclass in, a finished run directory out.

``train_teacher`` trains a product-DQN teacher on a grid until its greedy policy completes
the task on ``target_success`` of fresh-seed evaluation episodes, then distils it into the
automaton (``table.npz``). ``train_student`` trains any method of ``METHODS`` for a fixed
budget. Both train on the population engine (``craftsuite.population``: a population of
one), which holds every learning rule once. A run of the ``sb3`` engine (one SB3 agent per
run, as CraftSuite trained before) is reused when finished; it is not trained any more.
``evaluate`` plays any agent's greedy episodes as a run's evaluation does.
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numpy as np

from .configs import StudentConfig, TeacherConfig
from .runs import RunDir


class Evaluation(NamedTuple):
    success: float  # the share of episodes that completed the task
    mean_return: float
    mean_length: float  # decisions per episode


def evaluate(agent, env_id: str, episodes: int, seed: int, product: bool, env_kwargs: dict | None = None,
             on_step=None) -> Evaluation:
    """Greedy episodes on fresh seeds, played side by side so that the policy sees one
    batch per step (an untrained policy that never finishes costs one batched call per
    decision of the episode limit, not ``episodes`` times as many). ``on_step(episode,
    reward, info)``, if given, sees every step (for measures beyond an ``Evaluation``'s)."""
    from .evaluation import play

    played = play(lambda _: lambda obs: agent.predict(obs, deterministic=True)[0], env_id, env_kwargs or {},
                  product, episodes, seed, on_step)
    returns = np.array([e.total_reward for e in played])
    lengths = np.array([e.length for e in played], dtype=float)
    wins = np.array([e.success for e in played])
    return Evaluation(float(wins.mean()), float(returns.mean()), float(lengths.mean()))


SB3_REFUSED = ("{name}: the sb3 engine no longer trains (finished sb3 runs are reused, and this one is not "
               "finished); train it with --engine population{also}")


def finished_sb3_run(config: StudentConfig | TeacherConfig, root, also: str = "") -> Path:
    """The finished run of an ``sb3``-engine ``config`` under ``root``, reused as it is;
    one that is not finished is refused (nothing is written): the sb3 engine trains no more.
    ``also``: another way out the refusal names after ``--engine population`` (a command
    that reads an archive names it)."""
    path = Path(root) / config.run_name()
    if not (path / "result.json").is_file():
        raise ValueError(SB3_REFUSED.format(name=path.name, also=also))
    with RunDir(path, config) as run:  # a finished run of another configuration is refused by name
        return run.path


def train_teacher(config: TeacherConfig, root, progress: bool = True, device: str = "cpu") -> Path:
    """A teacher run under ``root``; returns its directory (with teacher.zip and table.npz).
    ``device``: the population engine's torch device."""
    if config.engine == "sb3":
        return finished_sb3_run(config, root)
    from .population.teacher import train_teacher as train_population_teacher

    return train_population_teacher(config, root, progress=progress, device=device)


def train_student(config: StudentConfig, root, progress: bool = True, device: str = "cpu") -> Path:
    """A student (or baseline) run under ``root``; returns its directory. ``device``: the
    population engine's torch device."""
    from .methods import check_methods

    check_methods([config.method])
    if config.engine == "sb3":
        return finished_sb3_run(config, root)
    from .population import train_population

    return train_population([config], root, progress=progress, device=device)[0]
