"""Issue 39 item 9: the lens diagram's chief ray lands on the drawn film.

The film was drawn as tall as the largest element (dgauss_50mm: +-12.6 mm) while the widest
unvignetted field's chief ray lands 21 mm off axis, beyond it. Checked on the drawing itself: every
traced ray that reaches the film plane ends within the film line matplotlib draws."""

from __future__ import annotations

import numpy as np
import pytest

from physcam.analysis.lens_cards.diagram import lens_diagram
from physcam.lens.library import list_lenses, load_lens


@pytest.mark.parametrize("slug", [r.slug for r in list_lenses()])
def test_rays_land_on_the_drawn_film(slug):
    d = lens_diagram(load_lens(slug))
    fig = d.figure(width_in=6.0)
    ax = fig.axes[0]
    z = d.gaussian.z_film
    film = [ln for ln in ax.get_lines() if np.allclose(ln.get_xdata(), z) and len(ln.get_xdata()) == 2
            and ln.get_ydata()[0] < 0 < ln.get_ydata()[1]]
    assert len(film) == 1
    top = film[0].get_ydata()[1]
    landed = [pts[-1][1] for _, pts in d.rays if abs(pts[-1][0] - z) < 1e-6]
    assert landed and max(abs(h) for h in landed) <= top + 1e-9
    assert ax.get_ylim()[1] >= top  # and the view shows it
