"""Pictures of CraftSuite worlds: grid frames, the status panel shared by every world."""

from .panel import hex_to_rgb, status_panel

__all__ = ["hex_to_rgb", "status_panel"]
