"""The one place that decides MuJoCo's OpenGL backend (``MUJOCO_GL``).

MuJoCo (and dm_control) read ``MUJOCO_GL`` when they are imported, so ``craftsuite``
calls ``configure_gl()`` on import, before anything imports mujoco. Rules: a
``MUJOCO_GL`` the user set wins; else ``CRAFTSUITE_GL`` (e.g. ``egl`` on a GPU machine);
else ``glfw`` when a display exists and OSMesa (software, ``libosmesa6``) when none does.
"""

from __future__ import annotations

import os
import sys


def configure_gl() -> str:
    backend = os.environ.get("MUJOCO_GL")
    if backend:
        return backend
    backend = os.environ.get("CRAFTSUITE_GL") or ("glfw" if os.environ.get("DISPLAY") else "osmesa")
    if "mujoco" in sys.modules:  # too late to choose: leave mujoco's own choice alone
        return backend
    os.environ["MUJOCO_GL"] = backend
    if backend in ("osmesa", "egl"):
        os.environ.setdefault("PYOPENGL_PLATFORM", backend)
    return backend


def gl_error_hint(err: Exception) -> str:
    backend = os.environ.get("MUJOCO_GL", "?")
    return (
        f"MuJoCo could not start an off-screen OpenGL context (MUJOCO_GL={backend}): {err}. "
        "Install libosmesa6 (Debian) for software rendering, or set MUJOCO_GL=egl on a GPU "
        "machine; MUJOCO_GL must be set before mujoco is first imported."
    )
