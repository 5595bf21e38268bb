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
