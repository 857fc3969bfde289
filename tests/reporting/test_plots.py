"""Learning curves and performance profiles, one file per task and world."""

from craftsuite.reporting.board import build
from craftsuite.reporting.plots import plot_curves, plot_profiles

from .fakes import fake_run


def test_curves_are_a_png_per_task_and_world_setting(runs, tmp_path):
    [png] = plot_curves(build(runs), tmp_path)
    assert png.name == "curves-BlindCraftsman-Cont.png" and png.read_bytes()[:4] == b"\x89PNG"
    fake_run(runs, "td3", 0, [(1000, 1.0)], [(995, 50.0)], world_kwargs={"frame_skip": 10, "max_episode_steps": 200})
    fake_run(runs, "dqn", 0, [(1000, 0.5)], [(995, 5.0)], world="Grid10", layout_seed=1)
    fake_run(runs, "td3", 0, [(1000, 0.2)], [(995, 9.0)], world="Kinematic")
    names = {p.name for p in plot_curves(build(runs), tmp_path)}
    assert names == {"curves-BlindCraftsman-Cont.png", "curves-BlindCraftsman-Grid10-layout_seed-1.png",
                     "curves-BlindCraftsman-Cont-frame_skip-10-max_episode_steps-200.png",
                     "curves-BlindCraftsman-Kinematic.png"}
    # settings that read alike in a file name do not overwrite each other's plot
    fake_run(runs, "td3", 0, [(1000, 0.0)], [(995, 0.0)], world_kwargs={"x": -1})
    fake_run(runs, "td3", 0, [(1000, 0.0)], [(995, 0.0)], world_kwargs={"x": 1})
    assert len({p.name for p in plot_curves(build(runs), tmp_path)}) == 6


def test_a_profile_per_world_with_an_aggregate(tmp_path):
    root = tmp_path / "students"
    fake_run(root, "td3", 0, [(1000, 1.0)], [(995, 1.0)])
    fake_run(root, "td3-dynamic", 0, [(1000, 1.0)], [(995, 1.0)])
    assert plot_profiles(build(root), tmp_path) == []  # one seed each: nothing to aggregate
    for seed in range(1, 3):
        fake_run(root, "td3", seed, [(1000, 0.5)], [(995, 0.0)])
        fake_run(root, "td3-dynamic", seed, [(1000, 1.0)], [(995, 0.0)])
    [profile] = plot_profiles(build(root), tmp_path)
    assert profile.world_label == "Cont, one-step regime"
    assert profile.path.name == "profile-Cont-one-step.png" and profile.path.read_bytes()[:4] == b"\x89PNG"


def test_a_smoothed_curve_is_the_mean_over_each_points_window():
    """The smoothed return is the mean over each point's window of the budget, in any order
    the episodes come, from a list of pairs or an array alike."""
    import numpy as np

    from craftsuite.reporting.plots import _curve, smoothed

    grid = np.array([100.0, 200.0, 300.0, 400.0])  # window: 10% of 400, so (g - 40, g]
    episodes = [(380, 4.0), (95, 1.0), (50, 9.0), (390, 2.0), (250, 5.0)]
    assert np.allclose(smoothed(episodes, grid), [1.0, np.nan, np.nan, 3.0], equal_nan=True)
    assert np.array_equal(smoothed(np.array(episodes), grid), smoothed(episodes, grid), equal_nan=True)
    assert np.isnan(smoothed([], grid)).all() and np.isnan(_curve(np.empty((0, 2)), grid)).all()
    assert np.array_equal(_curve([(150, 0.5), (300, 1.0)], grid), [np.nan, 0.5, 1.0, 1.0], equal_nan=True)


def test_an_entry_keeps_its_runs_logs_in_seed_order(runs):
    import numpy as np

    from craftsuite.runs import read_csv

    for e in build(runs):
        assert len(e.curves) == len(e.runs) == len(e.seeds)
        for run, curves in zip(e.runs, e.curves):
            episodes, evals = read_csv(run / "episodes.csv"), read_csv(run / "evals.csv")
            assert curves.episodes.tolist() == [[float(r["step"]), float(r["return"]), float(r["success"])]
                                                for r in episodes]
            assert np.array_equal(curves.evals, [[float(r["step"]), float(r["success"])] for r in evals])
