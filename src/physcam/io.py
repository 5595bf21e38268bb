"""Files written safely: atomically, and never over an existing file unless asked.

Every writer in physcam goes through :func:`atomic_write` so a crash leaves
either the old file or the new one, never half of one.
"""

from __future__ import annotations

import errno
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


def _exists_error(p: Path) -> ExportError:
    return ExportError(f"{p} already exists; pass --force (force=True) to overwrite it")


def _publish_new(tmp: str, p: Path) -> None:
    """Move the finished temporary file ``tmp`` to ``p`` only if ``p`` does not exist, atomically.

    A hard link fails with EEXIST when the name is taken, so of several processes creating the
    same new file exactly one wins (POSIX link(2)). Where the file system has no hard links, an
    exclusive create (O_EXCL) claims the name first and the rename fills it.
    """
    try:
        os.link(tmp, p)
    except FileExistsError:
        raise _exists_error(p) from None
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK):
            raise
        try:  # no hard links here: claim the name exclusively, then replace the empty claim
            os.close(os.open(p, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600))
        except FileExistsError:
            raise _exists_error(p) from None
        os.replace(tmp, p)
        return
    os.unlink(tmp)


def atomic_write(path, data: bytes | str, *, force: bool = False, encoding: str = "utf-8") -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder, then rename.

    Creates missing parent folders. Raises :class:`ExportError` when ``path`` exists and
    ``force`` is false (checked before writing, and again atomically when the file is put in
    place, so of several writers racing for one new name exactly one succeeds), or when the
    folder cannot be written.
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
            # mkstemp makes the file private (0600); give it the mode a plain open() would
            # (0666 less the umask), or keep the mode of the file it replaces
            replaced = force and p.exists()
            os.chmod(tmp, (os.stat(p).st_mode & 0o7777) if replaced else (0o666 & ~_umask()))
            if force:
                os.replace(tmp, p)
            else:
                _publish_new(tmp, p)
        except BaseException:
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise
    except OSError as exc:
        raise ExportError(f"cannot write {p}: {exc.strerror or exc}") from None
    return p
