"""Files written safely: atomically, and never over an existing file unless asked.

Every writer in physcam goes through :func:`atomic_write` (or :func:`staged`, for a library
that writes the file itself) so a crash leaves either the old file or the new one, never half
of one.

The temporary file is hidden next to the target and named for it, this host and this process:
``.<target>.physcam-tmp.<host>.<pid>.<random><suffix>``. A process killed mid-write (SIGKILL,
power loss) leaves its temporary behind; the next write of the same target removes those of
processes on this host that no longer run (:func:`remove_stale_temporaries`). Temporaries of
running processes, and of other hosts sharing the folder (whose processes cannot be seen from
here), are left alone.

Renaming over a name replaces whatever it names, so a device, FIFO or socket is never a target
(:func:`check_writable` refuses it, ``force`` or not); the null device and this process's standard
output and error are written through instead. :func:`refuse_inputs_as_outputs` keeps a command from
writing over a file it reads, and :func:`staged_folder` writes a folder of outputs as a whole.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import stat
from pathlib import Path

# ctypes, hashlib, secrets, shutil, socket and tempfile are imported where they are used: every command
# imports this module, and one that writes nothing would pay 0.01-0.02 s of CPU for them (issue 47)

from .errors import ExportError

__all__ = ["atomic_write", "check_writable", "folder_manifest", "refuse_inputs_as_outputs", "remove_stale_temporaries",
           "staged", "staged_folder", "MANIFEST_NAME"]

#: What marks a physcam temporary file's name, after the hidden target name.
TEMP_MARK = ".physcam-tmp."
#: A target name longer than this (bytes) is shortened in its temporary's name (start and a hash),
#: so that the temporary stays within the file system's 255-byte limit.
_TEMP_NAME_BYTES = 120


_SPECIAL = ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
            (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"))


def _through_fd(p: Path) -> int | None:
    """The file descriptor to write ``p`` through, when ``p`` is a target physcam writes into rather
    than replaces: this process's standard output or error (``/dev/stdout``, ``/dev/fd/2``, or the
    file, pipe or terminal they are), or the null device (same device numbers as ``os.devnull``,
    wherever its node lives): -1 for the null device (opened when written). None for any other path."""
    try:
        st = os.stat(p)
    except (OSError, ValueError):
        return None
    for fd in (1, 2):
        try:
            if os.path.samestat(st, os.fstat(fd)):
                return fd
        except OSError:
            pass
    try:
        null = os.stat(os.devnull)
    except OSError:
        return None
    if stat.S_ISCHR(st.st_mode) and stat.S_ISCHR(null.st_mode) and st.st_rdev == null.st_rdev:
        return -1
    return None


def _refuse_special(p: Path) -> None:
    """:class:`ExportError` when ``p`` exists and is a device, FIFO or socket (symbolic links
    followed) that physcam would otherwise replace by renaming a file over it."""
    try:
        mode = os.stat(p).st_mode
    except (OSError, ValueError):
        return
    for test, what in _SPECIAL:
        if test(mode):
            raise ExportError(f"{p} is {what}, not a regular file: physcam writes a file whole and renames it into "
                              "place, which would replace it; write to a regular file (or /dev/null, or /dev/stdout "
                              "for standard output)")


def _refuse_file_in_folder(p: Path) -> None:
    """:class:`ExportError` when the nearest existing part of ``p``'s folder is a file: the write would fail
    there (:func:`_make_folder`), and a command checking its output first says so before its work."""
    for part in (p.parent, *p.parent.parents):
        try:
            mode = os.stat(part).st_mode
        except (FileNotFoundError, NotADirectoryError):  # not there yet (made on writing), or under a file
            continue
        except (OSError, ValueError):
            return
        if not stat.S_ISDIR(mode):
            raise ExportError(f"cannot write {p}: a part of its folder {part} is a file, not a folder")
        return


def check_writable(path, *, force: bool = False) -> Path:
    """Return ``path`` as a Path; raise :class:`ExportError` if it exists and ``force`` is false, or if a
    part of its folder that exists is a file.

    A device, FIFO or socket is refused even with ``force`` (renaming a file over it would replace
    it), except the targets written through, never replaced and needing no ``force``: the null
    device and this process's standard output or error (``/dev/null``, ``/dev/stdout``)."""
    p = Path(path)
    if _through_fd(p) is not None:
        return p
    _refuse_special(p)
    _refuse_file_in_folder(p)
    if p.exists() and not force:
        raise ExportError(f"{p} already exists; pass --force (in Python, force=True) to overwrite it")
    if p.exists() and p.is_dir():
        raise ExportError(f"{p} is a directory, not a file")
    return p


def _write_through(tmp: str, p: Path, fd: int) -> None:
    """Copy the finished temporary ``tmp`` into ``p`` through ``fd`` (:func:`_through_fd`): standard
    output or error after Python's own buffer of it, at the stream's place; the null device opened."""
    import sys

    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, OSError, ValueError):
            stream.flush()
    own = fd < 0
    if own:
        fd = os.open(p, os.O_WRONLY)
    try:
        with open(tmp, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                view = memoryview(block)
                while view:
                    view = view[os.write(fd, view):]
    finally:
        if own:
            os.close(fd)


@contextlib.contextmanager
def _staged_through(p: Path, fd: int, suffix: str):
    """:func:`staged` for a target written through: the temporary lives in the system's temporary folder."""
    import tempfile

    handle, tmp = tempfile.mkstemp(prefix=".physcam-tmp.", suffix=suffix)
    os.close(handle)
    try:
        yield Path(tmp)
        _write_through(tmp, p, fd)
    except OSError as exc:
        if isinstance(exc, BrokenPipeError):
            raise  # a reader that has gone: the CLI's quiet exit
        raise ExportError(f"cannot write {p}: {exc.strerror or exc}") from None
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)


def refuse_inputs_as_outputs(inputs, outputs, *, folders=()) -> None:
    """Raise :class:`ExportError` in one line when an output would overwrite an input.

    ``outputs`` (files) and ``folders`` (outputs written whole, :func:`staged_folder`) may not be an
    input: the same file or folder by ``os.stat`` identity (device and inode), so a symbolic link to
    the input, a hard link of it and another spelling of its path all count; nor may an input lie
    inside one of ``folders``, which the write replaces. Paths are str or Path (None and "" skipped);
    an input that does not exist is skipped (a bundled lens's name is not a file)."""
    ins = []
    for i in inputs:
        if i is None or (isinstance(i, str) and not i):
            continue
        try:
            ins.append((Path(i), os.stat(i), os.path.realpath(i)))
        except (OSError, ValueError, TypeError):
            continue
    for o, whole in [(o, False) for o in outputs] + [(f, True) for f in folders]:
        if o is None or (isinstance(o, str) and not o) or _through_fd(Path(o)) is not None:
            continue  # /dev/null and standard output are written through, never replaced
        try:
            so = os.stat(o)
        except (OSError, ValueError, TypeError):
            so = None
        try:
            inside = os.path.realpath(o).rstrip(os.sep) + os.sep
        except (OSError, ValueError, TypeError):
            continue
        for pi, si, ri in ins:
            if so is not None and os.path.samestat(si, so):
                raise ExportError(f"the output {o} is the input {pi} (the same file): writing it would destroy the "
                                  "input; choose another output")
            if whole and ri.startswith(inside):
                raise ExportError(f"the input {pi} lies inside the output folder {o}, which is written whole "
                                  "(replaced with --force): choose another output folder")


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _exists_error(p: Path) -> ExportError:
    return ExportError(f"{p} already exists; pass --force (in Python, force=True) to overwrite it")


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


def _host() -> str:
    """This machine's name as it goes into a temporary's name (letters, digits, - and _)."""
    import socket

    return re.sub(r"[^A-Za-z0-9_-]", "-", socket.gethostname() or "host")[:64]


def _temp_prefix(p: Path) -> str:
    """``.<target>.physcam-tmp.``: what every temporary of target ``p`` starts with."""
    name = p.name
    raw = name.encode("utf-8", "surrogateescape")
    if len(raw) > _TEMP_NAME_BYTES:
        import hashlib

        digest = hashlib.sha1(raw).hexdigest()[:12]
        name = raw[:60].decode("utf-8", "ignore") + "~" + digest
    return f".{name}{TEMP_MARK}"


def _running(pid: int) -> bool:
    """Whether process ``pid`` exists on this host (signal 0 checks without sending anything)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return pid > 0  # another user's process: running
    return True


def remove_stale_temporaries(path) -> list[Path]:
    """Remove the temporaries of ``path`` that processes of this host left when killed mid-write;
    return them. Those of running processes and of other hosts are kept."""
    p = Path(path)
    prefix, host, removed = _temp_prefix(p), _host(), []
    try:
        entries = list(os.scandir(p.parent if str(p.parent) else "."))
    except OSError:
        return removed
    for entry in entries:
        if not entry.name.startswith(prefix):
            continue
        parts = entry.name[len(prefix):].split(".")
        if len(parts) < 3 or parts[0] != host or not parts[1].isdigit() or _running(int(parts[1])):
            continue
        try:
            if entry.is_file(follow_symlinks=False):
                os.unlink(entry.path)
                removed.append(Path(entry.path))
        except OSError:  # gone already (another writer cleaned it) or not ours to remove
            pass
    return removed


def _new_temporary(p: Path, suffix: str) -> str:
    """Create (exclusively, mode 0600) a fresh temporary for ``p`` in its folder; return its path."""
    import secrets

    name = f"{_temp_prefix(p)}{_host()}.{os.getpid()}.{secrets.token_hex(4)}{suffix}"
    tmp = os.path.join(p.parent, name)
    os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
    return tmp


def _make_folder(p: Path) -> None:
    try:
        p.parent.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        raise ExportError(f"cannot write {p}: a part of its folder {p.parent} is a file, not a folder") from None


@contextlib.contextmanager
def staged(path, *, force: bool = False, suffix: str = ".tmp"):
    """Write a file in place atomically: yields a temporary path (ending in ``suffix``, for
    libraries that pick a format by extension) next to ``path``; fill it, and on leaving the
    block it is synced and renamed to ``path`` (see :func:`atomic_write` for ``force``). On an
    error the temporary is removed; stale temporaries of ``path`` are removed first (module notes).
    A device, FIFO or socket is never renamed over (:func:`check_writable`); the null device and
    standard output or error get the finished temporary's bytes written through."""
    p = check_writable(path, force=force)
    fd = _through_fd(p)
    if fd is not None:
        with _staged_through(p, fd, suffix) as tmp:
            yield tmp
        return
    try:
        _make_folder(p)
        remove_stale_temporaries(p)
        tmp = _new_temporary(p, suffix)
    except OSError as exc:
        raise ExportError(f"cannot write {p}: {exc.strerror or exc}") from None
    try:
        yield Path(tmp)
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        # the temporary is private (0600); give it the mode a plain open() would (0666 less the
        # umask), or keep the mode of the file it replaces
        replaced = force and p.exists()
        os.chmod(tmp, (os.stat(p).st_mode & 0o7777) if replaced else (0o666 & ~_umask()))
        if force:
            _refuse_special(p)  # made meanwhile: never renamed over
            os.replace(tmp, p)
        else:
            _publish_new(tmp, p)
    except OSError as exc:
        raise ExportError(f"cannot write {p}: {exc.strerror or exc}") from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def atomic_write(path, data: bytes | str, *, force: bool = False, encoding: str = "utf-8") -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder, then rename.

    Creates missing parent folders. Raises :class:`ExportError` when ``path`` exists and
    ``force`` is false (checked before writing, and again atomically when the file is put in
    place, so of several writers racing for one new name exactly one succeeds), or when the
    folder cannot be written. Temporaries a killed writer left for ``path`` are removed (module notes).
    """
    if isinstance(data, str):
        data = data.encode(encoding)
    with staged(path, force=force) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
    return Path(path)


# ---- a folder of outputs written as a whole ---------------------------------------------------

#: The file :func:`staged_folder` writes last into every folder it publishes: what the folder holds.
MANIFEST_NAME = "physcam-manifest.json"
_MANIFEST_FORMAT = "physcam-manifest/1"


def _renameat2(src: str, dst: str, flags: int) -> bool:
    """Linux renameat2(2): ``flags`` 1 = RENAME_NOREPLACE, 2 = RENAME_EXCHANGE. False where the
    call does not exist (not Linux, old C library, a file system without it); OSError on failure."""
    import ctypes

    try:
        call = ctypes.CDLL(None, use_errno=True).renameat2
    except (AttributeError, OSError):
        return False
    at_fdcwd = -100
    if call(at_fdcwd, os.fsencode(src), at_fdcwd, os.fsencode(dst), flags) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP, errno.EOPNOTSUPP):
        return False
    raise OSError(err, os.strerror(err), dst)


def _file_digest(path: Path) -> str:
    import hashlib

    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _sync_tree(root: Path) -> list[dict]:
    """fsync every file and folder under ``root``; return the manifest's file entries."""
    entries = []
    for folder, _dirs, files in os.walk(root):
        for name in sorted(files):
            path = Path(folder, name)
            with open(path, "rb+") as fh:
                os.fsync(fh.fileno())
            entries.append({"path": path.relative_to(root).as_posix(), "bytes": path.stat().st_size,
                            "sha256": _file_digest(path)})
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
    return sorted(entries, key=lambda e: e["path"])


def folder_manifest(path) -> dict | None:
    """The manifest of a folder :func:`staged_folder` published, checked against what is on disk:
    the manifest's dict when every listed file is there with its size, else None (a folder that
    physcam did not write whole, or that was changed since)."""
    folder = Path(path)
    try:
        doc = json.loads((folder / MANIFEST_NAME).read_text(encoding="utf-8"))
        if doc.get("format") != _MANIFEST_FORMAT:
            return None
        for entry in doc["files"]:
            if (folder / entry["path"]).stat().st_size != entry["bytes"]:
                return None
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None
    return doc


def _replaceable(p: Path) -> bool:
    """Whether ``--force`` may replace folder ``p`` whole: it is empty, or physcam wrote it and it holds
    no file its manifest does not list (a file the user put there since is never deleted with it)."""
    try:
        if not any(p.iterdir()):
            return True
        doc = json.loads((p / MANIFEST_NAME).read_text(encoding="utf-8"))
        listed = {e["path"] for e in doc["files"]} | {MANIFEST_NAME}
        for folder, _dirs, files in os.walk(p):
            for name in files:
                if Path(folder, name).relative_to(p).as_posix() not in listed:
                    return False
        return True
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return False


def _empty_folder(p: Path) -> bool:
    """Whether ``p`` is an empty folder (not a symbolic link to one): written into without ``force``."""
    try:
        return not p.is_symlink() and p.is_dir() and not any(p.iterdir())
    except OSError:
        return False


def _not_ours_error(p: Path) -> ExportError:
    return ExportError(f"{p} holds files physcam did not write there; --force replaces only a folder "
                       f"physcam wrote whole (one with a {MANIFEST_NAME}) or an empty one: choose a new output folder")


def _publish_folder(tmp: Path, p: Path, force: bool) -> None:
    """Put the finished folder ``tmp`` at ``p`` in one rename (or one exchange, when replacing)."""
    import shutil

    if not (p.exists() or p.is_symlink()):
        if _renameat2(str(tmp), str(p), 1):
            return
        if p.exists():  # no renameat2: a plain rename would replace an empty folder made meanwhile
            raise _exists_error(p)
        os.rename(tmp, p)
        return
    if not force and not p.is_symlink() and p.is_dir():
        try:  # an empty folder is filled without force: rename(2) replaces an empty directory only
            os.rename(tmp, p)
            return
        except OSError as exc:
            if exc.errno not in (errno.ENOTEMPTY, errno.EEXIST):
                raise
        raise _exists_error(p)
    if not force:
        raise _exists_error(p)
    if p.is_symlink() or not p.is_dir():
        raise ExportError(f"{p} is not a folder; remove it or choose another output folder")
    if not _replaceable(p):
        raise _not_ours_error(p)
    old = Path(_new_temporary_name(p, ".old"))
    if _renameat2(str(tmp), str(p), 2):  # atomic swap: readers see the old folder or the new one
        shutil.rmtree(tmp, ignore_errors=True)
        return
    os.rename(p, old)
    os.rename(tmp, p)
    shutil.rmtree(old, ignore_errors=True)


def _new_temporary_name(p: Path, suffix: str) -> str:
    import secrets

    return os.path.join(p.parent, f"{_temp_prefix(p)}{_host()}.{os.getpid()}.{secrets.token_hex(4)}{suffix}")


def _remove_stale_folders(p: Path) -> None:
    """Remove the temporary folders of ``p`` that killed writers of this host left behind."""
    import shutil

    prefix, host = _temp_prefix(p), _host()
    try:
        entries = list(os.scandir(p.parent if str(p.parent) else "."))
    except OSError:
        return
    for entry in entries:
        parts = entry.name[len(prefix):].split(".") if entry.name.startswith(prefix) else []
        if (len(parts) >= 3 and parts[0] == host and parts[1].isdigit() and not _running(int(parts[1]))
                and entry.is_dir(follow_symlinks=False)):
            shutil.rmtree(entry.path, ignore_errors=True)


@contextlib.contextmanager
def staged_folder(path, *, force: bool = False, about: dict | None = None):
    """Write a folder of outputs as a whole: yields a private temporary folder next to ``path``;
    fill it, and on leaving the block every file is synced, ``physcam-manifest.json`` (each file's
    path, size and SHA-256, plus ``about``) is written last, and the folder is put at ``path`` in one
    rename. A writer killed at any moment leaves either the previous folder or the new one, never a
    mix (its temporary folder is removed by the next write of ``path``).

    An existing empty folder is filled without ``force`` (nothing is overwritten; the rename fails if
    files appear in it meanwhile). ``force`` replaces an existing folder only if physcam wrote it (it has
    a manifest) or it is empty, so a user's own files are never deleted; an error in the block removes
    the temporary folder.
    :func:`folder_manifest` tells whether a folder is complete.
    """
    import shutil

    p = Path(path)
    if (p.exists() or p.is_symlink()) and not force and not _empty_folder(p):
        raise _exists_error(p)
    if (p.exists() or p.is_symlink()) and (p.is_symlink() or not p.is_dir()):
        raise ExportError(f"{p} is not a folder; remove it or choose another output folder")  # before any work
    if p.is_dir() and not _replaceable(p):
        raise _not_ours_error(p)  # before any work is done
    try:
        _make_folder(p)
        _remove_stale_folders(p)
        tmp = Path(_new_temporary_name(p, ".d"))
        tmp.mkdir(mode=0o700)
    except OSError as exc:
        raise ExportError(f"cannot write {p}: {exc.strerror or exc}") from None
    try:
        yield tmp
        files = _sync_tree(tmp)
        if any(f["path"] == MANIFEST_NAME for f in files):
            raise ExportError(f"{MANIFEST_NAME} is physcam's own record of the folder; name the output otherwise")
        manifest = {"format": _MANIFEST_FORMAT, "about": about or {}, "files": files}
        text = json.dumps(manifest, indent=1, sort_keys=True, allow_nan=False) + "\n"
        with open(tmp / MANIFEST_NAME, "x", encoding="utf-8") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o777 & ~_umask())
        _publish_folder(tmp, p, force)
    except OSError as exc:
        raise ExportError(f"cannot write {p}: {exc.strerror or exc}") from None
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
