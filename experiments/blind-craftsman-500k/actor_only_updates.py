"""Does the greedy actor merely lag its critic? Actor-only updates on a frozen critic.

Usage: python experiments/blind-craftsman-500k/actor_only_updates.py CHECKPOINT [--updates 10000]
       [--report-at 2000] [--episodes 40]

CHECKPOINT is a TD3 student run's checkpoint directory (``model.zip`` and ``replay.pkl``),
e.g. ``runs/bc-fs10-500k/students/student-BlindCraftsman-Cont-td3-dynamic-s0-*/checkpoint``.
The actor takes ``--updates`` more steps of its own loss and optimiser on minibatches of
the run's replay buffer while the critic is not stepped; greedy success over
``--episodes`` fresh episodes (seeds from 10^8) is printed before, at ``--report-at`` and
after. The world is the run's: frame skip 10, 200-step episodes.
"""

from __future__ import annotations

import argparse
from pathlib import Path

WORLD = {"frame_skip": 10, "max_episode_steps": 200}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoint", type=Path)
    parser.add_argument("--updates", type=int, default=10_000)
    parser.add_argument("--report-at", type=int, default=2_000)
    parser.add_argument("--episodes", type=int, default=40)
    parser.add_argument("--env-id", default="CraftSuite/BlindCraftsman-Cont-v0")
    args = parser.parse_args(argv)
    for name in ("model.zip", "replay.pkl"):
        if not (args.checkpoint / name).exists():
            parser.error(f"{args.checkpoint} has no {name}: give a student run's checkpoint directory")

    import torch

    torch.set_num_threads(1)
    from craftsuite.agents.factory import load_agent
    from craftsuite.training import evaluate

    model = load_agent(args.checkpoint / "model.zip")
    model.load_replay_buffer(args.checkpoint / "replay.pkl")

    def greedy() -> float:
        return evaluate(model, args.env_id, args.episodes, seed=10**8, product=True, env_kwargs=WORLD)[0]

    print(f"before: greedy success {greedy():.2f}", flush=True)
    for update in range(1, args.updates + 1):
        obs = model.replay_buffer.sample(256).observations
        loss = -model.critic.q1_forward(obs, model.actor(obs)).mean()  # the actor's own loss; the critic is frozen
        model.actor.optimizer.zero_grad()
        loss.backward()
        model.actor.optimizer.step()
        if update == args.report_at or update == args.updates:
            print(f"after {update:,} actor-only updates: greedy success {greedy():.2f}", flush=True)


if __name__ == "__main__":
    main()
