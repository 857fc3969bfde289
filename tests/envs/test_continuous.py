"""The MuJoCo worlds: pickups by distance, physics, scripted completion, rendering, video."""

from __future__ import annotations

import re
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

import craftsuite
from craftsuite.cli import main as cli
from craftsuite.envs import continuous
from craftsuite.envs.continuous import TOP_SPEED, ContinuousWorldEnv
from craftsuite.episodes import rollout
from craftsuite.rendering.frames import MAX_FRAME_SIDE
from craftsuite.scripted import ContinuousScriptedPolicy

from .test_video import read_video

CONT = [i for i in craftsuite.registered_ids() if "-Cont-" in i]


def make(task="BlindCraftsman", **kw):
    return ContinuousWorldEnv(task, **kw)


def place_agent(env, xy):
    env.data.qpos[:2] = xy
    env.data.qvel[:2] = 0
    import mujoco
    mujoco.mj_forward(env.model, env.data)


@pytest.mark.parametrize("env_id", CONT)
def test_scripted_policy_completes_within_the_time_limit(env_id):
    env = gym.make(env_id)
    policy = ContinuousScriptedPolicy(env)
    successes = 0
    for seed in range(10):
        accepting_before_end = False
        obs, info = env.reset(seed=seed)
        done = False
        while not done:
            obs, reward, term, trunc, info = env.step(policy(obs))
            done = term or trunc
            accepting = env.unwrapped.automaton.accepting[info["automaton_state"]]
            accepting_before_end |= accepting and not done
        assert not accepting_before_end  # acceptance ends the episode on the spot
        assert info["is_success"] == env.unwrapped.automaton.accepting[info["automaton_state"]]
        successes += info["is_success"]
    assert successes >= 9


def test_acceptance_exactly_when_blind_craftsman_is_done():
    env = gym.make("CraftSuite/BlindCraftsman-Cont-v0")
    policy = ContinuousScriptedPolicy(env)
    env.reset(seed=3)
    u = env.unwrapped
    while True:
        obs, reward, term, trunc, info = env.step(policy())
        if term:
            break
        assert not (u.inventory["tools"] >= 3 and "home" in info["labels"])
    assert info["is_success"] and u.inventory["tools"] >= 3 and "home" in info["labels"]
    assert reward == pytest.approx(100 - 0.1, abs=0.11)  # + possibly a boundary push


def test_pickup_radius_is_0_4():
    env = make("DungeonQuest")
    env.reset(seed=0)
    key = env.kinds.index([o.name for o in env.task.objects].index("key"))
    kx, ky = env._positions[key]
    direction = -np.sign([kx, ky]) * np.array([1.0, 0.0])  # move towards the arena centre
    if not direction.any():
        direction = np.array([1.0, 0.0])
    place_agent(env, np.array([kx, ky]) + direction * 0.45)
    env.step(np.zeros(2))
    assert env.inventory["key"] == 0 and env._present[key]
    place_agent(env, np.array([kx, ky]) + direction * 0.35)
    obs, reward, term, trunc, info = env.step(np.zeros(2))
    assert env.inventory["key"] == 1 and not env._present[key]
    assert info["labels"] == ("key",) and reward == pytest.approx(0.9)
    layout = env.observation_layout
    slot = obs[layout["objects"]].reshape(-1, 3)[key]
    assert slot.tolist() == [0.0, 0.0, 0.0]  # consumed: gone from the observation
    assert env.model.geom_rgba[env._geom_ids[key], 3] == 0.0  # and from view


def test_places_act_on_arrival_only():
    env = make("DungeonQuest")
    env.reset(seed=0)
    env.inventory_counts[env.rules.inventory_names.index("key")] = 1
    chest = env.kinds.index([o.name for o in env.task.objects].index("chest"))
    place_agent(env, env._positions[chest] + [0.1, 0.0])
    env.step(np.zeros(2))
    assert env.inventory["sword"] == 1 and env.inventory["key"] == 0
    env.inventory_counts[env.rules.inventory_names.index("key")] = 1
    env.step(np.zeros(2))  # still inside: no second arrival
    assert env.inventory["sword"] == 1 and env.inventory["key"] == 1


def test_top_speed_and_control_period():
    env = make()
    env.reset(seed=0)
    place_agent(env, np.array([-3.0, 0.0]))
    env._positions[:] = 1e6  # nothing to touch on the way
    for _ in range(8):
        env.step(np.array([1.0, 0.0]))
    assert env.data.qvel[0] == pytest.approx(TOP_SPEED, rel=0.02)
    assert env.data.time == pytest.approx(8 * 0.25)  # the spec's control period: 10 physics steps


@pytest.mark.parametrize("env_id", CONT)
def test_registered_world_is_the_teachers_time_scale(env_id):
    env = gym.make(env_id)
    assert env.unwrapped.frame_skip == 10 and env.unwrapped.dt == pytest.approx(0.25)
    assert env.spec.max_episode_steps == 200  # 50 s of simulated time


def test_frame_skip_keyword_gives_the_fine_control_world():
    fine = gym.make("CraftSuite/BlindCraftsman-Cont-v0", frame_skip=2, max_episode_steps=1000)
    fine.reset(seed=0)
    fine.step(np.zeros(2))
    u = fine.unwrapped
    assert u.data.time == pytest.approx(2 * 0.025) and u.dt == pytest.approx(0.05)
    assert u.metadata["render_fps"] == 20 and fine.spec.max_episode_steps == 1000
    with pytest.raises(ValueError, match="frame_skip must be a positive integer"):
        ContinuousWorldEnv(frame_skip=0)


def test_a_control_period_off_the_physics_step_is_named(tmp_path):
    import dataclasses

    from craftsuite.spec import SpecError, load_spec, physics_timestep

    assert physics_timestep() == ContinuousWorldEnv().model.opt.timestep  # the spec reads arena.xml's step
    path = tmp_path / "odd.toml"
    path.write_text('name = "Odd"\nformula = "F coin"\n[propositions]\ncoin = { obtained = "coin" }\n'
                    '[items.coin]\ncount = 1\n[continuous]\ncontrol_period = 0.26\n')
    with pytest.raises(SpecError, match=r"odd.toml.*continuous.control_period.*0.26 s is not a whole number"):
        load_spec(path)  # at load, before any world is built
    spec = load_spec(_rewrite(path, "0.26", "0.5"))
    assert ContinuousWorldEnv(spec).frame_skip == 20
    odd = dataclasses.replace(spec, continuous=dataclasses.replace(spec.continuous, control_period=0.26))
    with pytest.raises(ValueError, match=r"continuous.control_period: 0.26 s is not a whole number"):
        ContinuousWorldEnv(odd)  # a spec changed in code is checked by the world


def _rewrite(path, old, new):
    path.write_text(path.read_text().replace(old, new))
    return path


def test_object_offsets_are_divided_by_the_arena_side():
    env = make()
    obs, _ = env.reset(seed=3)
    slots = obs[env.observation_layout["objects"]].reshape(-1, 3)
    expected = (env._positions - env.data.qpos[:2]) / env.arena
    np.testing.assert_allclose(slots[:, :2], expected, atol=1e-6)
    assert np.abs(slots[:, :2]).max() < 1


def test_the_offsets_keyword_is_gone():
    """The square-root offsets experiment did not help students; the world has one scaling."""
    with pytest.raises(ValueError, match="unknown keyword 'offsets' for the MuJoCo world"):
        gym.make("CraftSuite/BlindCraftsman-Cont-v0", offsets="sqrt")
    with pytest.raises(TypeError, match="offsets"):
        ContinuousWorldEnv(offsets="linear")
    assert not hasattr(continuous, "OFFSETS")


def test_boundary_push_costs_and_walls_hold():
    env = make()
    env.reset(seed=0)
    env._positions[:] = 1e6
    place_agent(env, np.array([env.half - 0.5, 0.0]))
    rewards = [env.step(np.array([1.0, 0.0]))[1] for _ in range(30)]
    assert env.data.qpos[0] < env.half
    assert rewards[-1] == pytest.approx(-0.2)
    assert rewards[0] == pytest.approx(-0.1)


def test_obstacles_are_solid():
    env = make("BlindCraftsmanObstacles")
    env.reset(seed=0)
    env._positions[:] = 1e6
    x, y, h = env.scene.obstacles[0]
    place_agent(env, np.array([x - h - 0.6, y]))
    for _ in range(60):
        env.step(np.array([1.0, 0.0]))
    assert env.data.qpos[0] < x - h


def test_reset_writes_positions_without_recompiling():
    env = make()
    model = env.model
    env.reset(seed=1)
    first = env._positions.copy()
    env.reset(seed=2)
    assert env.model is model and not np.allclose(first, env._positions)
    assert np.allclose(model.body_pos[env._body_ids, :2], env._positions)


@pytest.mark.parametrize("task", ["BlindCraftsman", "DiamondMine", "BlindCraftsmanObstacles"])
def test_zones_do_not_overlap(task):
    env = make(task)
    for seed in range(20):
        env.reset(seed=seed)
        points = np.vstack([env._positions, env.data.qpos[:2]])
        gaps = np.linalg.norm(points[:, None] - points[None], axis=2) + np.eye(len(points)) * 99
        assert gaps.min() >= 2 * env.radius
        for x, y, h in env.scene.obstacles:
            assert (np.maximum(abs(points[:, 0] - x), abs(points[:, 1] - y)) > h).all()


@pytest.mark.parametrize("action, message", [
    (np.array([np.nan, 0.0]), "NaN or infinite"),
    (np.array([np.inf, 0.0]), "NaN or infinite"),
    (np.zeros(3), "expected 2 numbers"),
    (np.zeros((2, 1)), "expected 2 numbers"),
    ("up", "expected 2 numbers"),
])
def test_bad_actions_are_named(action, message):
    env = make()
    env.reset(seed=0)
    with pytest.raises(ValueError, match=message):
        env.step(action)


def test_out_of_range_actions_are_clipped():
    a, b = make(), make()
    a.reset(seed=0)
    b.reset(seed=0)
    for _ in range(5):
        oa = a.step(np.array([7.0, -3.0]))[0]
        ob = b.step(np.array([1.0, -1.0]))[0]
    assert np.array_equal(oa, ob)


def test_frame_shows_the_agent_where_it_is(gl_available):
    if not gl_available:
        pytest.skip(gl_available.reason)
    env = make(render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert frame.shape == env.frame_shape == (240, 240, 3) and frame.std() > 10
    col, row = env.world_to_pixel(*env.data.qpos[:2])
    patch = frame[row - 2:row + 3, col - 2:col + 3].astype(int)
    assert patch.max() < 60  # the agent is a near-black cube
    far = env.world_to_pixel(*(-np.sign(env.data.qpos[:2]) * 2.0))
    assert frame[far[1], far[0]].min() > 100  # the floor elsewhere is light
    env.close()


@pytest.mark.parametrize("width, height", [(240, 240), (480, 240), (240, 480)])
def test_world_to_pixel_any_frame_shape(gl_available, width, height):
    if not gl_available:
        pytest.skip(gl_available.reason)
    env = make(render_mode="rgb_array", width=width, height=height)
    env.reset(seed=0)
    env._positions[:] = 1e6
    place_agent(env, np.array([-1.0, -1.0]))
    elsewhere = env.render().max(axis=2)
    place_agent(env, np.array([1.0, 1.0]))
    here = env.render().max(axis=2)
    assert here.shape == (height, width)
    agent = np.argwhere((here < 40) & (elsewhere > 100))  # pixels the agent moved onto
    row, col = agent.mean(axis=0)
    assert np.allclose((col, row), env.world_to_pixel(1.0, 1.0), atol=3)
    for corner in ((-3.5, -3.5), (3.5, 3.5)):  # the whole arena is in view
        c, r = env.world_to_pixel(*corner)
        assert 0 <= c < width and 0 <= r < height
    env.close()


@pytest.mark.parametrize("name", ["width", "height"])
@pytest.mark.parametrize("value", [0, -240, 2.5, 240.0, True, "240", None, MAX_FRAME_SIDE + 1])
def test_frame_sides_are_checked_at_construction(name, value, monkeypatch):
    def no_gl(*args, **kwargs):
        raise AssertionError("a bad frame size reached OpenGL")

    monkeypatch.setattr(continuous.mujoco, "Renderer", no_gl)
    for build in (lambda: gym.make("CraftSuite/BlindCraftsman-Cont-v0", render_mode="rgb_array", **{name: value}),
                  lambda: ContinuousWorldEnv(**{name: value})):
        with pytest.raises(ValueError, match=rf"^{name} must be a whole number of pixels in \[1, {MAX_FRAME_SIDE}\], "
                                             rf"got {re.escape(repr(value))}$"):
            build()


def test_numpy_integer_frame_sides_are_accepted():
    env = make(width=np.int64(320), height=np.uint16(200))
    assert env.frame_shape == (200, 320, 3) and type(env.width) is int and type(env.height) is int


def test_frames_larger_than_the_models_framebuffer_render(gl_available):
    if not gl_available:
        pytest.skip(gl_available.reason)
    offscreen = make().model.vis.global_  # arena.xml's off-screen buffer
    width = offscreen.offwidth + 160
    env = make(render_mode="rgb_array", width=width, height=offscreen.offheight + 2)
    env.reset(seed=0)
    assert env.render().shape == env.frame_shape == (offscreen.offheight + 2, width, 3)
    env.close()


def test_status_panel_is_drawn_only_when_asked(gl_available):
    if not gl_available:
        pytest.skip(gl_available.reason)
    from craftsuite.rendering.panel import PANEL_HEIGHT

    plain = make(render_mode="rgb_array", width=200, height=160)
    shown = make(render_mode="rgb_array", width=200, height=160, status_panel=True)
    plain.reset(seed=4)
    shown.reset(seed=4)
    world, framed = plain.render(), shown.render()
    assert world.shape == plain.frame_shape == (160, 200, 3)
    assert framed.shape == shown.frame_shape == (160 + PANEL_HEIGHT, 200, 3)
    np.testing.assert_array_equal(framed[:160], world)  # the same world, the strip under it
    strip = framed[160:]
    assert (strip < 128).any() and strip.mean() > 200  # dark text on a light strip
    with pytest.raises(ValueError, match="status_panel must be True or False, got 'yes'"):
        make(status_panel="yes")
    plain.close()
    shown.close()


def test_renderer_closes_cleanly_at_exit(gl_available):
    if not gl_available:
        pytest.skip(gl_available.reason)
    code = ("import gymnasium as gym, craftsuite; e = gym.make('CraftSuite/DungeonQuest-Cont-v0', "
            "render_mode='rgb_array'); e.reset(seed=0); e.render(); "
            "f = gym.make('CraftSuite/BlindCraftsman-Cont-v0', render_mode='rgb_array'); "
            "f.reset(seed=0); f.render(); f.close()")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0 and out.stderr.strip() == "", out.stderr


@pytest.mark.parametrize("env_id", ["CraftSuite/DungeonQuest-Cont-v0", "CraftSuite/DungeonQuest-Grid7-v0"])
def test_video_command_writes_a_readable_mp4(tmp_path, env_id, gl_available, capsys):
    if "Cont" in env_id and not gl_available:
        pytest.skip(gl_available.reason)
    out = tmp_path / "rollout.mp4"
    assert cli(["video", env_id, "--policy", "scripted", "--episodes", "2", "--out", str(out)]) == 0
    env = gym.make(env_id, status_panel=True)  # videos are for people: the command draws the panel
    policy = craftsuite.scripted.scripted_policy(env)
    meta, frames = read_video(out)
    per_decision = round(meta["fps"] / env.metadata["render_fps"])  # MuJoCo's: its motion, drawn between decisions
    assert per_decision == (1 if "Grid" in env_id else 5)
    expected = sum(per_decision * rollout(env, policy, 1, s)[0].length + 1 for s in range(2))  # + reset frames
    assert meta["codec"] == "h264" and meta["pix_fmt"].startswith("yuv420p")
    rows, columns, _ = env.unwrapped.frame_shape
    assert meta["size"] == (columns, rows) and len(frames) == expected
    printed = capsys.readouterr().out
    assert f"{expected} frames" in printed and "(h264)" in printed


def test_video_rejects_a_corrupt_checkpoint(tmp_path, capsys):
    bad = tmp_path / "model.zip"
    bad.write_bytes(b"not a zip")
    assert cli(["video", "CraftSuite/DungeonQuest-Grid7-v0", "--policy", str(bad),
                "--out", str(tmp_path / "x.mp4")]) == 2
    assert "not a stable-baselines3 checkpoint" in capsys.readouterr().err


def test_record_video_wrapper(tmp_path, gl_available):
    if not gl_available:
        pytest.skip(gl_available.reason)
    env = gym.make("CraftSuite/BlindCraftsman-Cont-v0", render_mode="rgb_array")
    env = gym.wrappers.RecordVideo(env, str(tmp_path / "videos"), episode_trigger=lambda e: True,
                                   disable_logger=True)
    env.reset(seed=0)
    for _ in range(10):
        env.step(env.action_space.sample())
    env.close()
    assert list((tmp_path / "videos").glob("*.mp4"))
