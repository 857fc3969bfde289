"""Method rows from outside the package: a user's module (``module:name`` on the command
line) or an installed package's entry point registers them, and the suites train them as
the package's own rows, in spawned workers too."""

import importlib.metadata
import json
import multiprocessing as mp
import sys
from concurrent.futures import ProcessPoolExecutor
from types import SimpleNamespace

import pytest

from craftsuite import methods, worker_pool
from craftsuite.cli import main
from craftsuite.methods import METHODS, Method, MethodError, methods_for, register_method, resolve_method

MODULE = '''
from craftsuite.methods import Method, register_method

ROWS = [Method("dqn-mine", "Grid", "dqn", False, description="my DQN from scratch")]
register_method(ROWS[0])
'''


@pytest.fixture
def user_module(tmp_path, monkeypatch):
    (tmp_path / "my_methods.py").write_text(MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))  # the spawned workers' path too
    yield "my_methods"  # (its rows go with the test: conftest)
    sys.modules.pop("my_methods", None)


def test_a_users_module_registers_a_row_the_suites_run(user_module):
    assert resolve_method(f"{user_module}:dqn-mine") == "dqn-mine"
    assert "dqn-mine" in methods_for("Grid10")
    assert methods.external_rows() == [{"name": "dqn-mine", "world": "Grid", "algorithm": "dqn", "product": False,
                                        "distill": None, "crm": False, "target": {},
                                        "description": "my DQN from scratch", "shaping": None,
                                        "potential_sign": 1}]
    register_method(METHODS["dqn-mine"])  # the same row again: nothing


def test_transfer_trains_a_users_row_in_a_spawned_worker(tmp_path):
    # registered from Python (a notebook, say), not by a module a worker could import
    register_method(Method("dqn-mine", "Grid", "dqn", False, description="my DQN from scratch"))
    out = tmp_path / "out"
    code = main(["transfer", "--suite", "standard", "--worlds", "Grid10", "--tasks", "Reach", "--methods",
                 "dqn-mine", "--seeds", "1", "--steps", "2000", "--workers", "1", "--no-video",
                 "--no-archive", "--out", str(out)])
    assert code == 0
    (run,) = (out / "students").glob("student-Reach-Grid10-dqn-mine-s0-*")
    assert json.loads((run / "result.json").read_text())["steps"] == 2000
    assert "| dqn-mine |" in (out / "leaderboard.md").read_text()


def test_the_leaderboard_reads_a_users_row_given_by_its_module(tmp_path, capsys):
    """Runs of a row of the user's own, on a board made by a process that has not imported
    its module: with --methods module:name they are that method (compared with scratch as a
    distilled one, described in the legend); without, named as rows it does not know."""
    from .reporting.fakes import fake_run

    (tmp_path / "my_rows.py").write_text(
        "from craftsuite.methods import Method, register_method\n"
        "register_method(Method('mine-static', 'Grid', 'dqn', True, distill='static', description='my static'))\n")
    runs, out = tmp_path / "runs", tmp_path / "board"
    for seed in range(3):
        fake_run(runs, "dqn", seed, [(1000, 0.0)], [(995, 0.0)], world="Grid10")
        fake_run(runs, "mine-static", seed, [(1000, 1.0)], [(995, 1.0)], world="Grid10",
                 effective={"method": {"algorithm": "dqn"}})  # as a run of a user's row records it
        fake_run(runs, "hand-made", seed, [(1000, 0.5)], [(995, 1.0)], world="Grid10")  # the format, by other code
    assert main(["leaderboard", str(runs), "--out", str(out)]) == 0
    md = (out / "leaderboard.md").read_text()
    assert "- `mine-static`: not a method of this version (a row of your own: `craftsuite leaderboard --methods " \
        "module:name` reads its runs as the method they are)" in md and "`mine-static` +1.00" not in md
    sys.path.insert(0, str(tmp_path))
    try:
        assert main(["leaderboard", str(runs), "--out", str(out), "--methods", "my_rows:mine-static"]) == 0
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("my_rows", None)
    md = (out / "leaderboard.md").read_text()
    assert "- `hand-made`: trained outside CraftSuite's trainers (its records hold no CraftSuite learner's " \
        "settings)" in md
    from craftsuite.stats import difference

    apart = difference([1.0] * 3, [0.0] * 3, bounds=(0, 1))  # 3 seeds all at 1 against 3 all at 0
    assert "- `mine-static`: my static" in md
    assert f"`mine-static` +1.00 [{apart.low:+.2f}, +1.00], P(> `dqn`) 1.00" in md
    capsys.readouterr()
    assert main(["leaderboard", str(runs), "--out", str(out), "--methods", "mine-static"]) == 2
    assert capsys.readouterr().err == ("craftsuite leaderboard: error: --methods mine-static: name a row of your "
                                       "own as module:name (CraftSuite's rows are known already)\n")


class _FreshWorkerRay:
    """The part of Ray the pool uses, each task run in a newly spawned process: as a Ray
    worker, it starts with the package's rows alone."""

    def remote(self, num_cpus):
        def task(function):
            def submit(*args):
                pool = ProcessPoolExecutor(1, mp_context=mp.get_context("spawn"))
                future = pool.submit(function, *args)
                pool.shutdown(wait=False)
                return SimpleNamespace(future=lambda: future)
            return SimpleNamespace(remote=submit)
        return task


def test_a_ray_worker_gets_the_rows_registered_in_the_driver(monkeypatch):
    register_method(Method("dqn-mine", "Grid", "dqn", False, description="my DQN from scratch"))
    monkeypatch.setattr(worker_pool, "connect_ray", lambda address: (_FreshWorkerRay(), False))
    pool = worker_pool.WorkerPool(1, ray="local")
    assert "dqn-mine" in pool.submit(methods_for, "Grid10").result(timeout=120)
    pool.close()


@pytest.mark.parametrize("row, message", [
    (Method("td3", "Cont", "td3", False), "method 'td3' is a row already"),
    (Method("My Method", "Cont", "td3", False), "use lowercase letters, digits and dashes"),
    ("td3-mine", "register_method takes a craftsuite.methods.Method row, got str"),
    (Method(None, "Cont", "td3", False), "method name None: use lowercase letters"),
])
def test_a_bad_row_is_refused_by_name(row, message):
    with pytest.raises(MethodError, match=message):
        register_method(row)


@pytest.mark.parametrize("fields, message", [
    ({"crm": "no"}, r"crm must be True or False, got 'no'"),  # a truth: it would switch CRM on
    ({"product": None}, r"product must be True or False, got None"),
    ({"distill": "dynamic", "target": {"rho": "x"}}, r"target rho must be a number in \[0, 1\], got 'x'"),
    ({"distill": "dynamic", "target": {"rho": float("nan")}}, r"target rho must be a number in \[0, 1\], got nan"),
    ({"distill": "dynamic", "target": {"self_loops": 0}}, r"target self_loops must be true or false, got 0"),
])
def test_a_rows_settings_are_checked_when_it_is_built_not_when_it_first_runs(fields, message):
    with pytest.raises(MethodError, match=rf"^METHODS row 'dqn-mine': {message}$"):
        Method(**{"name": "dqn-mine", "world": "Grid", "algorithm": "dqn", "product": True, **fields})


def test_a_module_that_is_not_there_or_registers_no_such_row_is_named(user_module, capsys):
    with pytest.raises(ValueError, match="module 'no_such_module' cannot be imported"):
        resolve_method("no_such_module:x")
    with pytest.raises(KeyError, match=rf"^unknown method 'dqn-other'.*; methods: dqn, .*; module '{user_module}' "
                                       r"was imported and registers no row 'dqn-other'$"):
        resolve_method(f"{user_module}:dqn-other")
    for text in (":row", f"{user_module}:", ":"):
        with pytest.raises(ValueError, match=f"method '{text}': a method of your own is named module:row"):
            resolve_method(text)
    assert main(["student", "Reach", "--method", "no_such_module:x"]) == 2
    assert "module 'no_such_module' cannot be imported" in capsys.readouterr().err


def test_an_installed_packages_entry_point_registers_its_rows(user_module, monkeypatch):
    point = importlib.metadata.EntryPoint(name="mine", value=f"{user_module}:ROWS", group=methods.ENTRY_POINTS)
    monkeypatch.setattr(importlib.metadata, "entry_points",
                        lambda group: [point] if group == methods.ENTRY_POINTS else [])
    methods.load_entry_points()
    assert METHODS["dqn-mine"].description == "my DQN from scratch"


def test_a_broken_entry_point_is_named_and_left_out(monkeypatch):
    point = importlib.metadata.EntryPoint(name="broken", value="no_such_package.rows:ROWS", group=methods.ENTRY_POINTS)
    monkeypatch.setattr(importlib.metadata, "entry_points",
                        lambda group: [point] if group == methods.ENTRY_POINTS else [])
    with pytest.warns(UserWarning, match="entry point 'no_such_package.rows:ROWS' was not loaded"):
        methods.load_entry_points()
    assert set(METHODS) == set(methods.BUILTIN)
