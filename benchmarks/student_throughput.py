"""Student throughput of the population engine: transitions and gradient updates per second per core.

Usage: python benchmarks/student_throughput.py [--seconds 10] [--members 5 10] [--at-once 2] [--only TEXT]
       [--device cpu] [--page PATH | --no-page]

One process, one torch thread with subnormal floats flushed to zero (as the engine trains on
a CPU), Blind Craftsman: TD3 in the MuJoCo world and on the kinematic board, DQN on the
10x10 grid. Each row (``craftsuite.population``): the suites' regimes
(``craftsuite.suites.TD3_REGIME`` / ``DQN_REGIME``: several envs per update, small networks)
for ``--members`` seeds in one process (5: a suite's cell; 10: as many as the engines were
compared with), collecting from one vector env, counted over all members, after the warm-up
of random actions (``learning_starts``). The rows named after the learner regime add the
standard and hard suites' regime (``craftsuite.regimes``: n-step targets, wider networks) to
those settings: what the suites train now. Each row trains for about ``--seconds``. The
reference column is each row's target. On CPU the learner-regime rows are also measured as
``--at-once`` processes at once (default 2, a campaign's process per core here, or the
machine's cores if fewer), each a fresh process, timed over the same window after every
one's warm-up: the rate of each process while the others run, which is what a campaign on
these cores gets (processes can slow one another through shared caches and memory, by an
amount that differs between machines). Under the table, the standard and hard suites'
student time projected from those rates at the suite's seeds per population (or the nearest
population size measured), from a whole run on CPU only. Those rates are a run's first
minutes, and a long run trains slower, so the projection is the least time a suite takes:
on an Intel Xeon, with subnormals flushed, the campaign's TD3 populations averaged
1,200-1,700 transitions/s a core over calls of 40-85 minutes (five-minute windows of
1,150-1,900/s, with no steady fall; the suite campaign's parts 52-55,
experiments/suite-campaign), slower than this benchmark's TD3 rows there; before the flush a
long run there fell to about half within an hour (experiments/flush-denormal). With
``--device cuda --members 20`` it measures a GPU population; ``--only n-step-wide`` keeps the
rows whose label holds that text.
"""

from __future__ import annotations

import argparse
import contextlib
import multiprocessing
import os
import queue
import time

import craftsuite  # noqa: F401
from craftsuite.hyperparameters import algorithm_settings
from craftsuite.regimes import REGIMES
from craftsuite.suites import DQN_REGIME, SUITES, TD3_REGIME
from _page import Report, add_page_argument  # benchmarks/ is on sys.path as a script

CONT, GRID = "CraftSuite/BlindCraftsman-Cont-v0", "CraftSuite/BlindCraftsman-Grid10-v0"
KINEMATIC = "CraftSuite/BlindCraftsman-Kinematic-v0"
TD3_N, DQN_N = TD3_REGIME["td3_n_envs"], DQN_REGIME["dqn_n_envs"]
TD3_SET, DQN_SET = TD3_REGIME["td3_hyperparameters"], DQN_REGIME["dqn_hyperparameters"]
POPULATION_ROWS = [  # (label, method, env id, n_envs, settings, env keywords, target transitions/s)
    ("TD3, MuJoCo, suites' regime", "td3", CONT, TD3_N, TD3_SET, {}, ">= 5,000"),
    ("TD3, kinematic, suites' regime", "td3", KINEMATIC, TD3_N, TD3_SET, {}, ">= 8,000"),
    ("DQN, Grid10, suites' regime", "dqn", GRID, DQN_N, DQN_SET, {"layout_seed": 1}, ">= 5,000"),
    ("CRM (DQN), Grid10, suites' regime", "crm", GRID, DQN_N, DQN_SET, {"layout_seed": 1}, ""),
]
# the learner regime the standard and hard suites train in, over their collection regime
LEARNER = SUITES["standard"].regime
assert SUITES["hard"].regime == LEARNER, "the projection assumes one learner regime for both suites"
TD3_WIDE = {**TD3_SET, **REGIMES[LEARNER].settings("td3")}
DQN_WIDE = {**DQN_SET, **REGIMES[LEARNER].settings("dqn")}
LEARNER_ROWS = [
    (f"TD3, MuJoCo, {LEARNER}", "td3", CONT, TD3_N, TD3_WIDE, {}, ""),
    (f"DQN, Grid10, {LEARNER}", "dqn", GRID, DQN_N, DQN_WIDE, {"layout_seed": 1}, ""),
    (f"CRM (DQN), Grid10, {LEARNER}", "crm", GRID, DQN_N, DQN_WIDE, {"layout_seed": 1}, ""),
]


def measure_population(method, env_id, n_envs, settings, env_kwargs, members: int, seconds: float,
                       device: str = "cpu", ready=None) -> tuple[float, float]:
    """The engine's hot path (``population.train._loop`` without its logs): act, step the
    vector env, store, learn. ``ready`` (if given) is called between the warm-up and the timed
    window: processes measured together wait there for one another."""
    from craftsuite.ids import parse_id, world_kind
    from craftsuite.methods import METHODS
    from craftsuite.population import Population
    from craftsuite.population.engine import sparse_width
    from craftsuite.population.envs import make_envs
    from craftsuite.population.train import cpu_settings
    from craftsuite.task_registry import resolve_task

    spec = resolve_task("BlindCraftsman")
    product = METHODS[method].product
    # as the engine trains on the CPU: one thread, subnormals flushed
    with cpu_settings() if device == "cpu" else contextlib.nullcontext():
        envs = make_envs(env_id, members * n_envs, env_kwargs, product)
        try:
            algorithm = algorithm_settings(METHODS[method].algorithm, {**settings, "buffer_size": 200_000})
            pop = Population(method, algorithm, list(range(members)), n_envs, envs.single_observation_space.shape[0],
                             envs.single_action_space, spec.automaton, spec.completion_reward, 10**7, device=device,
                             sparse_width=sparse_width(spec, world_kind(parse_id(env_id)[1]), product))
            return _timed(pop, envs, seconds, ready)
        finally:
            envs.close()


def _timed(pop, envs, seconds: float, ready) -> tuple[float, float]:
    """``pop`` acting, stepping ``envs`` and learning: its warm-up, then about ``seconds`` timed;
    transitions and updates per second, over all its members."""
    obs, _ = envs.reset(seed=list(range(envs.num_envs)))
    while pop.num_timesteps <= pop.learning_starts + 1_000:  # the warm-up, then some learning
        obs = pop.step(envs, obs)[0]
        pop.train()
    if ready is not None:
        ready()
    transitions, updates, start = pop.num_timesteps, pop.learner.n_updates, time.perf_counter()
    while time.perf_counter() - start < seconds:
        for _ in range(50):
            obs = pop.step(envs, obs)[0]
            pop.train()
    total = time.perf_counter() - start
    return pop.K * (pop.num_timesteps - transitions) / total, pop.K * (pop.learner.n_updates - updates) / total


def _measure_in_process(row: tuple, members: int, seconds: float, start, results) -> None:
    results.put(measure_population(*row, members, seconds, "cpu", ready=start.wait))


def measure_at_once(row: tuple, members: int, seconds: float, processes: int) -> list[float]:
    """Transitions/s of each of ``processes`` processes on CPU training the same population at
    once (``row``: method, env id, n_envs, settings, env keywords), timed together once all have
    warmed up; fresh processes, so none inherits this one's state.

    Raises:
        RuntimeError: a process that died (its traceback is printed above), after the others
            are stopped.
    """
    context = multiprocessing.get_context("spawn")
    start, results = context.Barrier(processes), context.Queue()
    workers = [context.Process(target=_measure_in_process, args=(row, members, seconds, start, results))
               for _ in range(processes)]
    for worker in workers:
        worker.start()
    rates = []
    try:
        while len(rates) < processes:
            try:
                rates.append(results.get(timeout=1)[0])
            except queue.Empty:
                dead = [w.exitcode for w in workers if w.exitcode not in (None, 0)]
                if dead:  # the others would wait at the barrier for it forever
                    start.abort()
                    raise RuntimeError(f"a process measuring {row[0]} in {row[1]} with {processes} at once died "
                                       f"(exit code {dead[0]}; its traceback is above)") from None
    finally:
        for worker in workers:
            worker.join(timeout=60)
            if worker.is_alive():
                worker.terminate()
                worker.join()
    return sorted(rates)


def _kind(method: str, env_id: str) -> tuple[str, bool]:
    """What sets a student's speed here: its world (MuJoCo, kinematic, grid) and whether it replays
    counterfactuals."""
    from craftsuite.ids import parse_id
    from craftsuite.methods import METHODS

    return parse_id(env_id)[1].rstrip("0123456789"), METHODS[method].crm


def suite_projection(name: str, rates: dict, cores: int) -> str:
    """The suite's student transitions over the learner-regime rates just measured (``rates``:
    each process's transitions/s with ``cores`` processes at once, by population size, then by
    world kind and CRM), at the population size nearest the suite's seeds, on ``cores`` cores:
    a projection (teachers, evaluations and the tail of the last runs left out)."""
    from craftsuite.ids import parse_id
    from craftsuite.methods import METHODS
    from craftsuite.task_registry import resolve_task

    suite = SUITES[name]
    configs = suite.student_configs("teachers")
    seconds, used = 0.0, set()
    for c in configs:
        # each cell's seeds are one population: the measured size nearest them
        seeds = suite.seeds_for(resolve_task(c.task), c.world)
        members = min(rates, key=lambda m: (abs(m - seeds), -m))
        used.add(members)
        kind = (parse_id(c.env_id)[1].rstrip("0123456789"), METHODS[c.method].crm)
        seconds += c.steps / rates[members].get(kind, rates[members].get((kind[0], False), float("nan")))
    total = sum(c.steps for c in configs)
    rate = f"at each process's rate with {cores} at once" if cores > 1 else "at the rate of one process alone"
    return (f"The `{name}` suite's students ({len(configs)} runs, {total:,} transitions, {suite.regime} regime) "
            f"at these rates on {cores} core{'s' if cores > 1 else ''}: {seconds / cores / 3600:.1f} h "
            f"({suite.seeds_text()}, each cell a population, projected from the populations of "
            f"{' and '.join(map(str, sorted(used)))}, {rate}; "
            "teachers and evaluations not counted).")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--members", type=int, nargs="+", default=[5, 10],
                        help="population sizes (default: 5, a suite cell's seeds, and 10)")
    parser.add_argument("--at-once", type=int, metavar="N",
                        help="on CPU, also measure the learner-regime rows as N processes at once, and project the "
                             "suites on N cores from those rates (default: 2, this project's cores, or the machine's "
                             "if fewer; 1: alone only)")
    parser.add_argument("--device", default="cpu", help="the population's torch device (default: cpu)")
    parser.add_argument("--only", metavar="TEXT", help="only the rows whose label holds TEXT (e.g. n-step-wide)")
    add_page_argument(parser)
    args = parser.parse_args()
    rows = [row for row in POPULATION_ROWS + LEARNER_ROWS if args.only is None or args.only in row[0]]
    if not rows:
        parser.error(f"--only {args.only!r}: no row's label holds it; the labels: "
                     + "; ".join(row[0] for row in POPULATION_ROWS + LEARNER_ROWS))
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    if args.at_once is None:
        args.at_once = min(2, cores) if args.device == "cpu" else 1
    if args.at_once < 1:
        parser.error(f"--at-once {args.at_once}: give a number of processes, 1 or more (1 measures each row alone)")
    if args.at_once > 1 and args.device != "cpu":
        parser.error(f"--at-once {args.at_once} with --device {args.device}: processes at once are measured on CPU "
                     "cores only; give --at-once 1 or --device cpu")
    if args.at_once > cores:
        parser.error(f"--at-once {args.at_once}: this process may use {cores} cores, and processes sharing a core "
                     "would measure the sharing; give at most that many")
    if args.only is not None and not args.no_page:  # a part of the table would replace the whole section
        parser.error("--only measures some rows, and the page's section holds them all: add --no-page")
    import torch

    torch.set_num_threads(1)
    report = Report()
    at_once = args.at_once
    together = f" transitions/s of each of {at_once} at once |" if at_once > 1 else ""
    report(f"| student | engine | transitions/s | updates/s (all members) |{together} reference transitions/s |")
    report("|---|---|---|---|" + ("---|" if at_once > 1 else "") + "---|")
    # the projection's rates: each process's transitions/s with the others at once (alone where
    # at_once is 1), of the learner-regime rows, by members, then (world kind, crm)
    rates = {}
    for label, method, env_id, n_envs, settings, env_kwargs, target in rows:
        for members in args.members:
            row = (method, env_id, n_envs, settings, env_kwargs)
            tps, ups = measure_population(*row, members, args.seconds, args.device)
            together = ""  # the at-once column's cell: only the learner-regime rows are measured at once
            if settings in (TD3_WIDE, DQN_WIDE):
                each = measure_at_once(row, members, args.seconds, at_once) if at_once > 1 else [tps]
                rates.setdefault(members, {})[_kind(method, env_id)] = sum(each) / len(each)
                together = ", ".join(f"{r:,.0f}" for r in each) if at_once > 1 else ""
            column = f" {together} |" if at_once > 1 else ""
            report(f"| {label} | population of {members} ({args.device}) | {tps:,.0f} | {ups:,.0f} |{column} "
                   f"{target} |")
    report("")
    # the projection needs every learner-regime row, measured on CPU
    for suite in ("standard", "hard") if args.only is None and args.device == "cpu" else ():
        report(suite_projection(suite, rates, at_once))
        report("")
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
