"""Rollout videos: H.264 MP4 in yuv420p that any player opens, whatever the frame size."""

from __future__ import annotations

import subprocess

import imageio_ffmpeg
import numpy as np
import pytest

from craftsuite.rendering.video import VideoWriter, even_frame


def read_video(path) -> tuple[dict, list[np.ndarray]]:
    """FFmpeg's description of the file (codec, pix_fmt, size as (width, height), fps) and
    its decoded RGB frames."""
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    width, height = meta["size"]
    frames = [np.frombuffer(f, np.uint8).reshape(height, width, 3) for f in reader]
    return meta, frames


def ramp(height: int, width: int, shift: int) -> np.ndarray:
    """A smooth RGB picture that changes with ``shift`` (lossy codecs keep smooth pictures)."""
    y, x = np.mgrid[0:height, 0:width]
    return np.stack([x * 255 // max(1, width - 1), y * 255 // max(1, height - 1),
                     np.full_like(x, shift % 256)], axis=2).astype(np.uint8)


@pytest.mark.parametrize("height, width", [(64, 96), (63, 95), (35, 64)])
def test_writes_h264_yuv420p_with_every_frame(tmp_path, height, width):
    frames = [ramp(height, width, 20 * i) for i in range(9)]
    path = tmp_path / "nested" / "clip.mp4"
    with VideoWriter(path, fps=8) as video:
        for frame in frames:
            video.write(frame)
    even = (width + width % 2, height + height % 2)  # odd sides padded by one
    assert video.frames == 9 and video.codec == "h264" and video.size == even
    meta, decoded = read_video(path)
    assert meta["codec"] == "h264" and meta["pix_fmt"].startswith("yuv420p")
    assert meta["size"] == even and meta["fps"] == 8 and len(decoded) == 9
    for written, read in zip(frames, decoded):  # not rescaled: the picture is where it was
        error = np.abs(read[:height, :width].astype(int) - written.astype(int))
        assert error.mean() < 6  # H.264's loss is a few levels; a shifted or scaled picture, tens


def test_ffmpeg_itself_reads_an_h264_stream(tmp_path):
    path = tmp_path / "clip.mp4"
    with VideoWriter(path, fps=4) as video:
        for i in range(3):
            video.write(ramp(40, 40, i))
    probe = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-i", str(path)],
                           capture_output=True, text=True).stderr  # no output file: FFmpeg only describes
    assert "Video: h264" in probe and "yuv420p" in probe and "40x40" in probe


def test_odd_frames_are_padded_with_their_edge_not_scaled():
    frame = ramp(5, 7, 0)
    padded = even_frame(frame)
    assert padded.shape == (6, 8, 3)
    np.testing.assert_array_equal(padded[:5, :7], frame)
    np.testing.assert_array_equal(padded[5, :7], frame[4])
    np.testing.assert_array_equal(padded[:5, 7], frame[:, 6])
    assert even_frame(padded) is padded


def test_bad_input_is_named_and_nothing_is_written(tmp_path):
    with pytest.raises(ValueError, match=r"clip.avi: a video is written as MP4; give a file name ending in .mp4, "
                                         r"e.g. .*clip.mp4"):
        VideoWriter(tmp_path / "clip.avi", fps=4)
    with pytest.raises(ValueError, match="fps must be positive"):
        VideoWriter(tmp_path / "clip.mp4", fps=0)
    video = VideoWriter(tmp_path / "clip.mp4", fps=4)
    with pytest.raises(ValueError, match=r"RGB frame \(H, W, 3\) of uint8, got shape \(8, 8\)"):
        video.write(np.zeros((8, 8), np.uint8))
    with pytest.raises(ValueError, match="of uint8, got shape .* of float64"):
        video.write(np.zeros((8, 8, 3)))
    assert not (tmp_path / "clip.mp4").exists()
    with video:
        video.write(ramp(8, 8, 0))
        with pytest.raises(ValueError, match="frame size 10x8 differs from the video's 8x8"):
            video.write(ramp(8, 10, 0))
    assert read_video(tmp_path / "clip.mp4")[0]["size"] == (8, 8)


def test_videos_for_people_carry_the_status_panel(tmp_path, capsys):
    """The video command and the transfer runner's best-student video ask the world for the
    status panel, which frames leave out by default."""
    import json

    import gymnasium as gym

    from craftsuite.agents.factory import make_agent
    from craftsuite.cli import main
    from craftsuite.suite_runner import _best_student_video

    env_id = "CraftSuite/DungeonQuest-Grid7-v0"
    plain = gym.make(env_id).unwrapped.frame_shape
    shown = gym.make(env_id, status_panel=True).unwrapped.frame_shape
    assert shown[0] > plain[0]
    assert main(["video", env_id, "--out", str(tmp_path / "command.mp4")]) == 0
    assert read_video(tmp_path / "command.mp4")[0]["size"] == (shown[1], shown[0])
    assert main(["video", env_id, "--out", str(tmp_path / "bare.mp4"), "--env", '{"status_panel": false}']) == 0
    assert read_video(tmp_path / "bare.mp4")[0]["size"] == (plain[1], plain[0])  # --env still decides

    run = tmp_path / "students" / "run"
    run.mkdir(parents=True)
    agent = make_agent("product-dqn", env_id, learning_starts=10, buffer_size=100)
    agent.save(run / "model.zip")
    (run / "config.json").write_text(json.dumps({"task": "DungeonQuest", "world": "Grid7", "method": "product-dqn",
                                                 "seed": 0, "steps": 20}))
    (run / "result.json").write_text(json.dumps({
        "kind": "student", "steps": 20, "task": "DungeonQuest", "env_id": env_id, "method": "product-dqn",
        "seed": 0, "model": "model.zip", "product": True, "env_kwargs": {}}))
    (run / "evals.csv").write_text("step,success,return\n20,0.0,-5.0\n")
    movie = _best_student_video([run], tmp_path)
    assert read_video(movie)[0]["size"] == (shown[1], shown[0])


@pytest.mark.parametrize("env_id", ["CraftSuite/BlindCraftsman-Cont-v0", "CraftSuite/BlindCraftsman-Kinematic-v0"])
def test_continuous_worlds_play_their_motion_between_decisions(tmp_path, env_id, gl_available):
    """A continuous world's video draws each decision's motion: 15 frames a second or more
    at the world's pace (MuJoCo's control period; the board's render_fps decisions a second),
    the agent moving between the frames of one decision."""
    import cv2
    import gymnasium as gym

    from craftsuite.episodes import rollout
    from craftsuite.rollouts import record_video
    from craftsuite.scripted import scripted_policy

    if "Cont" in env_id and not gl_available:
        pytest.skip(gl_available.reason)
    out = tmp_path / "motion.mp4"
    recording = record_video(env_id, "scripted", 1, str(out), seed=3, progress=False)
    env = gym.make(env_id)
    decisions = rollout(env, scripted_policy(env), 1, 3)[0].length
    video = cv2.VideoCapture(str(out))
    fps, count = video.get(cv2.CAP_PROP_FPS), int(video.get(cv2.CAP_PROP_FRAME_COUNT))
    frames = []
    while (ok := video.read())[0]:
        frames.append(ok[1].astype(int))
    video.release()
    assert fps >= 15 and recording.fps == fps
    assert count == len(frames) == recording.frames > decisions + 1
    per_decision = (len(frames) - 1) // decisions
    assert per_decision * decisions + 1 == len(frames)
    assert np.isclose(fps, per_decision * env.metadata["render_fps"])  # the world's pace
    # within one decision the picture changes: the agent glides instead of jumping
    moving = sum(np.abs(a - b).mean() > 0.05 for a, b in zip(frames[1:], frames[2:]))
    assert moving > decisions
