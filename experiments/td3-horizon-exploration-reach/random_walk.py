"""What exploration alone finds in the MuJoCo worlds: a persistent random walk per task.

Usage: python experiments/td3-horizon-exploration-reach/random_walk.py [--tasks T ...] [--episodes N] [--frame-skip K]

The walk keeps a uniform random thrust and draws a new one with probability 0.1 per step
(about what TD3's early, near-constant actor plus noise does, but livelier). Per task it
prints, per episode (50 s: 1,000 steps at frame skip 2; a violation ends one early): rewarded events
(an item or the completion: a reward above the step and wall costs), changes of
automaton state, the episodes that ended in success or in a violation (the rejecting
sink), and the mean episode length.
"""

from __future__ import annotations

import argparse


def random_walk(task: str, episodes: int = 20, frame_skip: int = 2) -> dict:
    import gymnasium as gym
    import numpy as np

    import craftsuite  # noqa: F401

    env = gym.make(f"CraftSuite/{task}-Cont-v0", frame_skip=frame_skip,  # 50 s episodes
                   max_episode_steps=round(50 / (0.025 * frame_skip)))
    rng = np.random.default_rng(0)
    events = changes = wins = violations = steps = 0
    for episode in range(episodes):
        env.reset(seed=episode)
        action, done, state = rng.uniform(-1, 1, 2), False, env.unwrapped.automaton_state
        while not done:
            if rng.random() < 0.1:
                action = rng.uniform(-1, 1, 2)
            _, reward, terminated, truncated, info = env.step(action)
            events += reward > -0.05  # more than the step and wall costs
            changes += env.unwrapped.automaton_state != state
            state, done, steps = env.unwrapped.automaton_state, terminated or truncated, steps + 1
        wins += bool(info.get("is_success"))
        violations += bool(info.get("violation"))
    env.close()
    return {"task": task, "episodes": episodes, "rewarded_events": events / episodes,
            "automaton_changes": changes / episodes, "successes": wins, "violations": violations,
            "mean_length": steps / episodes}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", nargs="+", default=["BlindCraftsman", "DungeonQuest", "DiamondMine"])
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--frame-skip", type=int, default=2)
    args = parser.parse_args()
    print(f"persistent random walk, {args.episodes} episodes per task, frame_skip {args.frame_skip}")
    print("| task | rewarded events / episode | automaton changes / episode | successes | violations "
          "| mean length (steps) |")
    print("|---|---|---|---|---|---|")
    for task in args.tasks:
        r = random_walk(task, args.episodes, args.frame_skip)
        print(f"| {task} | {r['rewarded_events']:.2f} | {r['automaton_changes']:.2f} | {r['successes']} "
              f"| {r['violations']} | {r['mean_length']:.0f} |")


if __name__ == "__main__":
    main()
