"""Bad input to the gymnasium ids and ``craftsuite video``: one clear line, nothing written."""

from __future__ import annotations

import gymnasium as gym
import pytest

import craftsuite
from craftsuite.cli import main

GRID7 = "CraftSuite/BlindCraftsman-Grid7-v0"
WRONG_SIZE = (f"size=10: {GRID7} is the 7x7 grid (its id fixes the size); "
              "use CraftSuite/BlindCraftsman-Grid10-v0")


# -- the ids ------------------------------------------------------------------------------

@pytest.mark.parametrize("make", [
    lambda **kw: gym.make(GRID7, **kw),
    lambda **kw: gym.make_vec(GRID7, num_envs=2, vectorization_mode="vector_entry_point", **kw),
    lambda **kw: gym.make_vec(GRID7, num_envs=2, vectorization_mode="sync", **kw),
], ids=["make", "vector_entry_point", "sync"])
def test_a_grid_id_refuses_another_size(make):
    with pytest.raises(ValueError) as err:
        make(size=10)
    assert str(err.value) == WRONG_SIZE
    make(size=7).close()  # its own size is no change


def test_a_size_with_no_id_names_the_tasks_grids():
    with pytest.raises(ValueError, match=r"^size=12: .*; leave size out \(BlindCraftsman's grids: Grid7, Grid10\)$"):
        gym.make(GRID7, size=12)


def test_the_kinematic_board_size_stays_an_option():
    env = gym.make("CraftSuite/BlindCraftsman-Kinematic-v0", size=10)
    assert env.unwrapped.size == 10
    env.close()


@pytest.mark.parametrize("mode", ["sync", "async", "vector_entry_point", None])
@pytest.mark.parametrize("num_envs", [0, -1])
def test_num_envs_below_one_is_one_clear_error_in_every_mode(mode, num_envs):
    with pytest.raises(ValueError) as err:
        craftsuite.make_vec(GRID7, num_envs=num_envs, vectorization_mode=mode)
    assert str(err.value) == f"num_envs must be a positive integer, got {num_envs}"


def test_the_native_vector_env_gives_the_same_error():
    with pytest.raises(ValueError) as err:  # gymnasium's own make_vec reaches the vector env's check
        gym.make_vec(GRID7, num_envs=0, vectorization_mode="vector_entry_point")
    assert str(err.value) == "num_envs must be a positive integer, got 0"


# -- craftsuite video ---------------------------------------------------------------------

def _refused(capsys, argv, out) -> str:
    """The one error line of a refused ``craftsuite video``, after checking it wrote nothing."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and err.startswith("craftsuite video: error: "), err
    assert not out.exists()
    return err.strip().removeprefix("craftsuite video: error: ")


@pytest.mark.parametrize("fps", ["0", "-5", "nan"])
def test_an_fps_of_zero_or_less_is_refused(tmp_path, capsys, fps):
    out = tmp_path / "v.mp4"
    with pytest.raises(SystemExit) as exit_:
        main(["video", GRID7, "--policy", "random", "--out", str(out), "--fps", fps])
    assert exit_.value.code == 2
    assert f"argument --fps: must be a number above 0, got {fps}" in capsys.readouterr().err
    assert not out.exists()


def test_record_video_refuses_an_fps_of_zero(tmp_path):
    from craftsuite.rollouts import record_video

    with pytest.raises(ValueError, match="fps must be positive, got 0"):  # not the world's pace, silently
        record_video(GRID7, "random", out=str(tmp_path / "v.mp4"), fps=0, progress=False)
    assert not (tmp_path / "v.mp4").exists()


@pytest.fixture(scope="module")
def checkpoints(tmp_path_factory):
    """Tiny DQN checkpoints of the Grid7 id, trained without and with the automaton state."""
    import stable_baselines3 as sb3

    folder = tmp_path_factory.mktemp("checkpoints")
    paths = {}
    for product in (False, True):
        model = sb3.DQN("MlpPolicy", gym.make(GRID7, product=product), learning_starts=10, device="cpu")
        model.learn(20)
        paths[product] = folder / f"{'product' if product else 'plain'}.zip"
        model.save(paths[product])
    return paths


def test_a_plain_checkpoint_with_product_says_drop_product(tmp_path, capsys, checkpoints):
    out = tmp_path / "v.mp4"
    error = _refused(capsys, ["video", GRID7, "--policy", str(checkpoints[False]), "--product", "--out", str(out)],
                     out)
    assert error == (f"{checkpoints[False]}: the policy's observation size 247 matches the plain observation "
                     "(trained without the automaton state); drop --product (product=False)")


def test_a_product_checkpoint_is_played_with_the_automaton_state_unasked(tmp_path, checkpoints):
    from craftsuite.policies import load_policy

    out = tmp_path / "v.mp4"
    assert main(["video", GRID7, "--policy", str(checkpoints[True]), "--out", str(out)]) == 0  # as evaluate reads it
    assert out.stat().st_size > 0
    with pytest.raises(ValueError, match=r"size 251 matches the observation with the automaton state \(trained "
                                         r"with it\); make the env with product=True"):
        load_policy(str(checkpoints[True]), gym.make(GRID7))  # an env made by hand says how to mend it


def test_a_checkpoint_of_another_task_names_both_sizes(tmp_path, capsys, checkpoints):
    out = tmp_path / "v.mp4"
    error = _refused(capsys, ["video", "CraftSuite/Reach-Grid7-v0", "--policy", str(checkpoints[False]),
                              "--out", str(out)], out)
    assert error.startswith(f"{checkpoints[False]}: the policy's observation shape (247,) is not "
                            "CraftSuite/Reach-Grid7-v0's") and "with the automaton state" in error


def test_an_unknown_task_in_an_id_is_named_as_elsewhere(tmp_path, capsys):
    out = tmp_path / "v.mp4"
    error = _refused(capsys, ["video", "CraftSuite/Nope-Grid7-v0", "--out", str(out)], out)
    assert error.startswith("unknown task 'Nope'; tasks: BlindCraftsman, ") and "Did you mean" not in error
    assert error == _refused(capsys, ["video", "Nope", "--out", str(out)], out)  # the task name's message


def test_an_unknown_world_in_an_id_lists_the_tasks_worlds(tmp_path, capsys):
    out = tmp_path / "v.mp4"
    error = _refused(capsys, ["video", "CraftSuite/BlindCraftsman-Grid99-v0", "--out", str(out)], out)
    assert error == "task 'BlindCraftsman' has no Grid99 world; its worlds: Cont, Grid10, Grid7, Kinematic"
    assert error == _refused(capsys, ["video", "BlindCraftsman", "--world", "Grid99", "--out", str(out)], out)
