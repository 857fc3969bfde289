"""CraftSuite worlds.

The names below load on first use: drawing code imports ``craftsuite.envs.cells`` (the
grid's cell codes and moves), and must not pull in the worlds, which import the drawing.
"""

__all__ = ["GridWorldEnv", "ACTION_NAMES"]


def __getattr__(name: str):
    if name == "GridWorldEnv":
        from .grid import GridWorldEnv
        return GridWorldEnv
    if name == "ACTION_NAMES":
        from .cells import ACTION_NAMES
        return ACTION_NAMES
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
