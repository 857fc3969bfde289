"""The id format: what builds an id reads it back; bad tasks and worlds are never built into one."""

from __future__ import annotations

import pytest

import craftsuite
from craftsuite import ids


@pytest.mark.parametrize("task, world", [("Reach", "Grid7"), ("BlindCraftsman", "Grid10"), ("A1", "Cont")])
def test_an_id_reads_back_as_what_built_it(task, world):
    env_id = ids.env_id(task, world)
    assert env_id == f"{ids.NAMESPACE}/{task}-{world}-{ids.VERSION}"
    assert ids.parse_id(env_id) == (task, world)
    assert ids.file_stem(env_id) == env_id.split("/")[1]


def test_grid_and_cont_ids_are_env_ids():
    assert ids.grid_id("Reach", 10) == ids.env_id("Reach", "Grid10")
    assert ids.cont_id("Reach") == ids.env_id("Reach", "Cont")
    assert ids.grid_size(ids.grid_world(12)) == 12
    assert [ids.world_kind(w) for w in ("Grid7", "Grid10", "Cont")] == ["Grid", "Grid", "Cont"]


@pytest.mark.parametrize("bad", ["Reach-Grid7-v0", "Other/Reach-Grid7-v0", "CraftSuite/Reach-Grid7-v1",
                                 "CraftSuite/Reach-Cube-v0", "CraftSuite/reach-Cont-v0", "CraftSuite/A-B-Cont-v0",
                                 "CraftSuite//tmp/x.toml-Grid7-v0", "", None])
def test_what_is_no_id_is_a_clear_error(bad):
    with pytest.raises(ValueError, match="is not a CraftSuite id .*CraftSuite/<Task>-<World>-v0"):
        ids.parse_id(bad)


@pytest.mark.parametrize("task, world, problem", [
    ("/tmp/x.toml", "Grid7", "is not a task name"), ("reach", "Cont", "is not a task name"),
    ("Reach", "Grid0", "unknown world"), ("Reach", "Mujoco", "unknown world"), ("Reach", "Grid", "unknown world"),
])
def test_an_id_of_a_bad_task_or_world_is_never_built(task, world, problem):
    with pytest.raises(ValueError, match=problem):
        ids.env_id(task, world)


def test_every_registered_id_parses_to_a_known_task_and_world():
    for env_id in craftsuite.registered_ids():
        task, world = ids.parse_id(env_id)
        assert task in craftsuite.tasks() and ids.world_kind(world) in ids.WORLD_KINDS

