"""Whole-file writes that a kill never leaves half done.

Every file CraftSuite writes whole (run records, logs rewritten on resume, models, replay
buffers, tables, the automaton cache, plots) is written beside its destination under a
temporary name, flushed to disk, then renamed over it with ``os.replace``: a reader, or a
run resumed after a kill, sees the old file or the new one, never a torn one.

* ``atomic_write(path, data)``: text or bytes held in memory;
* ``atomic_path(path)``: a context manager yielding the temporary path, for writers that
  take a path (``np.savez``, an agent's ``save``, ``save_replay_buffer``, matplotlib's
  ``savefig``).

A command checks where it will write before it computes anything: ``file_to_write(path,
flag)`` and ``directory_to_write(path, flag)`` name the flag, the path, the problem and the
fix in one line (a directory given for a file, a file on the way, no permission). A file it
reads, given as a directory (a run's, most likely), is refused by ``file_to_read``, naming
the file in it to give.
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


def missing_folders(path) -> list[Path]:
    """The folders at and above ``path`` that do not exist yet, innermost first: those a
    writer about to make ``path`` would make (and may remove again, ``remove_empty``)."""
    path = Path(path)
    return [d for d in (path, *path.parents) if not d.exists()]


def remove_empty(folders: list[Path]) -> None:
    """Remove ``folders`` (innermost first) while each is empty: one that holds something,
    arrived meanwhile, stops it with the folders above it kept."""
    try:
        for folder in folders:
            folder.rmdir()
    except OSError:
        pass


@contextlib.contextmanager
def atomic_path(path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; once the block ends without an error, the
    file written there replaces ``path``. Its folders are made where missing. On an error
    ``path`` is left as it was, the temporary file is removed, and so are the folders made
    for it while they are empty (a writer that makes the same new folder at the same moment
    may find it gone: no caller writes into a new folder from two processes but the
    caches, automata's and references', which take a failed write as a miss)."""
    path = Path(path)
    made = missing_folders(path.parent)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _temporary(path)
    try:
        yield tmp
        if not tmp.is_file():
            raise FileNotFoundError(f"nothing was written to {tmp} (the temporary file for {path})")
        _fsync(tmp)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        remove_empty(made)
        raise
    finally:
        tmp.unlink(missing_ok=True)


def atomic_write(path, data: str | bytes) -> None:
    """Write ``data`` (text or bytes) to ``path`` so that readers see the old file or the new one, never half."""
    with atomic_path(path) as tmp:
        if isinstance(data, bytes):
            tmp.write_bytes(data)
        else:
            tmp.write_text(data)


def _nearest(path: Path) -> Path:
    """``path``, or its nearest ancestor that exists."""
    while not path.exists() and path != path.parent:
        path = path.parent
    return path


# where no path was given, in one voice: the command line's path flags and these checks
EMPTY_PATH = "is empty: give a path"


def _refuse_empty(given, flag: str) -> None:
    """An empty path is the working directory to Python, which no one passing ``""`` (or an
    unset variable) meant; nor is anything but a path one (pathlib's TypeError names no flag)."""
    if not isinstance(given, (str, os.PathLike)):
        raise TypeError(f"{flag} must be a path, got {given!r}")
    if not str(given).strip():
        raise ValueError(f"{flag} {EMPTY_PATH}")


def _check_writable_dir(path: Path, flag: str, given) -> None:
    """Raise naming ``flag`` where ``path`` (a directory to write in, or to make) cannot be one."""
    nearest = _nearest(path)
    if not nearest.is_dir():
        where = "is a file" if nearest == path else f"cannot be made: {nearest} is a file"
        raise NotADirectoryError(f"{flag} {given}: {path} {where}, not a directory; give a path whose every "
                                 "folder is a directory")
    if not os.access(nearest, os.W_OK | os.X_OK):
        raise PermissionError(f"{flag} {given}: {nearest} is not writable here; give a directory you can write in")


def directory_to_write(path, flag: str) -> Path:
    """``path`` as a directory a command writes into (made later, where missing), checked
    before anything is computed or written; nothing is made here.

    Args:
        path: the directory, as given.
        flag: the option or argument that gave it, e.g. ``--out``: every message names it.

    Raises:
        ValueError: ``path`` is empty.
        NotADirectoryError: ``path``, or a folder on its way, is a file.
        PermissionError: it, or the folder it would be made in, cannot be written.
    """
    _refuse_empty(path, flag)
    given = path
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise NotADirectoryError(f"{flag} {given} is a file, not a directory: give a directory to write in "
                                 "(it is made if missing)")
    _check_writable_dir(path, flag, given)
    return path


def file_to_write(path, flag: str, example: str) -> Path:
    """``path`` as a file a command writes whole (its folders made later, where missing),
    checked before anything is computed or written; nothing is made here.

    Args:
        path: the file, as given.
        flag: the option or argument that gave it, e.g. ``--page``: every message names it.
        example: a file name for the fix where a directory was given, e.g. ``results.md``.

    Raises:
        ValueError: ``path`` is empty.
        IsADirectoryError: ``path`` is a directory (or names one, ending in a separator).
        NotADirectoryError: a folder on its way is a file.
        PermissionError: the folder it goes in cannot be written.
    """
    _refuse_empty(path, flag)
    given = path
    path = Path(path)
    if path.is_dir() or str(given).endswith(("/", os.sep)):
        raise IsADirectoryError(f"{flag} {given} {'is' if path.is_dir() else 'names'} a directory, not a file: "
                                f"give the file to write, e.g. {path / example}")
    _check_writable_dir(path.parent, flag, given)
    return path


def file_to_read(path, what: str, names: tuple[str, ...]) -> Path:
    """``path`` as a file a command reads (a checkpoint, a table), refused where it is a
    directory: a run's directory, most likely, holding the file under one of ``names``.

    Raises:
        IsADirectoryError: ``path`` is a directory; the message gives the file in it to
            give (the first of ``names`` there, else the first of them), and says when it is there.
    """
    path = Path(path)
    if path.is_dir():
        inside = next((path / name for name in names if (path / name).is_file()), None)
        raise IsADirectoryError(f"{path} is a directory, not a {what}: give the {what} file, e.g. "
                                f"{inside or path / names[0]}" + (" (it is there)" if inside else ""))
    return path
