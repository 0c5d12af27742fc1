"""Run directories: checked and made ready before a run starts, so nothing is lost later."""

from __future__ import annotations

import re
import shutil
import tempfile
from pathlib import Path

from dcsim.errors import DcsimError

RUN_FILES = ("scenario.yaml", "summary.json", "telemetry.csv", "events.jsonl")
"""The files that mark a folder as a run directory."""


class RunDirectoryError(DcsimError):
    """A run directory cannot be used: it cannot be created or written, or holds a run."""


def prepare_run_directory(path: Path, force: bool = False) -> Path:
    """Create (or, with ``force``, empty) the run directory ``path`` and check it is writable.

    Parameters
    ----------
    path : Path
        The run directory.
    force : bool
        Replace an existing run directory (or any non-empty folder) at ``path``.

    Returns
    -------
    Path
        ``path``, existing, empty and writable.

    Raises
    ------
    RunDirectoryError
        If a file is in the way, the folder holds a run (without ``force``), or it
        cannot be created or written.
    """
    for parent in (path, *path.parents):
        if parent.exists() and not parent.is_dir():
            raise RunDirectoryError(f"cannot use {path} as a run directory: {parent} is a file")
    if path.is_dir() and any(path.iterdir()):
        if not force:
            what = "holds a run" if any((path / f).exists() for f in RUN_FILES) else "is not empty"
            raise RunDirectoryError(
                f"{path} {what}; choose another --out or add --force to replace it"
            )
        _empty(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError as error:
        raise RunDirectoryError(
            f"cannot write the run directory {path}: {_reason(error)}"
        ) from None
    return path


def file_name_part(name: str) -> str:
    """``name`` made safe inside a file name: no separators or control characters, short."""
    return re.sub(r"[\x00-\x1f\x7f/\\]", "_", name)[:50]


def _empty(path: Path) -> None:
    """Remove everything inside ``path``."""
    try:
        for child in path.iterdir():
            if child.is_dir() and not child.is_symlink():
                shutil.rmtree(child)
            else:
                child.unlink()
    except OSError as error:
        raise RunDirectoryError(f"cannot replace {path}: {_reason(error)}") from None


def _reason(error: OSError) -> str:
    return error.strerror or str(error)
