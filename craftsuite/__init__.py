"""CraftSuite: LTLf tasks as grid and MuJoCo worlds for neuro-symbolic transfer RL.

Importing the package registers the gymnasium ids ``CraftSuite/<Task>-Grid<size>-v0``.
"""

from .rendering.gl import configure_gl

configure_gl()  # before anything imports mujoco

from .automata import Automaton, compile_ltlf  # noqa: E402
from .evaluation import Evaluation, evaluate  # noqa: E402
from .methods import Method, register_method  # noqa: E402
from .recorder import Recorder  # noqa: E402
from .registration import make_grid, make_vec, register_builtin, register_task, registered_ids  # noqa: E402
from .spec import SpecError, TaskSpec, load_spec  # noqa: E402
from .task_registry import ladder, resolve_task, tasks  # noqa: E402
from .wrappers import AutomatonObservation  # noqa: E402

__version__ = "0.1.0"
__all__ = [
    "Automaton", "AutomatonObservation", "Evaluation", "Recorder", "SpecError", "TaskSpec", "compile_ltlf",
    "evaluate", "ladder", "load_spec", "make_grid", "make_vec", "Method", "register_method", "register_task",
    "registered_ids", "resolve_task", "tasks",
]

register_builtin()
