"""Write the saved models of ``tests/agents/test_factory.py``: small agents trained by the SB3
trainer as CraftSuite had it, which runs at commit 85ab46c (the last before the SB3 training
code was retired), not at this one. Run there from the repository root:
``python tests/agents/saved/make.py``. The files are fixtures: they stand for the models
users and the archive saved then, and are not made again."""

from __future__ import annotations

from pathlib import Path

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.agents.factory import make_agent, static_distillation
from craftsuite.task_registry import resolve_task

HERE = Path(__file__).parent
SMALL = {"learning_starts": 30, "buffer_size": 200, "batch_size": 8, "policy_kwargs": {"net_arch": [8]}}
GRID, CONT = "CraftSuite/FirstTool-Grid7-v0", "CraftSuite/FirstTool-Cont-v0"
# name: (method, env id, world keywords, settings beyond SMALL, with a table)
CASES = {
    "product-dqn": ("product-dqn", GRID, {"layout_seed": 0}, {}, False),
    "dqn-layer-norm": ("dqn", GRID, {"layout_seed": 0}, {"dueling": False, "layer_norm": True}, False),
    "dqn-residual-cnn": ("product-dqn", GRID, {"layout_seed": 0},
                         {"features_extractor": "residual-cnn", "prioritized": False,
                          "policy_kwargs": {"net_arch": [8], "features_extractor_kwargs": {"filters": 2, "blocks": 1}}},
                         False),
    "crm": ("crm", GRID, {"layout_seed": 0}, {}, False),
    "td3-dynamic": ("td3-dynamic", CONT, {"frame_skip": 10, "max_episode_steps": 40},
                    {"layer_norm": True, "action_noise": {"type": "persistent", "sigma": 0.6, "resample": 0.1}},
                    True),
}


def main() -> None:
    for name, (method, env_id, env_kwargs, settings, needs_table) in CASES.items():
        table = None
        if needs_table:
            spec = resolve_task("FirstTool")
            table = static_distillation(spec.automaton, completion_reward=spec.completion_reward)
        agent = make_agent(method, env_id, table=table, env_kwargs=env_kwargs, **{**SMALL, **settings})
        agent.learn(60)
        agent.save(HERE / f"{name}.zip")
        if name == "product-dqn":  # a teacher's checkpoint: craftsuite distill reads its replay
            agent.save_replay_buffer(HERE / f"{name}-replay.pkl")
        print(name, agent.num_timesteps, agent.n_updates)


if __name__ == "__main__":
    main()
