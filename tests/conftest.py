import atexit
import os
import shutil
import tempfile

# One scratch directory per test session, removed at its end. Tests must not touch the
# user's automaton cache; and SB3 makes an empty /tmp/SB3-<time> folder for every learn()
# without a log directory (hundreds per run of the tests) unless SB3_LOGDIR names one.
_SCRATCH = tempfile.mkdtemp(prefix="craftsuite-tests-")
atexit.register(shutil.rmtree, _SCRATCH, ignore_errors=True)
os.environ.setdefault("CRAFTSUITE_CACHE_DIR", os.path.join(_SCRATCH, "cache"))
os.environ.setdefault("SB3_LOGDIR", os.path.join(_SCRATCH, "sb3"))
# One torch thread, set before torch is imported, as real runs do (training sets it): these
# nets are small, and on a machine with other work OpenMP's spinning threads made a
# 300-step smoke test take a minute instead of half a second.
os.environ.setdefault("OMP_NUM_THREADS", "1")


import pytest  # noqa: E402


class _GL:
    def __init__(self, ok: bool, reason: str = ""):
        self.ok, self.reason = ok, reason

    def __bool__(self):
        return self.ok


@pytest.fixture(scope="session")
def gl_available():
    """Whether MuJoCo can render off-screen here; falsy with the reason when it cannot."""
    import craftsuite  # noqa: F401  (chooses MUJOCO_GL before mujoco is imported)
    import mujoco

    try:
        model = mujoco.MjModel.from_xml_string("<mujoco><worldbody/></mujoco>")
        with mujoco.Renderer(model, 8, 8) as renderer:
            renderer.render()
    except Exception as err:  # no GL backend could start
        import os
        return _GL(False, f"no off-screen GL backend (MUJOCO_GL={os.environ.get('MUJOCO_GL')}): {err}")
    return _GL(True)


_TREASURE = """
name = "{name}"
formula = "F(coin)"

[propositions]
coin = {{ obtained = "coin" }}

[items.coin]
count = 1

[grid]
sizes = [{size}]
max_steps = {max_steps}
"""


@pytest.fixture
def treasure_spec(tmp_path):
    """A factory of user spec files (one coin to pick up on a small grid), written under
    ``tmp_path/specs``; whatever of them a test registers is forgotten after it (its ids and
    its registry entry), so user tasks never leak into other tests."""
    import gymnasium as gym

    from craftsuite import task_registry

    names = []

    def write(name: str, size: int, max_steps: int):
        path = tmp_path / "specs" / f"{name.lower()}.toml"
        path.parent.mkdir(exist_ok=True)
        path.write_text(_TREASURE.format(name=name, size=size, max_steps=max_steps))
        names.append(name)
        return path

    yield write
    for name in names:
        for env_id in [i for i in gym.registry if i.startswith(f"CraftSuite/{name}-")]:
            del gym.registry[env_id]
        task_registry.tasks().pop(name, None)


@pytest.fixture(autouse=True)
def _registered_tasks_are_the_tests_own():
    """A task a test registers (and its gymnasium ids) is gone after it: the ladder and the
    suites read every registered task, so one left behind would change tests that follow."""
    from craftsuite import task_registry
    import gymnasium as gym

    tasks = dict(task_registry.tasks())
    ids = set(gym.registry)
    yield
    task_registry.tasks().clear()
    task_registry.tasks().update(tasks)
    for env_id in set(gym.registry) - ids:
        del gym.registry[env_id]


@pytest.fixture(autouse=True)
def _registered_methods_are_the_tests_own():
    """A METHODS row a test (or a module it imports) registers is gone after it: the suites,
    the command line and the leaderboard read every row, so one left behind would change
    tests that follow."""
    from craftsuite import methods

    rows = set(methods.METHODS)
    yield
    for name in set(methods.METHODS) - rows:
        del methods._ROWS[name]
