"""figures.dots: a scatter of sub-pixel round dots drawn on an Agg canvas as one coverage image (issue 47: a
spot diagram's 56,000 dots were 0.22 s of Agg's path rendering). The oracle is matplotlib's own rendering of
the same scatter (``ax.scatter``, Agg): the two pictures must agree pixel by pixel to a few grey levels and
carry the same ink; SVG and PDF still get the scatter's vector dots."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from physcam import figures


def _dots_like_a_spot(seed=3):
    """Rings of dots as a spot diagram has them (dense centre, sparse rim, some refined rim rays 1/16 the size)."""
    rng = np.random.default_rng(seed)
    r = np.sqrt(rng.uniform(0, 1, 20_000)) * 40.0
    phi = rng.uniform(0, 2 * np.pi, r.size)
    w = np.where(rng.uniform(size=r.size) < 0.2, 1 / 16, 1.0)
    return r * np.cos(phi), 0.6 * r * np.sin(phi) + 0.01 * r ** 2, 0.3 * w / w.max()


def _png(draw, fmt="png"):
    import matplotlib

    with figures.figure_style(), matplotlib.rc_context({"svg.hashsalt": "dots"}):
        fig, ax = figures.subplots(figsize=(3.2, 3.4))
        ax.set_aspect("equal")
        draw(ax)
        ax.set_xlabel("x (µm)")
        ax.set_ylabel("y (µm)")
        buf = io.BytesIO()
        fig.savefig(buf, format=fmt, dpi=130, metadata={"svg": {"Date": None}, "pdf": {"CreationDate": None}}.get(fmt))
    return buf.getvalue()


def _grey(data):
    return np.asarray(Image.open(io.BytesIO(data)).convert("L"), dtype=float)


def test_dots_draw_the_picture_agg_draws_for_the_scatter():
    x, y, s = _dots_like_a_spot()
    scatter = _grey(_png(lambda ax: ax.scatter(x, y, s=s, c="k", lw=0)))
    dots = _grey(_png(lambda ax: figures.dots(ax, x, y, s, "k")))
    assert scatter.shape == dots.shape
    ink_scatter, ink_dots = (255 - scatter).sum(), (255 - dots).sum()
    assert abs(ink_dots - ink_scatter) < 0.02 * ink_scatter  # the same darkness overall
    diff = np.abs(scatter - dots)
    assert diff.mean() < 1.5  # grey levels, over the whole figure (1.1 here: bilinear against exact disc coverage)
    inked = scatter < 250
    assert np.median(diff[inked]) < 8.0
    # no dot moved by a pixel: blurred over 3 x 3 pixels the two agree within a few grey levels
    blur = [np.lib.stride_tricks.sliding_window_view(a, (3, 3)).mean(axis=(-1, -2)) for a in (scatter, dots)]
    assert np.abs(blur[0] - blur[1]).max() < 30.0
    assert np.abs(blur[0] - blur[1]).mean() < 0.5


def test_agg_draws_one_image_not_a_path_per_dot(monkeypatch):
    from matplotlib.backends.backend_agg import RendererAgg

    calls = {"draw_path_collection": 0, "draw_image": 0}
    init = RendererAgg.__init__

    def counted_init(self, *a, **k):  # Agg's renderer sets these two on the instance, from its C++ part
        init(self, *a, **k)
        for name in calls:
            real = getattr(self, name)

            def wrapped(*args, _name=name, _real=real, **kw):
                calls[_name] += 1
                return _real(*args, **kw)
            setattr(self, name, wrapped)

    monkeypatch.setattr(RendererAgg, "__init__", counted_init)
    x, y, s = _dots_like_a_spot()
    _png(lambda ax: figures.dots(ax, x, y, s, "k"))
    assert calls == {"draw_path_collection": 0, "draw_image": 1}
    _png(lambda ax: ax.scatter(x, y, s=s, c="k", lw=0))  # the counting sees the scatter's paths
    assert calls["draw_path_collection"] > 0 and calls["draw_image"] == 1


@pytest.mark.parametrize("fmt", ["svg", "pdf"])
def test_vector_files_keep_the_scatter(fmt):
    x, y, s = _dots_like_a_spot()
    x, y, s = x[:300], y[:300], s[:300]
    data = _png(lambda ax: figures.dots(ax, x, y, s, "k"), fmt)
    # the same file, byte for byte, but for the SVG group's name (the artist's class)
    assert data.replace(b"CoverageDots_", b"PathCollection_") == _png(lambda ax: ax.scatter(x, y, s=s, c="k", lw=0), fmt)
