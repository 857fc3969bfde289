"""CraftSuite worlds."""

from .grid import ACTION_NAMES, GridWorldEnv

__all__ = ["GridWorldEnv", "ACTION_NAMES"]
