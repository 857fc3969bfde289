"""A policy's episodes recorded as an MP4 (``record_video``), through the one rollout loop
(``craftsuite.episodes``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import gymnasium as gym

from .episodes import rollout
from .progress import progress_bar
from .rendering.video import VideoWriter


SMOOTH_FPS = 20  # the least frames per second of a continuous world's video (motion drawn between decisions)


@dataclass(frozen=True)
class Recording:
    path: str
    frames: int
    fps: float
    codec: str
    successes: int
    episodes: int


def record_video(env_id: str, policy: str = "scripted", episodes: int = 1, out: str = "rollout.mp4",
                 seed: int = 0, fps: float | None = None, product: bool | None = None,
                 progress: bool = True, env_kwargs: dict | None = None) -> Recording:
    """Roll out ``policy`` (see ``load_policy``) for ``episodes`` and write every frame to
    ``out``. ``env_kwargs`` go to ``gymnasium.make`` (the world a student was trained in);
    ``product``: whether the env's observations carry the automaton state (default: as the
    checkpoint's observation space says, as ``craftsuite.evaluate`` reads it; not for
    ``"random"`` and ``"scripted"``).

    A grid video shows one frame per decision at the env's ``render_fps``; a continuous
    world's draws each decision's motion too (``set_frames_per_decision``), so that it plays
    at ``SMOOTH_FPS`` or more at the world's pace. ``fps``, if given, sets the playback rate."""
    # here: the loop's other users (training's evaluation) need no policies
    from .evaluation import sees_automaton
    from .policies import checkpoint_policy, is_checkpoint, load_checkpoint, load_policy

    model = load_checkpoint(policy) if is_checkpoint(policy) else None
    if product is None:
        try:
            product = model is not None and sees_automaton(model, env_id, env_kwargs or {})
        except ValueError:  # of neither shape: checkpoint_policy names it, with the checkpoint's path
            product = False
    env = gym.make(env_id, render_mode="rgb_array", product=product, **(env_kwargs or {}))
    world = env.unwrapped
    try:
        act = load_policy(policy, env, seed=seed) if model is None else checkpoint_policy(model, env, policy)
        decisions_per_second = env.metadata.get("render_fps", 20)
        per_decision = 1
        if hasattr(world, "set_frames_per_decision"):
            per_decision = world.set_frames_per_decision(math.ceil(SMOOTH_FPS / decisions_per_second))
        fps = decisions_per_second * per_decision if fps is None else fps  # 0 is VideoWriter's to refuse
        with VideoWriter(out, fps) as video:
            def on_step(episode, reward, info):
                for frame in world.motion_frames() if per_decision > 1 else [env.render()]:
                    video.write(frame)

            def on_reset(episode):
                bar.update(episode - bar.n)  # the episodes before this one are done
                video.write(env.render())

            with progress_bar(episodes, f"{env_id} ({policy})", unit="episode", enabled=progress) as bar:
                played = rollout(env, act, episodes, seed, on_reset=on_reset, on_step=on_step)
                bar.update(episodes - bar.n)
    finally:
        env.close()
    return Recording(str(out), video.frames, fps, video.codec, sum(e.success for e in played), episodes)
