"""MJCF scenes for the MuJoCo worlds, assembled in memory from ``assets/arena.xml``.

One scene per task: the arena sized to ``spec.continuous.arena``, four boundary walls,
the task's obstacles as solid boxes (grid cells of the largest grid size, scaled to the
arena), and one non-colliding body per object instance: items as small cubes, places as
large flat tiles, in the spec's colours. Positions are placeholders; each episode writes
its own into ``model.body_pos`` (no recompilation per reset).
"""

from __future__ import annotations

from dataclasses import dataclass

from dm_control import mjcf

from ..paths import assets_dir
from ..rendering.panel import hex_to_rgb
from ..spec import TaskSpec
from .planar import obstacle_boxes

WALL_THICKNESS = 0.1
AGENT_HALF = 0.15
ITEM_HALF = 0.12
PLACE_HALF = 0.25


@dataclass(frozen=True)
class Scene:
    xml: str
    object_bodies: tuple[str, ...]  # body names, spec order, one per instance
    object_kinds: tuple[int, ...]
    obstacles: tuple[tuple[float, float, float], ...]  # (x, y, half side) of solid boxes


def _rgba(color: str) -> list[float]:
    return [c / 255 for c in hex_to_rgb(color)] + [1.0]


_SCENES: dict[int, tuple[TaskSpec, Scene]] = {}  # by id(spec); the spec is kept alive with it


def build_scene(spec: TaskSpec) -> Scene:
    """The task's scene, built once per spec object (specs hold dicts: not hashable)."""
    cached = _SCENES.get(id(spec))
    if cached is None or cached[0] is not spec:
        cached = _SCENES[id(spec)] = (spec, _build(spec))
    return cached[1]


def _build(spec: TaskSpec) -> Scene:
    root = mjcf.from_path(str(assets_dir() / "arena.xml"))
    half = spec.continuous.arena / 2
    root.find("geom", "floor").size = [half, half, 0.1]
    camera = root.find("camera", "top")
    camera.fovy = spec.continuous.arena + 4 * WALL_THICKNESS  # orthographic: the extent in metres
    wall_rgba = [0.35, 0.38, 0.45, 1]
    for name, pos, size in (
        ("wall_east", [half + WALL_THICKNESS, 0, 0.2], [WALL_THICKNESS, half + 2 * WALL_THICKNESS, 0.2]),
        ("wall_west", [-half - WALL_THICKNESS, 0, 0.2], [WALL_THICKNESS, half + 2 * WALL_THICKNESS, 0.2]),
        ("wall_north", [0, half + WALL_THICKNESS, 0.2], [half, WALL_THICKNESS, 0.2]),
        ("wall_south", [0, -half - WALL_THICKNESS, 0.2], [half, WALL_THICKNESS, 0.2]),
    ):
        root.worldbody.add("geom", name=name, type="box", pos=pos, size=size, rgba=wall_rgba)
    obstacles = obstacle_boxes(spec)
    for i, (x, y, h) in enumerate(obstacles):
        root.worldbody.add("geom", name=f"obstacle{i}", type="box", pos=[x, y, 0.2],
                           size=[h, h, 0.2], rgba=[0.24, 0.35, 0.59, 1])
    bodies, kinds = [], []
    n_items = len(spec.items)
    for kind, obj in enumerate(spec.objects):
        place = kind >= n_items
        for j in range(obj.count):
            name = f"{obj.name}{j}"
            body = root.worldbody.add("body", name=name, pos=[0, 0, -1])
            if place:
                body.add("geom", name=name, dclass="object", type="box",
                         size=[PLACE_HALF, PLACE_HALF, 0.02], pos=[0, 0, 0.02], rgba=_rgba(obj.color))
            else:
                body.add("geom", name=name, dclass="object", type="box",
                         size=[ITEM_HALF, ITEM_HALF, ITEM_HALF], pos=[0, 0, ITEM_HALF], rgba=_rgba(obj.color))
            bodies.append(name)
            kinds.append(kind)
    return Scene(xml=root.to_xml_string(), object_bodies=tuple(bodies),
                 object_kinds=tuple(kinds), obstacles=obstacles)
