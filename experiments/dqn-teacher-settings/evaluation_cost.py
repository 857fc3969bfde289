"""What one evaluation costs: 50 episodes of an untrained agent, played side by side.

Usage: python experiments/dqn-teacher-settings/evaluation_cost.py [--episodes 50]

``craftsuite.training.evaluate`` plays all evaluation episodes at once, one batched
forward pass per step; an untrained agent runs every episode to its time limit, so this is
the most an evaluation costs. Product DQN on the 7x7 Blind Craftsman grid and TD3 (the
package's [400, 300]) in its MuJoCo world.
"""

from __future__ import annotations

import argparse
import time

CASES = [("CraftSuite/BlindCraftsman-Grid7-v0", "product-dqn"), ("CraftSuite/BlindCraftsman-Cont-v0", "td3")]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=50)
    args = parser.parse_args(argv)
    import craftsuite  # noqa: F401
    from craftsuite.agents.factory import make_agent
    from craftsuite.methods import METHODS
    from craftsuite.training import evaluate

    for env_id, method in CASES:
        agent = make_agent(method, env_id)
        start = time.perf_counter()
        success, ret, _ = evaluate(agent, env_id, args.episodes, 0, METHODS[method].product)
        print(f"{env_id} ({method}): {time.perf_counter() - start:.2f} s for {args.episodes} episodes "
              f"(success {success:.2f}, return {ret:.1f})")


if __name__ == "__main__":
    main()
