"""CRM's memory: the resident size of a CRM student run on Diamond Mine's 10x10 grid.

Usage: python benchmarks/crm_memory.py [--steps 100000] [--page PATH | --no-page]

Diamond Mine's automaton has 13 live states, and SB3's CRM buffer (``agents.crm``, whose storing of them went
with the SB3 trainer) stored every real step once per live state: 7.5 GB was measured for a 100k-transition Grid10 run,
and two such runs at once were killed for memory on a 24 GiB machine. The population
engine stores each step once and makes the counterfactuals when a batch is sampled
(``population.replay``). Each row trains one run (``crm``, the standard suite's DQN
regime, a replay of the whole budget) in a fresh process and reads its peak resident set
(``ru_maxrss``); a population of 5 seeds is shown per member too.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile

from _page import Report, add_page_argument

TARGET_GB = 1.5
_CHILD = """
import json, resource, sys, time
import craftsuite
from craftsuite.configs import StudentConfig
from craftsuite.population import train_population
from craftsuite.suites import DQN_REGIME
steps, members, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
configs = [StudentConfig(task="DiamondMine", method="crm", world="Grid10", seed=s, steps=steps, eval_every=steps,
                         eval_episodes=5, hyperparameters=DQN_REGIME["dqn_hyperparameters"], layout_seed=1,
                         n_envs=DQN_REGIME["dqn_n_envs"], engine="population") for s in range(members)]
start = time.perf_counter()
train_population(configs, out, progress=False)
print(json.dumps({"rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20,
                  "seconds": time.perf_counter() - start}))
"""


def peak(steps: int, members: int) -> dict:
    with tempfile.TemporaryDirectory() as out:
        done = subprocess.run([sys.executable, "-c", _CHILD, str(steps), str(members), out], check=True,
                              capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=100_000, help="each run's budget in transitions")
    add_page_argument(parser)
    args = parser.parse_args()
    report = Report()
    report(f"| runs | transitions per run | peak resident GB (per run) | target <= {TARGET_GB} GB per run | "
           "transitions/s | reference |")
    report("|---|---|---|---|---|---|")
    for members in (1, 5):
        got = peak(args.steps, members)
        per_run = got["rss_gb"] / members if members > 1 else got["rss_gb"]
        report(f"| {members} (population) | {args.steps:,} | {got['rss_gb']:.2f} ({per_run:.2f}) | "
               f"{'met' if got['rss_gb'] <= TARGET_GB * members else 'NOT met'} | "
               f"{members * args.steps / got['seconds']:,.0f} | SB3's CRM buffer: 7.5 GB for one run |")
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
