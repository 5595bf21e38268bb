"""Two processes never write numba's cache of physcam's kernels at once (:mod:`physcam.trace.kernels._jitcache`).

numba reads a function's cache index, adds an entry and writes it back without a lock, naming the new
machine-code file after what it read: two processes compiling two variants of the tracer at once (a cold
cache under a farm's workers) could leave one variant's key pointing at the other's code. physcam takes an
exclusive lock on the cache folder around a variant's first call (compile or load): here the test holds that
lock, and a fresh process's first JIT trace waits for it, then traces (loading the suite's warm cache)."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

pytest.importorskip("numba")

CHILD = """
import sys
import numpy as np
from physcam.lens.library import load_lens
from physcam.trace import RayBatch, trace_through
lens = load_lens("dgauss_50mm")
rays = RayBatch.collimated(np.linspace(0.0, 5.0, 64), np.zeros(64), -1.0)
print("ready", flush=True)
out = trace_through(lens, rays, backend="numba", end_z=100.0)
print("traced", int(out.x.shape[0]), flush=True)
"""


def test_a_first_jit_call_waits_for_another_process_compiling():
    from physcam.trace.kernels import _jitcache

    assert _jitcache.cache_dir(create=True) is not None  # the suite's cache folder, writable
    with _jitcache.compile_lock():
        p = subprocess.Popen([sys.executable, "-c", CHILD], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            assert p.stdout.readline().strip() == "ready"
            time.sleep(2.5)  # loading a cached variant takes ~0.3 s: unlocked, the child would be done
            assert p.poll() is None, p.stderr.read()
        except BaseException:
            p.kill()
            raise
    out, err = p.communicate(timeout=300)
    assert p.returncode == 0, err
    assert out.split() == ["traced", "64"]


def test_the_lock_is_released_after_the_block_and_on_error(tmp_path, monkeypatch):
    """The lock is one ``flock`` on a file of the cache folder, released when the block ends, an error
    included: another descriptor takes it at once without waiting (``LOCK_NB``)."""
    fcntl = pytest.importorskip("fcntl")
    from physcam.trace.kernels import _jitcache

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    lock = tmp_path.joinpath(_jitcache.cache_dir(create=True), _jitcache.LOCK_NAME)

    def free() -> bool:
        fd = os.open(lock, os.O_RDWR)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return True
        except BlockingIOError:
            return False
        finally:
            os.close(fd)

    with _jitcache.compile_lock():
        assert lock.is_relative_to(tmp_path) and not free()
    assert free()
    with pytest.raises(RuntimeError):
        with _jitcache.compile_lock():
            raise RuntimeError("a compile failing")
    assert free()


def test_a_file_system_without_locks_compiles_unlocked(tmp_path, monkeypatch):
    """Where ``flock`` fails (an NFS mount without locks: ENOLCK), the compile goes on without the lock rather
    than failing the trace."""
    import errno

    fcntl = pytest.importorskip("fcntl")
    from physcam.trace.kernels import _jitcache

    def refuse(fd, op):
        raise OSError(errno.ENOLCK, "No locks available")

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(fcntl, "flock", refuse)
    ran = []
    with _jitcache.compile_lock():
        ran.append(True)
    assert ran == [True]
