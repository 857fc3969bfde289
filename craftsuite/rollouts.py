"""Recorded rollouts: a policy's episodes in an env, written as an MP4."""

from __future__ import annotations

from dataclasses import dataclass

import gymnasium as gym
from tqdm import tqdm

from .policies import load_policy
from .rendering.video import VideoWriter


@dataclass(frozen=True)
class Recording:
    path: str
    frames: int
    fps: float
    codec: str
    successes: int
    episodes: int


def record_video(env_id: str, policy: str = "scripted", episodes: int = 1, out: str = "rollout.mp4",
                 seed: int = 0, fps: float | None = None, product: bool = False,
                 progress: bool = True, env_kwargs: dict | None = None) -> Recording:
    """Roll out ``policy`` (see ``load_policy``) for ``episodes`` and write every frame to
    ``out``. ``env_kwargs`` go to ``gymnasium.make`` (the world a student was trained in)."""
    env = gym.make(env_id, render_mode="rgb_array", product=product, **(env_kwargs or {}))
    try:
        act = load_policy(policy, env, seed=seed)
        fps = fps or env.metadata.get("render_fps", 20)
        successes = 0
        with VideoWriter(out, fps) as video:
            for episode in tqdm(range(episodes), desc=f"{env_id} ({policy})", unit="episode",
                                disable=not progress):
                obs, _ = env.reset(seed=seed + episode)
                video.write(env.render())
                done = False
                while not done:
                    obs, _, term, trunc, info = env.step(act(obs))
                    video.write(env.render())
                    done = term or trunc
                successes += bool(info["is_success"])
    finally:
        env.close()
    return Recording(str(out), video.frames, fps, video.codec, successes, episodes)
