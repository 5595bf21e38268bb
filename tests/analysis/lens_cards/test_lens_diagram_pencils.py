"""Every ray the lens diagram draws for the default field reaches the film (a first-day review saw
stray light-blue stubs at the lower left: rim rays aimed at the paraxial pupil's edge of a vignetted
field, stopped outside the front element's clear aperture)."""

import matplotlib.colors as mcolors
import pytest

from physcam.analysis.lens_cards.diagram import lens_diagram
from physcam.figures import PALETTE
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state


@pytest.mark.parametrize("name", ["dgauss_50mm", "cooke_triplet_50mm_f4_5", "fisheye_10mm"])
def test_every_drawn_ray_line_ends_on_the_film(name):
    d = lens_diagram(camera_state(load_lens(name)))
    fig = d.figure()
    ray_colours = {mcolors.to_hex(PALETTE[i]) for i in (1, 2, 5)}  # marginal, chief, rim
    rays = [ln for ln in fig.axes[0].lines if mcolors.to_hex(ln.get_color()) in ray_colours
            and len(ln.get_xdata()) > 2]
    assert len(rays) == 6  # three marginal rays, the chief ray and two rim rays
    for ln in rays:  # the matplotlib artist itself: its last point on the film plane
        assert ln.get_xdata()[-1] == pytest.approx(d.gaussian.z_film, abs=1e-6)
    rims = [pts for kind, pts in d.rays if kind == "rim"]
    assert len(rims) == 2 and rims[0][0][1] > rims[1][0][1]  # the upper rim first, then the lower


def test_diagram_prints_where_it_wrote(tmp_path, capsys):
    from physcam.cli import main

    out = tmp_path / "d.png"
    assert main(["lens", "diagram", "--lens", "cooke_triplet_50mm_f4_5", "-o", str(out)]) == 0
    assert out.stat().st_size > 0 and capsys.readouterr().out.strip() == f"wrote {out}"
