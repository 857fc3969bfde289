"""What the TD3 experiment scripts (td3_horizon.py, td3_exploration.py, td3_reach.py here; nstep.py in
blind-craftsman-500k) share:
a student trained in-process with a report every few thousand steps."""

from __future__ import annotations

import json
import time


EVAL_EPISODES = 10
EVENT = -0.05  # a reward above this is an item or the completion, not the step or wall cost


def train_with_reports(method: str, table: str | None, *, task: str, seed: int, steps: int, every: int,
                       env_kwargs: dict | None = None, **agent_kwargs) -> list[dict]:
    """Train ``method`` on ``CraftSuite/<task>-Cont-v0`` (one torch thread) and, every
    ``every`` steps, print and keep a row: greedy success, return, rewarded events (an
    item or the completion), automaton transitions that change its state (the task's
    progress) and violations per episode over 10 fresh episodes, training episodes, wins
    and violations so far, and rewarded events per training episode since the row before.
    ``agent_kwargs`` go to ``make_agent``."""
    import torch

    torch.set_num_threads(1)
    import craftsuite  # noqa: F401
    from stable_baselines3.common.callbacks import BaseCallback

    from craftsuite.agents import AutomatonQTable
    from craftsuite.agents.factory import make_agent
    from craftsuite.methods import METHODS
    from craftsuite.training import evaluate

    env_id = f"CraftSuite/{task}-Cont-v0"
    table = AutomatonQTable.load(table) if METHODS[method].needs_table else None
    agent = make_agent(method, env_id, table=table, seed=seed, env_kwargs=env_kwargs, **agent_kwargs)
    rows, start = [], time.perf_counter()

    class Report(BaseCallback):
        episodes = wins = violations = window_episodes = window_events = 0

        def _on_step(self) -> bool:
            self.window_events += int((self.locals["rewards"] > EVENT).sum())
            if self.locals["dones"][0]:
                self.episodes += 1
                self.window_episodes += 1
                self.wins += bool(self.locals["infos"][0].get("is_success"))
                self.violations += bool(self.locals["infos"][0].get("violation"))
            if self.num_timesteps % every == 0:
                greedy_events, greedy_edges, greedy_violations = [], [], []

                def count(i, r, info):
                    greedy_events.append(r > EVENT)
                    w, _, w2 = info["automaton_transition"]  # every step's info has one (only reset's is None)
                    greedy_edges.append(w != w2)
                    greedy_violations.append(info["violation"])

                success, ret, _ = evaluate(agent, env_id, EVAL_EPISODES, 10**6, METHODS[method].product, env_kwargs,
                                        on_step=count)
                row = {"method": method, "step": self.num_timesteps, "eval_success": success,
                       "eval_return": round(ret, 1), "eval_events": sum(greedy_events) / EVAL_EPISODES,
                       "eval_edges": sum(greedy_edges) / EVAL_EPISODES,
                       "eval_violations": sum(greedy_violations) / EVAL_EPISODES,
                       "train_episodes": self.episodes, "train_wins": self.wins, "train_violations": self.violations,
                       "events_per_episode": round(self.window_events / max(self.window_episodes, 1), 2),
                       "seconds": round(time.perf_counter() - start)}
                print(json.dumps(row), flush=True)
                rows.append(row)
                self.window_events = self.window_episodes = 0
            return True

    agent.learn(steps, callback=Report())
    return rows


def main(argv=None) -> None:
    """``python _students.py [--task Reach] [--steps 5000] [--seed 0]``: one TD3 student from
    scratch with its reports, to try the helper on its own."""
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--task", default="Reach")
    parser.add_argument("--steps", type=int, default=5_000)
    parser.add_argument("--every", type=int, default=2_500)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    train_with_reports("td3", None, task=args.task, seed=args.seed, steps=args.steps, every=args.every)


if __name__ == "__main__":
    main()
