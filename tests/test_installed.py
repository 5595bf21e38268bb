"""physcam as a studio installs it: the wheel and sdist built from this tree, the wheel installed
into a fresh virtual environment in a temporary folder (no source tree on the path, no physcam
environment variables), first alone (the light core), then with every extra (issue 26).

It needs pip to reach the package index (CI does; the versions come from constraints.txt). The core
wheel goes in with pip; the extras with uv where the test environment has it (:func:`_add`). The sizes and times it measures are printed (pytest -s) and recorded in
docs/install.md.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
from _session import session_lock

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.slow


def _run(cmd, cwd, *, env, check=True, timeout=900):
    p = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    if check and p.returncode != 0:
        raise AssertionError(f"{' '.join(map(str, cmd))} exited {p.returncode}:\n{p.stdout[-2000:]}\n{p.stderr[-3000:]}")
    return p


def _add(inst, *requirements, target=None):
    """Install ``requirements`` (constraints.txt's versions) into the installed environment, or into the
    folder ``target``: with the test environment's uv where it has one (the Makefile's installer, the
    same resolution as pip; its cache is warm from `make test`, and it does not byte-compile what no
    test imports: the extras cost 66 s of the suite with pip), else pip. The core wheel itself goes in
    with pip, as a studio installs it."""
    uv = Path(sys.executable).with_name("uv")
    where = ["--target", str(target)] if target is not None else []
    if uv.exists():
        cmd = [uv, "pip", "install", "--quiet", "--python", inst["py"], *where]
    else:
        cmd = [inst["py"], "-m", "pip", "install", "--quiet", *where]
    _run([*cmd, "-c", str(ROOT / "constraints.txt"), *map(str, requirements)], inst["work"], env=inst["env"])


def _size_mb(folder: Path) -> float:
    return sum(f.stat().st_size for f in folder.rglob("*") if f.is_file() and not f.is_symlink()) / 1e6


def _new_venv(venv: Path, cwd: Path, env: dict) -> Path:
    """The virtual environment ``python -m venv`` makes, at ``venv``; returns its python. ``python -m venv``
    puts pip in with ``ensurepip``: a pip process of its own installing the pip and setuptools wheels that
    come with Python, byte-compiled (8.6 s of CPU). Where the test environment has uv, the venv is made
    without pip and uv installs those same two wheels (ensurepip's own files, byte-compiled as ensurepip
    does: the same pip, the same site-packages) in 3.5 s; a user's `pip install` then runs that pip."""
    uv = Path(sys.executable).with_name("uv")
    import ensurepip

    bundled = sorted((Path(ensurepip.__file__).parent / "_bundled").glob("*.whl"))
    if not uv.exists() or not bundled:
        _run([sys.executable, "-m", "venv", str(venv)], cwd, env=env)
        return venv / "bin" / "python"
    _run([sys.executable, "-m", "venv", "--without-pip", str(venv)], cwd, env=env)
    py = venv / "bin" / "python"
    _run([uv, "pip", "install", "--quiet", "--offline", "--no-deps", "--compile-bytecode", "--python", py,
          *bundled], cwd, env=env)
    return py


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("installed")
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PHYSCAM_", "PYTHON", "VIRTUAL_ENV"))}
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    dist = tmp / "dist"
    # `python -m build` stages the sdist in the checkout itself (physcam-<version>/, src/*.egg-info): two
    # xdist workers building at once removed each other's staging folder, so they take turns
    # build's isolated build environments (the sdist's, then the wheel's from it) made with the test
    # environment's uv where it has one: the same isolation and wheel, 8.5 -> 5.0 s CPU (pip's venvs)
    uv = Path(sys.executable).with_name("uv")
    installer = ["--installer", "uv"] if uv.exists() else []
    with session_lock(tmp_path_factory, "build"):
        _run([sys.executable, "-m", "build", *installer, "--outdir", str(dist), str(ROOT)], tmp,
             env=dict(env, UV=str(uv)))
    wheels, sdists = sorted(dist.glob("physcam-*.whl")), sorted(dist.glob("physcam-*.tar.gz"))
    assert len(wheels) == 1 and len(sdists) == 1
    venv = tmp / "venv"
    py = _new_venv(venv, tmp, env)
    work = tmp / "work"
    work.mkdir()
    _run([py, "-m", "pip", "install", "--quiet", "-c", str(ROOT / "constraints.txt"), str(wheels[0])], work, env=env)
    site = Path(_run([py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], work, env=env)
                .stdout.strip())
    yield {"tmp": tmp, "py": py, "bin": venv / "bin", "work": work, "env": env, "wheel": wheels[0],
           "site": site, "core_mb": _size_mb(site)}
    shutil.rmtree(tmp, ignore_errors=True)  # the clean venv and its extras: about 1.1 GB of a CI machine's disk


def _physcam(inst, *args, check=True):
    return _run([inst["bin"] / "physcam", *map(str, args)], inst["work"], env=inst["env"], check=check)


def test_the_core_installs_light_and_runs_the_report(installed):
    inst = installed
    # nothing from the source tree: physcam comes from the installed wheel
    where = _run([inst["py"], "-c", "import physcam; print(physcam.__file__)"], inst["work"], env=inst["env"]).stdout
    assert str(inst["site"]) in where and str(ROOT) not in where
    assert _physcam(inst, "--version").stdout.strip() == "physcam 0.2.0"
    doc = json.loads(_physcam(inst, "report", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--json").stdout)
    import jsonschema

    schema = json.loads((ROOT / "src/physcam/cli/schemas/lens_report.schema.json").read_text())
    jsonschema.validate(doc, schema)
    # the installed wheel computes what this tree computes
    from physcam.onset.report import solve_lens_report
    from physcam.optics.sensors import find_sensor

    here = solve_lens_report(focal_length_mm=50.0, fstop=2.8, focus_mm=3000.0, sensor=find_sensor("Super 35"))
    assert doc["dof"]["near_from_film_mm"] == pytest.approx(here.dof.near_from_film_mm, rel=1e-12)
    # bundled lenses, sensors and the JSON schemas came with the wheel
    listed = _physcam(inst, "lenses", "--json")
    lenses = json.loads(listed.stdout)
    bundled = [lens for lens in lenses["lenses"] if lens["library"] == "bundled"]
    assert len(bundled) == len(list((ROOT / "src/physcam/data/lenses").glob("*.toml"))) == 51  # 47 primes, 4 zooms (issue 45)
    assert "ALEXA 35" in _physcam(inst, "sensors", "ARRI").stdout
    shipped = _run([inst["py"], "-c", "import importlib.resources as r; print(len(list(r.files('physcam.cli.schemas')"
                                      ".iterdir())))"], inst["work"], env=inst["env"]).stdout
    assert int(shipped) == len(list((ROOT / "src/physcam/cli/schemas").glob("*.json")))
    # and the catalogue glasses' stored fits (data/glass/fits): without them the wheel refitted 34 glasses in
    # every process that met one (`physcam lenses`: 6 s of CPU, not 0.6) and warned of a HOYA glass whose
    # stored fit is within tolerance
    fits = [p.name for p in (inst["site"] / "physcam" / "data" / "glass" / "fits").glob("*.json")]
    assert sorted(fits) == sorted(p.name for p in (ROOT / "src/physcam/data/glass/fits").glob("*.json")) != []
    assert "warning" not in listed.stderr, listed.stderr
    # the light core (issue 26's goal, under 300 MB): numba is the 'fast' extra; the C kernel (or, where it could
    # not be built, the numpy kernel) traces
    assert inst["core_mb"] < 300.0, f"the core install is {inst['core_mb']:.0f} MB"
    assert "No module named 'numba'" in _run([inst["py"], "-c", "import numba"], inst["work"], env=inst["env"],
                                             check=False).stderr
    # issue 47's install row, the fast path without numba: the core wheel is a platform wheel with the compiled
    # C kernel (setup.py), which "auto" traces with; a command's output is the numpy kernel's to the byte
    # (both kernels give the same rays: tests/trace/test_simd_kernel.py), and the process loaded the C
    # kernel, never numba. (One process for both runs: the second sets PHYSCAM_BACKEND=numpy.)
    assert "-py3-none-any" not in inst["wheel"].name, inst["wheel"].name
    kinds = _run([inst["py"], "-m", "physcam.trace.kernels"], inst["work"], env=inst["env"]).stdout.splitlines()
    assert kinds[0].startswith("c: built (") and kinds[1:] == ["numba: not installed", "numpy: always", "auto: c"]
    code = ("import io, os, sys, json, contextlib\nfrom physcam.cli import main\nout = []\n"
            "for backend in ('auto', 'numpy'):\n"
            "    os.environ['PHYSCAM_BACKEND'] = backend\n    buf = io.StringIO()\n"
            "    with contextlib.redirect_stdout(buf):\n"
            "        assert main(['bokeh', '--lens', 'dgauss_50mm', '--rays', '20000', '--pixels', '16', '--spectral',"
            " '--json']) == 0\n"
            "    out.append(buf.getvalue())\n"
            "    if backend == 'auto':\n"
            "        from physcam.trace.kernels import rim_pass\n"
            "        rims = rim_pass() is not None\n"
            "        seen = ['physcam.trace.kernels._ckernel' in sys.modules, 'numba' in sys.modules, rims]\n"
            "print(json.dumps([out[0] == out[1], json.loads(out[0])['rays_passed'] > 0, *seen]))")
    # (and the Blender extension's compiled rim pass is there too, without numba: the C one, round 22)
    assert json.loads(_run([inst["py"], "-c", code], inst["work"], env=inst["env"]).stdout) == [True, True, True, False,
                                                                                             True]
    # the tracer and an analysis figure
    _physcam(inst, "mtf", "dgauss_50mm", "--fstop", "8", "--field", "5", "--pupil-samples", "32", "-o", "mtf.png")
    assert (inst["work"] / "mtf.png").stat().st_size > 10_000
    # the measured figures of docs/install.md
    t0 = time.perf_counter()
    _run([inst["py"], "-c", "import physcam"], inst["work"], env=inst["env"])
    print(f"\ncore install: {inst['core_mb']:.0f} MB in site-packages; `python -c 'import physcam'` "
          f"{(time.perf_counter() - t0) * 1e3:.0f} ms")


def test_without_a_c_compiler_the_sdist_installs_and_traces_with_numpy(installed):
    """The C kernel is an optional extension (setup.py): where no C compiler works (``CC=/bin/false``) the
    sdist still installs, setuptools only warning, and that physcam has no compiled kernel, so "auto" traces
    with the numpy kernel (the same rays) and ``backend="c"`` is one line naming the fix. Installed with
    ``--no-deps`` into a folder put first on the path of the test's environment (its dependencies)."""
    inst = installed
    sdist = next(inst["wheel"].parent.glob("physcam-*.tar.gz"))
    target = inst["tmp"] / "no-compiler"
    env = dict(inst["env"], CC="/bin/false")
    # built with the test environment's own setuptools where it is new enough (2.4 s of CPU; an isolated
    # build environment costs 4.1), the same setup.py either way
    try:
        import setuptools

        own = int(setuptools.__version__.split(".")[0]) >= 77
    except ImportError:
        own = False
    pip = [sys.executable, "-m", "pip", "install", "--no-build-isolation"] if own else [inst["py"], "-m", "pip", "install"]
    _run([*pip, "--quiet", "--no-deps", "--target", str(target), str(sdist)], inst["work"], env=env)
    assert (target / "physcam/trace/kernels/_ckernel.c").exists()  # the source came, no module built from it
    assert not [m for m in target.glob("physcam/trace/kernels/_ckernel*") if m.suffix in (".so", ".pyd")]
    env = dict(inst["env"], PYTHONPATH=str(target))
    kinds = _run([inst["py"], "-m", "physcam.trace.kernels"], inst["work"], env=env).stdout.splitlines()
    assert kinds[0].startswith("c: not built") and kinds[-1] == "auto: numpy"
    p = _run([inst["bin"] / "python", "-m", "physcam", "spot", "--lens", "dgauss_50mm"], inst["work"],
             env=dict(env, PHYSCAM_BACKEND="c"), check=False)
    assert p.returncode == 2 and "not built" in p.stderr and len(p.stderr.strip().splitlines()) == 1, p.stderr


@pytest.mark.parametrize("extra, args", [
    ("usd", ["usd", "write", "cam.usda", "--focal", "50", "--fstop", "2.8", "--focus", "3m"]),
    ("exr", ["distortion", "dgauss_50mm", "--resolution", "64x48", "--stmap", "maps"]),
    ("live", ["live", "validate", "sample.json"]),
    ("dask", ["characterize", "dgauss_50mm", "-o", "char", "--focus", "2m", "--fstop", "4"]),
    ("serve", ["serve", "--port", "0", "--check"]),
    # found by a review of the core install: each used to end in a traceback, or after the work
    ("exr", ["defocus-kernels", "--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8", "--resolution", "64x36",
             "--depths", "1m", "-o", "psf"]),
    ("exr", ["distortion", "--lens", "dgauss_50mm", "--resolution", "640x480", "--stmap", "maps2"]),
    ("usd", ["live", "wall", "wall.usda", "--kind", "flat"]),
    ("usd", ["demo", "--out", "demo-core"]),
])
def test_a_missing_extra_is_one_line_naming_its_install(installed, extra, args):
    (installed["work"] / "sample.json").write_text("{}")
    p = _physcam(installed, *args, check=False)
    assert p.returncode == 2
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and f"pip install 'physcam[{extra}]'" in lines[0], p.stderr
    assert "Traceback" not in p.stderr
    # said before any work: nothing written
    assert not any((installed["work"] / name).exists() for name in ("psf", "maps2", "wall.usda", "demo-core"))


def test_the_core_reads_camera_metadata_and_a_take_needs_usd_before_it_is_received(installed):
    inst = installed
    clip = inst["site"] / "physcam" / "data" / "samples" / "arri_alexa_lf_B001C001_first48.csv"
    p = _physcam(inst, "metadata", "report", clip, "--json")
    assert len(json.loads(p.stdout)["frames"]) == 48
    # with the 'live' extra but not 'usd' (its packages on a side path), a recording stops at once
    from physcam.extras import EXTRAS

    side = inst["tmp"] / "live-only"
    _add(inst, *(pypi for _, pypi in EXTRAS["live"]), target=side)
    env = dict(inst["env"], PYTHONPATH=str(side))
    t0 = time.perf_counter()
    p = _run([inst["bin"] / "physcam", "live", "record", "take.usda", "--port", "55631", "--duration", "30"],
             inst["work"], env=env, check=False)
    assert time.perf_counter() - t0 < 20.0  # not after the 30 s take
    assert p.returncode == 2 and "pip install 'physcam[usd]'" in p.stderr and len(p.stderr.strip().splitlines()) == 1
    assert not (inst["work"] / "take.usda").exists()


def test_the_jit_kernels_missing_is_one_line_naming_the_fast_extra(installed):
    env = dict(installed["env"], PHYSCAM_BACKEND="numba")
    p = _run([installed["bin"] / "physcam", "spot", "dgauss_50mm"], installed["work"], env=env, check=False)
    assert p.returncode == 2
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and "pip install 'physcam[fast]'" in lines[0], p.stderr


FIRST_TRACE = """
import json
from physcam.lens.library import load_lens
from physcam.trace import RayBatch, kernels, trace_to_film
from physcam.trace.kernels import _jitcache
calls = []
kernels.set_compile_reporter(lambda done, total: calls.append(done))
lens = load_lens("dgauss_50mm")
rays = RayBatch.collimated([0.0, 1.0, 2.0], [0.0, 0.5, 1.0], -1.0)
trace_to_film(lens, rays, 68.0, backend="numba")
print(json.dumps({"compiled": bool(calls), "dir": _jitcache.cache_dir()}))
"""


def test_the_fast_extra_compiles_once_where_the_install_can_write(installed):
    """Issue 47: the first traced command after `pip install 'physcam[fast]'` compiles the JIT variant it
    needs and caches it; where the package folder cannot take numba's cache (a system install; here the
    cache folder is blocked by a file, since this suite may run as root, whom permissions do not stop)
    it goes to the user cache (XDG_CACHE_HOME), and the next process loads it instead of compiling."""
    inst = installed
    _add(inst, f"{inst['wheel']}[fast]")
    pycache = inst["site"] / "physcam" / "trace" / "kernels" / "__pycache__"
    pycache.mkdir(exist_ok=True)
    (pycache / "physcam-jit").write_text("not a folder: the package's own cache place is unusable\n")
    env = dict(inst["env"], XDG_CACHE_HOME=str(inst["tmp"] / "user-cache"))
    env.pop("NUMBA_CACHE_DIR", None)
    first = json.loads(_run([inst["py"], "-c", FIRST_TRACE], inst["work"], env=env).stdout)
    assert first["compiled"] and first["dir"].startswith(str(inst["tmp"] / "user-cache" / "physcam" / "jit"))
    assert any(name.endswith(".nbi") for name in os.listdir(first["dir"]))
    second = json.loads(_run([inst["py"], "-c", FIRST_TRACE], inst["work"], env=env).stdout)
    assert second == {"compiled": False, "dir": first["dir"]}


def test_with_every_extra_the_demo_usd_plugin_and_serve_work(installed):
    inst = installed
    _add(inst, f"{inst['wheel']}[all]")
    print(f"\nwith every extra: {_size_mb(inst['site']):.0f} MB in site-packages")
    _physcam(inst, "demo", "--out", "demo")
    assert (inst["work"] / "demo").is_dir()
    # the PhysicalCamera schema plugin registers from the installed wheel, in a plain process
    code = ("import physcam.usd\n"
            "from pxr import Usd, Sdf\n"
            "from physcam.usd.author import CameraSpec, author_camera, new_stage\n"
            "stage = new_stage()\n"
            "prim = author_camera(stage, '/Cam', CameraSpec.of(focal_length_mm=35.0, fstop=2.8, focus_mm=2000.0))\n"
            "print(prim.GetTypeName(), Usd.SchemaRegistry().FindConcretePrimDefinition('PhysicalCamera') is not None)\n")
    out = _run([inst["py"], "-c", code], inst["work"], env=inst["env"]).stdout.split()
    assert out == ["PhysicalCamera", "True"]
    # with 'all' (which holds 'fast') the JIT kernels load and trace
    code = "from physcam.trace.kernels import resolve_backend; print(resolve_backend('numba'))"
    assert _run([inst["py"], "-c", code], inst["work"], env=inst["env"]).stdout.split() == ["numba"]
    assert "answer" in _physcam(inst, "serve", "--port", "0", "--check").stdout
