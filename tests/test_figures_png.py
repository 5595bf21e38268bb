"""physcam's figures write PNG files themselves (figures.png_bytes, issue 47: Pillow's plugins and per-row
filters were 30-40 ms of a cold figure command). The oracle is matplotlib's own PNG (Agg's print_png through
Pillow) of the same figure, decoded by Pillow: the same pixels, size, dpi and Software text."""

from __future__ import annotations

import io

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from PIL import Image

from physcam import figures


def _figure():
    with figures.figure_style():
        fig, (a, b) = figures.subplots(1, 2, figsize=(4.0, 2.2))
        x = np.linspace(0, 3, 50)
        a.plot(x, np.sin(3 * x), label="sin (rad)")
        a.set_xlabel("x (mm)")
        a.set_ylabel("y (mm)")
        a.legend()
        b.imshow(np.random.default_rng(1).uniform(size=(30, 40)), cmap="magma")
        b.set_title("noise, µm")
        fig.tight_layout()
    return fig


def _decoded(data: bytes):
    im = Image.open(io.BytesIO(data))
    im.load()
    return im


def _matplotlib_png(fig, **kw) -> bytes:
    buf = io.BytesIO()
    FigureCanvasAgg(fig)  # matplotlib's own canvas: Agg's print_png, Pillow's encoder
    with figures.figure_style():
        fig.savefig(buf, format="png", **kw)
    return buf.getvalue()


@pytest.mark.parametrize("dpi", [72, 130, 150])
def test_save_figure_writes_matplotlibs_pixels(tmp_path, dpi):
    ours = _decoded(figures.save_figure(_figure(), tmp_path / "f.png", dpi=dpi).read_bytes())
    theirs = _decoded(_matplotlib_png(_figure(), dpi=dpi))
    assert theirs.mode == "RGBA" and ours.mode == "RGB"  # every pixel opaque: no alpha channel written
    assert ours.size == theirs.size
    assert np.array_equal(np.asarray(ours), np.asarray(theirs.convert("RGB")))
    assert np.asarray(theirs)[..., 3].min() == 255
    assert ours.info["dpi"] == pytest.approx(theirs.info["dpi"]) and ours.info["Software"] == theirs.info["Software"]


def test_a_transparent_figure_keeps_its_alpha():
    fig = _figure()
    buf = io.BytesIO()
    with figures.figure_style():
        fig.savefig(buf, format="png", transparent=True, dpi=100)
    ours = _decoded(buf.getvalue())
    theirs = _decoded(_matplotlib_png(_figure(), transparent=True, dpi=100))
    assert ours.mode == "RGBA" and np.array_equal(np.asarray(ours), np.asarray(theirs))
    assert np.asarray(ours)[..., 3].min() == 0


@pytest.mark.parametrize("shape", [(1, 1), (3, 7), (64, 33)])
def test_png_bytes_round_trip(shape):
    rng = np.random.default_rng(sum(shape))
    rgba = rng.integers(0, 256, size=(*shape, 4), dtype=np.uint8)
    im = _decoded(figures.png_bytes(rgba, dpi=96, text={"Title": "test: µm"}))
    assert im.mode == "RGBA" and np.array_equal(np.asarray(im), rgba)
    assert im.info["Title"] == "test: µm" and im.info["dpi"] == pytest.approx((96, 96), abs=0.0127)  # whole pixels per metre
    rgba[..., 3] = 255
    im = _decoded(figures.png_bytes(rgba))
    assert im.mode == "RGB" and np.array_equal(np.asarray(im), rgba[..., :3]) and "dpi" not in im.info


def test_pillow_options_still_reach_pillow():
    fig = _figure()
    buf = io.BytesIO()
    with figures.figure_style():
        fig.savefig(buf, format="png", pil_kwargs={"compress_level": 1}, metadata={"Title": "Ω"}, dpi=80)
    im = _decoded(buf.getvalue())
    assert im.mode == "RGBA" and im.info["Title"] == "Ω"  # matplotlib's own writer, as asked
