"""``physcam export blender-extension --workers``: the lenses' tables computed by several processes give
the zip one process gives (the session's shared zip is built with two workers, tests/conftest.py)."""

import json
import os
import subprocess
import sys
import zipfile

import pytest
from _session import EXTENSION_LENSES

from physcam.cli import main
from physcam.errors import PhysCamError
from physcam.export.blender_extension import build_extension, lens_payload
from physcam.lens.library import list_lenses, load_lens
from physcam.trace.kernels import numba_available

LENS = "dgauss_77deg_3_5201mm"  # the cheapest lens to tabulate (~2 s)


def test_tables_of_the_pooled_build_are_the_one_process_ones(extension_zip, monkeypatch):
    """Every lens asked for (the session's, tests/_session.py) is in the pooled zip, in the order asked
    (the library's), with one shader source (its four variants' #define lines are the add-on's:
    shader_variant.py), and one lens's table and shader computed here, in this process, are the zip's
    byte for byte, whichever rim pass finds them: the zip's workers trace with "auto" (the C kernel and its rim
    pass where built), this process with the numpy kernel and pass (``PHYSCAM_BACKEND=numpy``) and, where numba
    is installed, with numba's kernel and pass (tests/export/test_blender_pupil_rimpass.py holds the passes'
    points equal; this holds that the zip's bytes are too)."""
    for backend in ("numpy", "numba") if numba_available() else ("numpy",):
        monkeypatch.setenv("PHYSCAM_BACKEND", backend)
        data, shaders = lens_payload(load_lens(LENS), LENS)
        assert list(shaders) == [f"{LENS}.osl"]
        asked = [r.slug for r in list_lenses() if r.slug in EXTENSION_LENSES]
        with zipfile.ZipFile(extension_zip) as z:
            index = json.loads(z.read("lenses/index.json"))
            assert [e["slug"] for e in index] == asked
            assert sorted(n for n in z.namelist() if n.startswith("shaders/")) == sorted(f"shaders/{s}.osl" for s in asked)
            assert "def variant_source(" in z.read("shader_variant.py").decode("utf-8")
            assert z.read(f"lenses/{LENS}.json") == json.dumps(data).encode("utf-8"), backend
            for name, text in shaders.items():
                assert z.read(f"shaders/{name}") == text.encode("utf-8"), (backend, name)


#: Two of the cheapest lenses to tabulate, one of them anamorphic (its rectangle tables, not the radial ones)
FORKED = ("dgauss_77deg_3_5201mm", "neil_front_anamorphic_2x")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the program forks its workers on Linux only")
def test_the_programs_forked_workers_give_the_one_process_tables(tmp_path):
    """The ``physcam`` program (``python -m physcam``) on Linux forks its two workers from itself once it has
    loaded the tables' modules (blender_extension._forks, asked in the same program here: a library caller gets
    fresh processes), and never numba first (round 22: the rim pass is in C; a worker's tables rent what their work
    pays for, numba included, as any tracing job does): each
    lens's table and shader in its zip are the ones computed here, in this process, byte for byte, and the
    lenses come in the order asked."""
    probe = ("import sys; from physcam import _program; _program.start(); "
             "from physcam.export.blender_extension import _forks; print(_forks(), 'numba' in sys.modules)")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    env.pop("PHYSCAM_BACKEND", None)
    forks = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=env, check=True)
    assert forks.stdout.split() == ["True", "False"]
    from physcam.export.blender_extension import _forks

    assert not _forks()  # the library (this test's process) spawns fresh workers
    argv = ["export", "blender-extension", "-o", str(tmp_path), "--workers", "2"]
    for name in FORKED:
        argv += ["--lens", name]
    r = subprocess.run([sys.executable, "-m", "physcam", *argv], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    (zp,) = tmp_path.glob("*.zip")
    with zipfile.ZipFile(zp) as z:
        assert [e["slug"] for e in json.loads(z.read("lenses/index.json"))] == list(FORKED)
        for name in FORKED:
            data, shaders = lens_payload(load_lens(name), name)
            assert z.read(f"lenses/{name}.json") == json.dumps(data).encode("utf-8")
            assert z.read(f"shaders/{name}.osl") == shaders[f"{name}.osl"].encode("utf-8")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the program forks its workers on Linux only")
def test_the_program_forks_beside_its_waiting_progress_timer_only():
    """At a terminal the program runs a progress timer thread from the start (``slow_command_progress``): a quiet
    thread (physcam.progress.quiet_thread: it waits, then takes FORK_LOCK before drawing), beside which the
    workers are still forks (round 21's review: they were spawned at every terminal); any other thread (a
    display already drawing, a caller's own) still means fresh processes."""
    probe = ("import threading, time\n"
             "from physcam import _program; _program.start()\n"
             "from physcam.progress import quiet_thread\n"
             "from physcam.export.blender_extension import _forks\n"
             "t = quiet_thread(threading.Timer(60, print)); t.daemon = True; t.start(); time.sleep(0.05)\n"
             "print(_forks())\n"
             "e = threading.Event(); u = threading.Thread(target=e.wait, daemon=True); u.start()\n"
             "print(_forks())\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["True", "False"]


@pytest.mark.parametrize("workers", [0, 257, 1.5, True])
def test_a_bad_number_of_workers_is_refused(workers, tmp_path):
    with pytest.raises(PhysCamError, match="workers"):
        build_extension(tmp_path, lenses=[LENS], workers=workers)
    assert not list(tmp_path.iterdir())


def test_the_cli_refuses_zero_workers_in_one_line(tmp_path, capsys):
    assert main(["export", "blender-extension", "-o", str(tmp_path), "--lens", LENS, "--workers", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert "workers" in err and len(err.splitlines()) == 1
    assert not list(tmp_path.iterdir())
