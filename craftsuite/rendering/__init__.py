"""Pictures of CraftSuite worlds: grid frames, the status panel shared by every world."""

from .panel import PANEL_HEIGHT, add_status_panel, hex_to_rgb, status_panel

__all__ = ["PANEL_HEIGHT", "add_status_panel", "hex_to_rgb", "status_panel"]
