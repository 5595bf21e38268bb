"""Structural guards of the cold-start goal of `physcam spot`/`bokeh`/`distortion` (< 0.5 s,
benchmarks/startup.py): plots use Agg canvases, never matplotlib.pyplot (0.1-0.3 s to import)."""

import subprocess
import sys


def test_plotting_commands_do_not_import_pyplot(tmp_path):
    code = ("import sys, io, contextlib\nfrom physcam.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            f"    assert main(['spot', 'dgauss_50mm', '--rings', '4', '-o', {str(tmp_path / 's.png')!r}]) == 0\n"
            f"    assert main(['bokeh', 'dgauss_50mm', '--rays', '2000', '--pixels', '16', '-o', "
            f"{str(tmp_path / 'b.png')!r}]) == 0\n"
            f"    assert main(['distortion', 'dgauss_50mm', '--field', '0', '--field', '5', '-o', "
            f"{str(tmp_path / 'd.png')!r}]) == 0\n"
            "print('matplotlib.pyplot' in sys.modules, 'matplotlib.figure' in sys.modules)")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert p.stdout.split() == ["False", "True"]
    for name in ("s.png", "b.png", "d.png"):
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def _run(code: str) -> subprocess.CompletedProcess:
    import os

    env = {k: v for k, v in os.environ.items() if k != "PHYSCAM_BACKEND"}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)


def _warm_jit(*argv: list[str]) -> None:
    """Run each command once with the JIT kernel forced, so numba's disk cache holds the variants they
    use: "auto" counts a cold cache as a compile (kernels.numba_load_cost), and these tests are about
    a warm one."""
    import os

    code = ("import io, contextlib\nfrom physcam.cli import main\n"
            f"for argv in {list(argv)!r}:\n"
            "    with contextlib.redirect_stdout(io.StringIO()):\n"
            "        assert main(argv) == 0\n")
    env = dict(os.environ, PHYSCAM_BACKEND="numba")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert p.returncode == 0, p.stderr


def test_default_bokeh_stays_in_numpy_and_a_large_one_loads_numba():
    """The whole job is known ahead (kernels.backend_for_job). Without the C kernel: 250,000 rays cost the
    numpy kernel less than loading numba, 1e6 rays do not. With it (where built), "auto" rents the C kernel
    and counts only what numba would save (kernels.C_EXCESS): both bokehs stay in C, and a job of 1e10
    ray-surfaces (seconds of the C kernel's time even at AVX-512, where numba saves least) loads numba."""
    from physcam.trace.kernels import c_available

    _warm_jit(["bokeh", "dgauss_50mm", "--rays", "2000", "--pixels", "16", "--json"])
    code = ("import sys, io, contextlib\nfrom physcam.cli import main\n"
            "import physcam.trace.kernels as K\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            "    assert main(['bokeh', 'dgauss_50mm', '--json']) == 0\n"
            "a = 'numba' in sys.modules\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            "    assert main(['bokeh', 'dgauss_50mm', '--rays', '1000000', '--pixels', '32', '--json']) == 0\n"
            "b = 'numba' in sys.modules\n"
            "job = K.backend_for_job('auto', 1e10)\n"
            "print(a, b, K.loaded_backend(), job, K.resolve_backend(job) if job == 'auto' else job)")
    p = _run(code)
    assert p.returncode == 0, p.stderr
    if c_available():
        assert p.stdout.split() == ["False", "False", "c", "auto", "numba"]
    else:
        assert p.stdout.split()[:2] == ["False", "True"]


def test_vendor_mtf_chart_stays_in_numpy_and_a_process_of_charts_loads_numba():
    # a chart's pupils (15 fields x 3 wavelengths, about 5e5 rays; dgauss_50mm has no dispersion, so a
    # third of them traced: issue 47) cost the numpy kernel less than loading numba; a process that keeps
    # drawing charts loads it once its numpy work has reached that cost (by the fourth or fifth chart)
    _warm_jit(["mtf", "--lens", "dgauss_50mm", "--fstop", "8", "--field", "5", "--pupil-samples", "32", "--json"])
    code = ("import sys, io, contextlib\nfrom physcam.cli import main\n"
            "argv = ['mtf', '--lens', 'dgauss_50mm', '--fstop', '4', '--focus', '3m', '--sensor', 'FF', '--json']\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            "    assert main(argv) == 0\n"
            "a = sorted({'numba', 'scipy', 'matplotlib', 'numpy.ma'} & set(sys.modules))\n"
            "charts = 1\n"
            "while 'numba' not in sys.modules and charts < 6:\n"
            "    with contextlib.redirect_stdout(io.StringIO()):\n"
            "        assert main(argv) == 0\n"
            "    charts += 1\n"
            "print(a, 'numba' in sys.modules, charts)")
    from physcam.trace.kernels import c_available

    if c_available():
        # the C kernel (where built): what numba would save on a chart is milliseconds, so a process of
        # charts keeps renting it (two charts here: the same rent each)
        code = code.replace("charts < 6", "charts < 2")
    p = _run(code)
    assert p.returncode == 0, p.stderr
    imported, loaded, charts = p.stdout.split()
    if c_available():
        assert imported == "[]" and loaded == "False" and charts == "2"
    else:
        assert imported == "[]" and loaded == "True" and 2 <= int(charts) <= 5


def test_the_program_exits_cleanly_after_numba_was_loaded(tmp_path):
    # physcam.cli.run skips the interpreter's teardown once numba is loaded: exit handlers still
    # run, output is complete, the status is main()'s
    import json

    flag = tmp_path / "atexit.txt"
    code = ("import atexit, sys\nimport numba\n"
            f"atexit.register(lambda: open({str(flag)!r}, 'w').write('ran'))\n"
            "sys.argv = ['physcam'] + sys.argv[1:]\nfrom physcam.cli import run\nrun()\n")
    out = tmp_path / "b.png"
    p = subprocess.run([sys.executable, "-c", code, "bokeh", "dgauss_50mm", "--rays", "5000", "--pixels", "16",
                        "--json", "-o", str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert json.loads(p.stdout)["rays_traced"] == 5000
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert flag.read_text() == "ran"
    flag.unlink()
    p = subprocess.run([sys.executable, "-c", code, "bokeh", "dgauss_50mm", "--rays", "0"], capture_output=True,
                       text=True)
    assert p.returncode == 2 and p.stderr.startswith("physcam: error:") and "Traceback" not in p.stderr
    assert flag.read_text() == "ran"


def test_ghosts_and_relative_illumination_stay_in_numpy():
    # issue 47: each one's tracing (0.19 and 0.23 s estimated in the numpy kernel, in many small calls)
    # costs less than loading numba (kernels.NUMBA_LOAD_S); "auto" used to load it after a third of that
    _warm_jit(["ghosts", "--lens", "dgauss_50mm", "--field", "10", "--top", "1"])
    for argv in (["ghosts", "--lens", "dgauss_50mm", "--field", "10", "--top", "5"], ["illumination", "--lens",
                                                                                      "dgauss_50mm"]):
        code = ("import sys, io, contextlib\nfrom physcam.cli import main\n"
                "with contextlib.redirect_stdout(io.StringIO()):\n"
                f"    assert main({argv!r}) == 0\n"
                "print('numba' in sys.modules)")
        p = _run(code)
        assert p.returncode == 0, p.stderr
        assert p.stdout.split() == ["False"], argv


def test_a_command_that_writes_no_file_loads_neither_the_writers_modules_nor_plotting():
    # issue 47: physcam.io imports what writing a file needs (shutil and the compressors it imports, socket,
    # tempfile) where it writes; a bokeh that only prints its numbers loads none of them, nor matplotlib
    code = ("import sys, io, contextlib\nfrom physcam.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            "    assert main(['bokeh', 'dgauss_50mm', '--rays', '2000', '--pixels', '16']) == 0\n"
            "print(sorted({'shutil', 'lzma', 'bz2', 'socket', 'tempfile', 'matplotlib', 'scipy', 'numba', 'rich'}"
            " & set(sys.modules)))")
    p = _run(code)
    assert p.returncode == 0, p.stderr
    assert p.stdout.split() == ["[]"]


def test_the_issue_47_commands_load_only_what_they_draw_or_print(tmp_path):
    # issue 47, as the program runs them (_program.start: matplotlib's lean import): the commands that
    # print load neither matplotlib nor numba; the figures load Figure and the Agg canvas, never pyplot,
    # matplotlib's 3-D toolkit, its style library (figures._rcdefaults) or numba (their rays cost the numpy
    # kernel less than numba's load; a
    # compare of one lens with few bokeh rays keeps the test cheap: the figure is the same kind)
    printed = [["mtf", "--lens", "dgauss_50mm", "--field", "0"]]
    drawn = [["compare", "--lens", "tessar_50mm_f2_8", "--focus", "2m", "--sensor", "S35", "--rays", "2000", "-o",
              str(tmp_path / "c.png")]]
    # (each command as in a process of its own: the numpy work "auto" has counted starts at 0)
    code = ("import sys, io, contextlib\nfrom physcam import _program\nfrom physcam.cli import main\n"
            "import physcam.trace.kernels as K\n_program.start()\n"
            "def loaded():\n"
            "    return sorted(m for m in ('numba', 'matplotlib', 'matplotlib.pyplot', 'mpl_toolkits.mplot3d',"
            " 'matplotlib.style')"
            " if sys.modules.get(m) is not None)\n"
            f"for argv in {printed!r}:\n"
            "    K._rent_paid = 0.0\n"
            "    with contextlib.redirect_stdout(io.StringIO()):\n"
            "        assert main(argv) == 0\n"
            "print(loaded())\n"
            f"for argv in {drawn!r}:\n"
            "    K._rent_paid = 0.0\n"
            "    with contextlib.redirect_stdout(io.StringIO()):\n"
            "        assert main(argv) == 0\n"
            "print(loaded())\n")
    p = _run(code)
    assert p.returncode == 0, p.stderr
    assert p.stdout.split("\n")[:2] == ["[]", "['matplotlib']"]
    assert (tmp_path / "c.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
