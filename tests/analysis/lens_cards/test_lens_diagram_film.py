"""Issue 39 item 9: the lens diagram's chief ray lands on the drawn film.

The film was drawn as tall as the largest element (dgauss_50mm: +-12.6 mm) while the widest
unvignetted field's chief ray lands 21 mm off axis, beyond it. Checked on the drawing itself: every
traced ray that reaches the film plane ends within the film line matplotlib draws.

Every bundled lens is checked on :meth:`LensDiagram.draw`'s drawing, in an axes made as
:meth:`LensDiagram.figure` makes it (its size, physcam's style), without the figure's ``tight_layout``: that
pass moves the axes on the page and never the drawing's lines or view limits (the same film line, rays and
limits for every bundled lens, checked 2026-11-30), and measuring every tick label for it was a quarter of
this file's CPU (`pytest` of the file: 14.4, 15.1 s user before, 11.3, 12.5 s after). Two lenses (a prime, a
fisheye) check that the figure shows that same drawing."""

from __future__ import annotations

import numpy as np
import pytest

from physcam.analysis.lens_cards.diagram import lens_diagram
from physcam.lens.library import list_lenses, load_lens

WIDTH_IN = 6.0


def _drawing(d):
    """The axes of ``d``'s drawing as :meth:`LensDiagram.figure` draws it (width 6 in), without its layout pass."""
    from physcam.figures import figure_style, new_figure

    fig = new_figure(figsize=(WIDTH_IN, WIDTH_IN * 0.45))
    with figure_style():
        ax = fig.add_subplot(1, 1, 1)
    d.draw(ax, width_in=WIDTH_IN)
    return ax


def _film_top(d, ax):
    """The top of the film line drawn at the film plane (the one line there crossing the axis)."""
    z = d.gaussian.z_film
    film = [ln for ln in ax.get_lines() if np.allclose(ln.get_xdata(), z) and len(ln.get_xdata()) == 2
            and ln.get_ydata()[0] < 0 < ln.get_ydata()[1]]
    assert len(film) == 1
    return film[0].get_ydata()[1]


@pytest.mark.parametrize("slug", [r.slug for r in list_lenses()])
def test_rays_land_on_the_drawn_film(slug):
    d = lens_diagram(load_lens(slug))
    ax = _drawing(d)
    top = _film_top(d, ax)
    z = d.gaussian.z_film
    landed = [pts[-1][1] for _, pts in d.rays if abs(pts[-1][0] - z) < 1e-6]
    assert landed and max(abs(h) for h in landed) <= top + 1e-9
    assert ax.get_ylim()[1] >= top  # and the view shows it


@pytest.mark.parametrize("slug", ["dgauss_50mm", "nikkor_fisheye_16mm_f2_8"])
def test_the_figure_shows_that_drawing(slug):
    """:meth:`LensDiagram.figure` at that width: the same lines (the film's among them) and view limits."""
    d = lens_diagram(load_lens(slug))
    ax, fig_ax = _drawing(d), d.figure(width_in=WIDTH_IN).axes[0]
    assert _film_top(d, fig_ax) == _film_top(d, ax)
    assert [ln.get_xydata().tolist() for ln in fig_ax.get_lines()] == [ln.get_xydata().tolist() for ln in ax.get_lines()]
    assert fig_ax.get_xlim() == ax.get_xlim() and fig_ax.get_ylim() == ax.get_ylim()
