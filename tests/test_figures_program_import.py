"""The ``physcam`` program imports matplotlib without what it never uses (figures.PROGRAM_IMPORT,
issue 47: the property tables of artist docstrings and set() signatures, the 3-D toolkit, 0.2 s of CPU, and the
code of TeX's glyph names until read), its objects frozen out of the cycle collector's scans (``gc.freeze``,
the collector itself left on), Pillow's plugins other than PNG's loaded only when asked for: the pictures are the same, byte for byte, and a library caller's matplotlib
and collector stay as they were."""

from __future__ import annotations

import subprocess
import sys


def _draw(tmp_path, program: bool):
    out = tmp_path / ("program.png" if program else "library.png")
    code = ("import sys, io, contextlib\n"
            "from physcam import figures\n"
            f"figures.PROGRAM_IMPORT = {program}\n"
            "from physcam.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            f"    assert main(['spot', '--lens', 'dgauss_50mm', '--rings', '4', '-o', {str(out)!r}]) == 0\n"
            "import matplotlib.lines\n"
            "print('mpl_toolkits.mplot3d' in sys.modules, 'Properties:' in (matplotlib.lines.Line2D.set.__doc__ or ''),\n"
            "      '__signature__' in vars(matplotlib.lines.Line2D.set),\n"
            "      type(sys.modules['fontTools.agl']).__name__ == '_LazyModule')\n"
            "import fontTools.agl\n"  # read, a lazy module runs its code: the same module
            "print(fontTools.agl.toUnicode('Alpha') == '\\u0391')\n"
            "import gc\n"  # the program's import is frozen out of the collector's scans, the collector left on
            "print(gc.isenabled(), gc.get_freeze_count() > 50000)\n"
            # Pillow's other plugins not loaded for the PNG; loaded when another format is asked for
            "print(sorted(m for m in sys.modules if m.endswith('ImagePlugin')) == ['PIL.PngImagePlugin'])\n"
            "from PIL import Image\n"
            "b = io.BytesIO()\n"
            "Image.new('RGB', (4, 4), (200, 10, 10)).save(b, format='JPEG')\n"
            "print(Image.open(io.BytesIO(b.getvalue())).format == 'JPEG')\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return out.read_bytes(), p.stdout.split()


def test_the_program_draws_the_same_pictures_and_the_library_keeps_matplotlib_whole(tmp_path):
    lean, seen_lean = _draw(tmp_path, True)
    whole, seen_whole = _draw(tmp_path, False)
    assert lean[:8] == b"\x89PNG\r\n\x1a\n" and lean == whole
    # no 3-D toolkit, no property table or signature for set(), TeX's glyph names not run yet
    assert seen_lean == ["False", "False", "False", "True", "True", "True", "True", "True", "True"]
    assert seen_whole == ["True", "True", "True", "False", "True", "True", "False", "False", "True"]


def test_the_program_draws_dates_on_an_axis(tmp_path):
    """matplotlib's date converters are registered in the program's lean import as in a whole matplotlib: a
    datetime x axis draws (round 21 made ``matplotlib.dates`` lazy, and a date plot then raised TypeError)."""
    import subprocess
    import sys

    code = ("from physcam import figures\n"
            "figures.PROGRAM_IMPORT = True\n"
            "from physcam.figures import pyplot\n"
            "import datetime\n"
            "plt = pyplot(); fig, ax = plt.subplots()\n"
            "ax.plot([datetime.datetime(2026, 11, 30), datetime.datetime(2026, 12, 1)], [0, 1])\n"
            f"fig.savefig({str(tmp_path / 'd.png')!r}); print('ok')\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr[-2000:]
