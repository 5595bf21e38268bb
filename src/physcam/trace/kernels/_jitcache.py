"""Where numba caches the compiled kernels, and when a cached kernel is fresh.

numba's own cache (``cache=True``) checks only the source file of the function it compiled:
a kernel whose constants come from another module (the column layout in :mod:`._layout`) would
load stale machine code after that module changed, and an upgrade that keeps file contents
but changes the package could do the same. physcam's locator keys every cache entry with a hash
of physcam's version and of all kernel sources (this package's ``.py`` files), so a cache written
by any other version or source is never used: it is recompiled and overwritten. Should a numba
release not accept the locator, the kernels are compiled without a disk cache (slow to start,
never stale) rather than cached under numba's weaker key.

Entries go to ``$NUMBA_CACHE_DIR`` when it is set (as numba's own caches), else to
``__pycache__/physcam-jit`` beside the kernels, or, where the package directory is not writable (a
system install), to the user cache (``$XDG_CACHE_HOME`` or ``~/.cache``, under ``physcam/jit``). The locator subclasses numba's cache
locator class (``numba.core.caching._CacheLocator``, the class ``NUMBA_CACHE_LOCATOR_CLASSES``
names; an internal of numba) and is registered ahead of numba's own, for functions defined in
this directory only: other numba users are unaffected.

numba reads a function's cache index, adds an entry and writes the index back without a lock
(``numba.core.caching.IndexDataCacheFile.save``), naming the new machine-code file after the entries it
read. Two processes compiling two variants of one kernel at once (a cold cache under a farm's or
``--workers``' processes) could both take the name ``.1.nbc``, and the index could then point one
variant's key at the other's machine code: wrong rays, silently. :func:`compile_lock` serialises
physcam's compiles and cache loads across processes (an exclusive ``flock`` on a file in the cache
folder; where there is no ``fcntl``, Windows, none): the second process waits, then loads what the
first compiled.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import sys

_HERE = os.path.dirname(os.path.abspath(__file__))
_installed = False
_stamp: str | None = None


def source_stamp() -> str:
    """sha256 of physcam's version and every kernel source file (sorted by name)."""
    global _stamp
    if _stamp is None:
        from ... import __version__

        h = hashlib.sha256(f"physcam {__version__}\n".encode())
        for name in sorted(os.listdir(_HERE)):
            if name.endswith(".py"):
                h.update(name.encode())
                with open(os.path.join(_HERE, name), "rb") as f:
                    h.update(hashlib.sha256(f.read()).digest())
        _stamp = h.hexdigest()
    return _stamp


def _user_dir() -> str:
    base = os.environ.get("NUMBA_CACHE_DIR") or os.environ.get("XDG_CACHE_HOME") or os.path.join(
        os.path.expanduser("~"), ".cache")
    tag = hashlib.sha1(_HERE.encode()).hexdigest()[:16]
    return os.path.join(base, "physcam", "jit", tag)


def _cache_dirs() -> list[str]:
    """Where entries go, in order of preference: ``$NUMBA_CACHE_DIR`` when set (numba's own rule: the
    user's choice comes first), else beside the kernels, else the user cache."""
    pkg = os.path.join(_HERE, "__pycache__", "physcam-jit")
    return [_user_dir(), pkg] if os.environ.get("NUMBA_CACHE_DIR") else [pkg, _user_dir()]


def _usable(path: str, create: bool) -> bool:
    """Whether numba's cache could be written in ``path``: it is a writable folder, or (``create``
    False) the nearest existing folder above it is writable; ``create`` makes the folder."""
    if create:
        try:
            os.makedirs(path, exist_ok=True)
        except OSError:
            return False
    probe = path
    while not os.path.exists(probe):
        parent = os.path.dirname(probe)
        if parent == probe:
            return False
        probe = parent
    return os.path.isdir(probe) and os.access(probe, os.W_OK | os.X_OK)


def cache_dir(create: bool = False) -> str | None:
    """The folder numba's cache of the kernels uses: the first of :func:`_cache_dirs` that can be
    written (the locator's own choice below); None if none can."""
    return next((d for d in _cache_dirs() if _usable(d, create)), None)


_warm: bool | None = None


def _marker() -> str:
    return f"physcam-compiled-{source_stamp()[:20]}"


def is_warm() -> bool:
    """Whether numba's disk cache holds kernels compiled from these sources: the marker
    :func:`mark_compiled` leaves in :func:`cache_dir` (looked up once per process, without importing
    numba or creating a folder). A marker whose kernels numba then cannot load (another CPU) costs a
    compile, never a wrong answer."""
    global _warm
    if _warm is None:
        d = cache_dir()
        _warm = d is not None and os.path.exists(os.path.join(d, _marker()))
    return _warm


def mark_compiled() -> None:
    """Leave the marker of :func:`is_warm` in :func:`cache_dir` (after a compile or a first load)."""
    global _warm
    d = cache_dir(create=True)
    if d is None:
        return
    try:
        with open(os.path.join(d, _marker()), "w") as f:
            f.write("numba's cache here holds physcam's kernels compiled from these sources\n")
    except OSError:
        return
    _warm = True


LOCK_NAME = "physcam-compile.lock"


@contextlib.contextmanager
def compile_lock():
    """Hold an exclusive lock on :func:`cache_dir` while a kernel compiles or loads from numba's cache
    (module notes: numba's index is read, extended and written without one). Blocks while another
    process holds it; no lock where the folder cannot be written, its file system refuses locks (an NFS
    mount without them) or there is no ``fcntl``."""
    try:
        import fcntl
    except ImportError:  # Windows
        fcntl = None
    d = cache_dir(create=True)
    fd = None
    if fcntl is not None and d is not None:
        try:
            fd = os.open(os.path.join(d, LOCK_NAME), os.O_RDWR | os.O_CREAT, 0o666)
            fcntl.flock(fd, fcntl.LOCK_EX)
        except OSError:
            if fd is not None:
                os.close(fd)
            fd = None
    try:
        yield
    finally:
        if fd is not None:
            os.close(fd)  # closing the descriptor releases the lock


def install() -> bool:
    """Register the locator with numba (idempotent; call before the kernels are defined).
    Returns False where this numba does not take it (then do not cache)."""
    global _installed
    if _installed:
        return True
    try:
        _register()
    except Exception:  # noqa: BLE001 - another numba: compile without the disk cache instead
        return False
    _installed = True
    return True


def _register() -> None:
    from numba.core import caching, config

    if getattr(config, "CACHE_LOCATOR_CLASSES", None):  # the user's locators replace ours: no cache
        raise RuntimeError("NUMBA_CACHE_LOCATOR_CLASSES is set")

    class PhysCamLocator(caching._CacheLocator):
        def __init__(self, py_func, py_file, path):
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            self._path = path

        def get_cache_path(self):
            return self._path

        def get_source_stamp(self):
            return source_stamp()

        def get_disambiguator(self):
            return str(self._lineno)

        @classmethod
        def from_function(cls, py_func, py_file):
            if os.path.dirname(os.path.abspath(py_file)) != _HERE:
                return None
            path = cache_dir(create=True)
            return None if path is None else cls(py_func, py_file, path)

    caching.CacheImpl._locator_classes.insert(0, PhysCamLocator)
    sys.modules[__name__].PhysCamLocator = PhysCamLocator
