"""Bin the authors' published TD3 training curves into assets/authors_td3_returns.csv.

Their logs (adenm-10/Automaton_Distillation, logs/findings/*_experience_generation_episode_rew.csv,
dated 2024-10-22 to 10-27, one seed per method) hold the reward of each finished episode
against their loop step; one step is 10 envs, so transitions = 10 x step. Each curve is
binned into 100 equal spans of steps (the mean reward per span).

    python experiments/kinematic-figure5/authors_curves.py PATH/TO/Automaton_Distillation/logs/findings
"""

import csv
import sys
from pathlib import Path

import numpy as np

LOGS = {  # (task, method): their log's stem
    ("BlindCraftsman", "td3-dynamic"): "blind_craftsmen_7_target_rew_per_step_productMDP_TD3",
    ("BlindCraftsman", "td3"): "blind_craftsman_rew_per_step_env_config_7_cont",
    ("DungeonQuest", "td3-dynamic"): "dungeon_quest_7_target_rew_per_step_productMDP_TD3",
    ("DungeonQuest", "td3"): "dungeon_quest_rew_per_step_env_config_7_cont",
    ("GoldMine", "td3-dynamic"): "gold_mine_7_target_rew_per_step_productMDP_TD3",
    ("GoldMine", "td3"): "gold_mine_rew_per_step_env_config_7_cont",
}
BINS = 100


def main(logs: Path, out: Path) -> None:
    rows = []
    for (task, method), stem in LOGS.items():
        data = np.genfromtxt(logs / f"{stem}_experience_generation_episode_rew.csv", delimiter=",", skip_header=1)
        steps, rewards = data[:, 1], data[:, 2]
        edges = np.linspace(0, steps.max(), BINS + 1)
        which = np.clip(np.searchsorted(edges, steps, side="right") - 1, 0, BINS - 1)
        for b in range(BINS):
            inside = which == b
            if inside.any():
                rows.append((task, method, int(10 * edges[b + 1]), round(float(rewards[inside].mean()), 3)))
    with out.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["task", "method", "transitions", "return"])
        writer.writerows(rows)
    print(f"wrote {out} ({len(rows)} rows)")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(__file__).resolve().parents[2] / "assets" / "authors_td3_returns.csv")
