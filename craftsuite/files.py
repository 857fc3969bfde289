"""Whole-file writes that a kill never leaves half done.

Every file CraftSuite writes whole (run records, logs rewritten on resume, models, replay
buffers, tables, the automaton cache, plots) is written beside its destination under a
temporary name, flushed to disk, then renamed over it with ``os.replace``: a reader, or a
run resumed after a kill, sees the old file or the new one, never a torn one.

* ``atomic_write(path, data)``: text or bytes held in memory;
* ``atomic_path(path)``: a context manager yielding the temporary path, for writers that
  take a path (``np.savez``, an agent's ``save``, ``save_replay_buffer``, matplotlib's
  ``savefig``).
"""

from __future__ import annotations

import contextlib
import os
import secrets
from collections.abc import Iterator
from pathlib import Path


def _temporary(path: Path) -> Path:
    # Same directory (os.replace is atomic only within one file system); a random part keeps
    # two writers of one file apart (processes or threads); the suffix is kept last because some writers add theirs
    # when it is missing (SB3 appends ".zip" and ".pkl", numpy ".npz").
    return path.with_name(f".{path.stem}.{secrets.token_hex(6)}.tmp{path.suffix}")


def _fsync(path: Path) -> None:
    with open(path, "rb+") as f:
        os.fsync(f.fileno())


@contextlib.contextmanager
def atomic_path(path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; once the block ends without an error, the
    file written there replaces ``path``. On an error ``path`` is left as it was and the
    temporary file is removed."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _temporary(path)
    try:
        yield tmp
        if not tmp.is_file():
            raise FileNotFoundError(f"nothing was written to {tmp} (the temporary file for {path})")
        _fsync(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def atomic_write(path, data: str | bytes) -> None:
    """Write ``data`` (text or bytes) to ``path`` so that readers see the old file or the new one, never half."""
    with atomic_path(path) as tmp:
        if isinstance(data, bytes):
            tmp.write_bytes(data)
        else:
            tmp.write_text(data)
