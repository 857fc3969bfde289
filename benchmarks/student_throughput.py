"""Student throughput: transitions and gradient updates per second, per collection regime.

Usage: python benchmarks/student_throughput.py [--seconds 10] [--page PATH | --no-page]

One process, one torch thread, Blind Craftsman, TD3 in the MuJoCo world and DQN on the
10x10 grid: the package's defaults (one env, one update per transition; TD3 [400, 300])
and the suites' regimes (``craftsuite.suites.TD3_REGIME`` / ``DQN_REGIME``: several envs
per update, small networks), each with SB3's default Adam and with the fused Adam that
``make_agent`` uses. Each row trains for about ``--seconds`` after 2,000 warm-up
transitions. The reference column is what was measured for plain SB3 TD3 [400, 300] here
before: about 85 transitions/s with one env, about 1,400 with 10 envs per gradient step.
"""

from __future__ import annotations

import argparse
import time

import craftsuite  # noqa: F401
from craftsuite.agents.methods import make_agent
from craftsuite.suites import DQN_REGIME, TD3_REGIME
from _page import Report, add_page_argument  # benchmarks/ is on sys.path as a script

CONT, GRID = "CraftSuite/BlindCraftsman-Cont-v0", "CraftSuite/BlindCraftsman-Grid10-v0"
ROWS = [  # (label, method, env id, n_envs, algorithm settings, reference transitions/s)
    ("TD3, package defaults (1 env, [400, 300], batch 64)", "td3", CONT, 1, {}, "~85 (SB3 TD3, 1 env)"),
    ("TD3, suites' regime (10 envs, [64, 64], batch 256)", "td3", CONT, TD3_REGIME["td3_n_envs"],
     TD3_REGIME["td3_hyperparameters"], "~1,400 (SB3 TD3 [400, 300], 10 envs)"),
    ("DQN, package defaults (1 env, [64, 64])", "dqn", GRID, 1, {"env_kwargs": {"layout_seed": 1}}, ""),
    ("DQN, suites' regime (4 envs, 2 updates per step)", "dqn", GRID, DQN_REGIME["dqn_n_envs"],
     {**DQN_REGIME["dqn_hyperparameters"], "env_kwargs": {"layout_seed": 1}}, ""),
]


def measure(method, env_id, n_envs, settings, fused: bool, seconds: float) -> tuple[float, float]:
    settings = dict(settings)
    policy_kwargs = dict(settings.pop("policy_kwargs", {}))
    policy_kwargs["optimizer_kwargs"] = {"fused": fused}
    agent = make_agent(method, env_id, n_envs=n_envs, buffer_size=200_000, policy_kwargs=policy_kwargs, **settings)
    agent.learn(2_000)
    steps, total = 1_000 * n_envs, 0.0
    transitions, updates = agent.num_timesteps, agent._n_updates
    while total < seconds:
        start = time.perf_counter()
        agent.learn(steps, reset_num_timesteps=False)
        total += time.perf_counter() - start
    return (agent.num_timesteps - transitions) / total, (agent._n_updates - updates) / total


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    add_page_argument(parser)
    args = parser.parse_args()
    import torch

    torch.set_num_threads(1)
    report = Report()
    report("| student | Adam | transitions/s | updates/s | reference transitions/s |")
    report("|---|---|---|---|---|")
    for label, method, env_id, n_envs, settings, reference in ROWS:
        for fused in (False, True):
            tps, ups = measure(method, env_id, n_envs, settings, fused, args.seconds)
            report(f"| {label} | {'fused' if fused else 'SB3 default'} | {tps:,.0f} | {ups:,.0f} | {reference} |")
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
