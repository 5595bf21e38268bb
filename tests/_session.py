"""What the xdist workers of one test session share: a folder and locks in it."""

from __future__ import annotations

import contextlib
import fcntl
import os
from pathlib import Path


def session_folder(tmp_path_factory) -> Path:
    """The temporary folder common to every worker of this session (each worker's own basetemp is a
    subfolder of it under pytest-xdist; without xdist, the session's basetemp)."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@contextlib.contextmanager
def session_lock(tmp_path_factory, name: str):
    """Hold the session-wide lock ``name``: one worker at a time runs the block; yields the common folder."""
    folder = session_folder(tmp_path_factory)
    with open(folder / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
        yield folder
