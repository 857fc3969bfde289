"""What every CraftSuite world shares: its task, rules, objective tracker and their views."""

from __future__ import annotations

import gymnasium as gym

from ..task_registry import resolve_task
from ..rules import Rules
from ..spec import TaskSpec
from ..tracking import ObjectiveTracker


class CraftWorld(gym.Env):
    """Base of the grid and MuJoCo worlds. Subclasses lay out the world and move the agent;
    touching objects goes through ``self.rules``, labels through ``self.labeller`` and the
    objective through ``self.tracker``."""

    def __init__(self, task: str | TaskSpec, render_mode: str | None, status_panel: bool = False):
        if not isinstance(status_panel, bool):
            raise ValueError(f"status_panel must be True or False, got {status_panel!r}")
        self.task = resolve_task(task)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode {render_mode!r} is not supported; use one of {self.metadata['render_modes']}"
            )
        self.render_mode = render_mode
        # the inventory and automaton state drawn under each frame: for people, never for
        # agents that learn from pixels, hence off unless asked for
        self.status_panel = status_panel
        self.rules = Rules(self.task)
        self.tracker = ObjectiveTracker(self.task)
        self.automaton = self.tracker.automaton
        self.labeller = self.tracker.labeller
        self.inventory_counts = self.rules.new_inventory()

    @property
    def automaton_state(self) -> int:
        return self.tracker.state

    @property
    def inventory(self) -> dict[str, int]:
        return dict(zip(self.rules.inventory_names, self.inventory_counts))

    def _can_render(self, started: bool) -> bool:
        """Whether ``render()`` has a frame to draw: False (with gymnasium's warning) without
        a render mode; before the first ``reset`` (``started`` False), a RuntimeError."""
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode= to make()")
            return False
        if not started:
            raise RuntimeError("call reset() before render()")
        return True
