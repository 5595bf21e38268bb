"""Files written safely: atomically, and never over an existing file unless asked.

Every writer in physcam goes through :func:`atomic_write` so a crash leaves
either the old file or the new one, never half of one.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from .errors import ExportError

__all__ = ["atomic_write", "check_writable"]


def check_writable(path, *, force: bool = False) -> Path:
    """Return ``path`` as a Path; raise :class:`ExportError` if it exists and ``force`` is false."""
    p = Path(path)
    if p.exists() and not force:
        raise ExportError(f"{p} already exists; pass --force (force=True) to overwrite it")
    if p.exists() and p.is_dir():
        raise ExportError(f"{p} is a directory, not a file")
    return p


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write(path, data: bytes | str, *, force: bool = False, encoding: str = "utf-8") -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder, then rename.

    Creates missing parent folders. Raises :class:`ExportError` when ``path`` exists and
    ``force`` is false, or when the folder cannot be written.
    """
    p = check_writable(path, force=force)
    if isinstance(data, str):
        data = data.encode(encoding)
    try:
        p.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".tmp", dir=p.parent)
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
            if not force and p.exists():  # appeared while we wrote
                raise ExportError(f"{p} already exists; pass --force (force=True) to overwrite it")
            # mkstemp makes the file private (0600); give it the mode a plain open() would
            # (0666 less the umask), or keep the mode of the file it replaces
            os.chmod(tmp, (os.stat(p).st_mode & 0o7777) if p.exists() else (0o666 & ~_umask()))
            os.replace(tmp, p)
        except BaseException:
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise
    except OSError as exc:
        raise ExportError(f"cannot write {p}: {exc.strerror or exc}") from None
    return p
