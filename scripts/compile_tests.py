"""Write pytest's assertion-rewritten bytecode of the test modules before the suite runs.

pytest rewrites the ``assert`` statements of every test module and ``conftest.py`` it imports and
caches the result in ``__pycache__/<name>.<tag>-pytest-<version>.pyc``, but only when Python may write
bytecode. CI sets ``PYTHONDONTWRITEBYTECODE``, so each xdist worker (and the ``usd-min`` run) parsed,
rewrote and compiled all of ``tests/`` again: about 14 s of a worker's 24 s collection. pytest reads
such a cache even when it may not write one, and checks it against the source's hash, so a stale or
foreign file is ignored, never used. The tests' own helper modules (``_blender.py``, ``_session.py``,
``tests/analysis/_*.py``), imported plainly by the workers and their subprocesses, get ordinary bytecode.

pytest rewrites its plugins' modules too (every distribution with a ``pytest11`` entry point: hypothesis,
xdist, anyio here): 111 modules in each pytest process (the controller, both workers, ``usd-min``'s, the
newest versions' three) under ``PYTHONDONTWRITEBYTECODE``, about 3 s of CPU each (collection 13.5 -> 10.5 s
of CPU), so their rewritten bytecode is written here as well, beside the installed plugin's sources.

Uses ``_pytest.assertion.rewrite``'s own rewriting and pyc writer (the pytest of constraints.txt); if a
pytest version lacks them this prints why and exits 0: the suite is then only slower, not different.
Run by ``make test-bytecode`` (and by ``make latest-run`` with the newest versions' Python).
"""

from __future__ import annotations

import fnmatch
import os
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

PATTERNS = ("test_*.py", "*_test.py", "conftest.py")  # pytest's python_files default and conftests


def _modules(root: Path) -> list[Path]:
    """Every Python file under ``root``: test modules and conftests rewritten, the rest compiled plainly."""
    return sorted(p for p in root.rglob("*.py") if "__pycache__" not in p.parts)


def _plugin_modules() -> list[Path]:
    """The Python files of every installed pytest plugin distribution (a ``pytest11`` entry point), which
    pytest rewrites as it imports them."""
    import importlib.metadata as md

    out = []
    for dist in md.distributions():
        if any(ep.group == "pytest11" for ep in dist.entry_points):
            out += [Path(dist.locate_file(f)) for f in dist.files or () if f.suffix == ".py"]
    return sorted(p for p in out if p.is_file())


def _compile_plugin(path: str) -> None:
    """A plugin module's rewritten bytecode; a file that does not compile (none here) is left to pytest."""
    try:
        _compile(path, rewrite=True)
    except (SyntaxError, ValueError, OSError):
        pass


def _compile(path: str, rewrite: bool | None = None) -> None:
    """Write ``path``'s bytecode: pytest's rewritten form for a test module or conftest (or when
    ``rewrite``), plain bytecode for the tests' other modules."""
    if rewrite is None:
        rewrite = any(fnmatch.fnmatch(os.path.basename(path), g) for g in PATTERNS)
    if not rewrite:
        import py_compile

        py_compile.compile(path, doraise=True)
        return
    from _pytest.assertion.rewrite import PYC_TAIL, _read_pyc, _rewrite_test, _write_pyc_fp, get_cache_dir

    fn = Path(path)
    pyc = get_cache_dir(fn) / (fn.name[:-3] + PYC_TAIL)
    if _read_pyc(fn, pyc) is not None:  # already current
        return
    source_hash, code = _rewrite_test(fn, None)
    pyc.parent.mkdir(exist_ok=True)
    tmp = pyc.with_name(f"{pyc.name}.{os.getpid()}")
    with open(tmp, "wb") as fp:
        _write_pyc_fp(fp, source_hash, code)
    os.replace(tmp, pyc)


def main() -> int:
    try:
        import _pytest.assertion.rewrite as rewrite

        for name in ("PYC_TAIL", "_read_pyc", "_rewrite_test", "_write_pyc_fp", "get_cache_dir"):
            getattr(rewrite, name)
    except (ImportError, AttributeError) as exc:
        print(f"compile_tests: pytest's rewriting is not reachable here ({exc}); the suite rewrites as it goes")
        return 0
    paths = [str(p) for p in _modules(Path(sys.argv[1] if len(sys.argv) > 1 else "tests"))]
    plugins = [str(p) for p in _plugin_modules()]
    with ProcessPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        list(pool.map(_compile, paths, chunksize=8))
        list(pool.map(_compile_plugin, plugins, chunksize=8))
    return 0


if __name__ == "__main__":
    sys.exit(main())
