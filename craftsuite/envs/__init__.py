"""CraftSuite worlds: ``grid``, ``continuous``, ``kinematic`` (and their vector forms); the grid's
cell codes and moves in ``cells``.

The package imports nothing itself: drawing code imports ``craftsuite.envs.cells``, and must not
pull in the worlds, which import the drawing.
"""
