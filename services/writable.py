"""Where a command may write: ``--out`` folders and output files checked before any work
starts, so that a bad path is one line and exit status 2, never a traceback after minutes.
"""

from __future__ import annotations

import os
from pathlib import Path

SYSTEM_TREES = (Path("/proc"), Path("/sys"), Path("/dev"))
"""Kernel file systems: a file written there is not a file (or fails halfway)."""


class PathError(ValueError):
    """A path a command cannot write to; the message is the one-line reason."""


def _common_checks(path: Path) -> Path:
    absolute = Path(os.path.abspath(path))
    for tree in SYSTEM_TREES:
        if absolute == tree or tree in absolute.parents:
            raise PathError(f"{path}: under {tree}, which is not a place for output")
    for parent in reversed(absolute.parents):
        if parent.exists() and not parent.is_dir():
            raise PathError(f"{path}: {parent} is a file, not a folder")
    return absolute


def _make_folder(path: Path, shown: Path) -> None:
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise PathError(f"{shown}: cannot create the folder ({exc.strerror or exc})") from None
    if not os.access(path, os.W_OK | os.X_OK):
        raise PathError(f"{shown}: the folder is not writable")


def check_output_dir(path: Path, create: bool = True) -> Path:
    """Make ``path`` a writable folder (creating it and its parents); PathError if it
    cannot be one. ``create=False``: only check that it could be made, creating nothing
    (a command whose other input may still be refused)."""
    absolute = _common_checks(path)
    if absolute.exists() and not absolute.is_dir():
        raise PathError(f"{path}: exists and is not a folder")
    if create:
        _make_folder(absolute, path)
        return path
    existing = next(p for p in (absolute, *absolute.parents) if p.exists())
    if not os.access(existing, os.W_OK | os.X_OK):
        what = "folder is" if existing == absolute else f"folder {existing} is"
        raise PathError(f"{path}: the {what} not writable")
    return path


def check_output_file(path: Path) -> Path:
    """Make sure ``path`` can be written as a file (creating its folder); PathError if
    not. An existing file is replaced."""
    absolute = _common_checks(path)
    if absolute.is_dir():
        raise PathError(f"{path}: is a folder, not a file")
    _make_folder(absolute.parent, path.parent)
    if absolute.exists() and not os.access(absolute, os.W_OK):
        raise PathError(f"{path}: the file is not writable")
    return path
