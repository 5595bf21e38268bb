"""Real-ray depth of field (issue 39 item 4): the focusing convention and sampling until converged.

Before: the lens was focused paraxially, so dgauss_50mm at f/2.8 and 3 m read 2.601-2.976 m, the
mark outside its own sharp zone; and each blur was traced with 32 x 32 rays per beam, so the
Distagon 35 at f/4 and 2 m read its near limit 1876 mm where finer sampling and an independent
trace give 1886-1887 mm.

The independent trace here: rays from the on-axis point to a fine square grid (400 x 400) over
1.3 times the paraxial entrance pupil, clipped by the lens's apertures and its iris, traced to the
film by physcam's tracer; the 80 % energy diameter about their centroid; the limit by bisection on
1 / distance. Nothing of physcam.analysis.defocus.real_dof or .centroid is used.
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

from physcam.analysis.defocus.real_dof import real_depth_of_field
from physcam.cli import main
from physcam.lens.library import load_lens
from physcam.optics import focusing as focusing_mod
from physcam.optics.paraxial import gaussian
from physcam.optics.state import camera_state
from physcam.trace import RayBatch, trace_to_film

pytestmark = pytest.mark.slow

S35_COC = math.hypot(24.89, 18.66) / 1500.0


def _blur80(lens, mark, fstop, d_from_film, film_shift=0.0, n=400):
    """80 % energy diameter (mm) on the film of an on-axis point ``d_from_film`` in front of it."""
    st = focusing_mod.focus(lens, mark)
    q = st.prescription
    film_z = st.film_z + film_shift
    iris = focusing_mod.iris_semi_diameter(lens, fstop)
    g = gaussian(q, object_z=st.object_z, film_z=st.film_z)
    r = 1.3 * g.entrance_pupil_diameter / 2 * iris / q.surfaces[q.stop_index].semi_diameter
    u = (np.arange(n) + 0.5) / n * 2 - 1
    X, Y = np.meshgrid(u * r, u * r)
    inside = X * X + Y * Y <= r * r
    tgt = np.stack([X[inside], Y[inside], np.full(inside.sum(), g.z_entrance_pupil)], axis=1)
    start = np.zeros_like(tgt)
    start[:, 2] = film_z - d_from_film
    out = trace_to_film(q, RayBatch.from_arrays(start, tgt - start, lens.wavelength_nm), film_z, clip=True,
                        stop_semi_diameter=iris, fresnel=False)
    x, y = out.x[out.ok], out.y[out.ok]
    assert x.size > 1000 and out.ok.sum() < inside.sum()  # the iris, not the grid, cuts the beam
    rad = np.sort(np.hypot(x - x.mean(), y - y.mean()))
    return 2.0 * rad[int(math.ceil(0.8 * rad.size)) - 1]


#: Halvings of the 1 / distance bracket: the brackets here (1/2000-1/1700, 1/2100-1/2600 and
#: 1/3000-1/2500 per mm) end within 0.04 mm, 20 times finer than the tightest tolerance (the
#: near limit's 1885-1888.5 mm and rel 1e-3); 22 until round 14 (0.0001 mm, 8 traces a limit more)
BISECTIONS = 14


def _limit(lens, mark, fstop, inside_mm, outside_mm, film_shift=0.0):
    """The distance between ``inside_mm`` (blur below the CoC) and ``outside_mm`` where the blur is the CoC."""
    a, b = 1.0 / inside_mm, 1.0 / outside_mm
    assert _blur80(lens, mark, fstop, inside_mm, film_shift) < S35_COC < _blur80(lens, mark, fstop, outside_mm,
                                                                                   film_shift)
    for _ in range(BISECTIONS):
        m = 0.5 * (a + b)
        if _blur80(lens, mark, fstop, 1.0 / m, film_shift) < S35_COC:
            a = m
        else:
            b = m
    return 2.0 / (a + b)


def test_distagon_near_limit_converges_to_the_independent_trace():
    lens = load_lens("zeiss_distagon_35mm_f4")
    d = real_depth_of_field(camera_state(lens, focus_mm=2000.0, fstop=4.0), coc_mm=S35_COC, measure="energy",
                            focusing="paraxial")
    assert d.converged and d.pupil_grid > 32
    near = _limit(lens, 2000.0, 4.0, 2000.0, 1700.0)
    far = _limit(lens, 2000.0, 4.0, 2100.0, 2600.0)
    assert 1885.0 < near < 1888.5  # the 1886-1887 mm
    assert d.near_from_film_mm == pytest.approx(near, rel=1e-3)
    assert d.far_from_film_mm == pytest.approx(far, rel=1e-3)


def test_collimated_lens_is_sharpest_at_its_mark():
    lens = load_lens("dgauss_50mm")
    d = real_depth_of_field(camera_state(lens, focus_mm=3000.0, fstop=2.8), coc_mm=S35_COC, measure="energy")
    assert d.focusing == "collimated"
    assert d.sharpest_from_film_mm == pytest.approx(3000.0, rel=2e-3)
    assert d.near_from_film_mm < 3000.0 < d.far_from_film_mm  # paraxially it read 2.601-2.976 m
    # the double Gauss's spherical aberration: its best focus lies in front of the paraxial image
    assert -0.1 < d.film_shift_mm < -0.03
    near = _limit(lens, 3000.0, 2.8, 3000.0, 2500.0, d.film_shift_mm)
    assert d.near_from_film_mm == pytest.approx(near, rel=1.5e-3)


def test_report_says_the_focusing_and_the_band_in_words(capsys):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["report", "--lens", "dgauss_50mm", "--fstop", "2.8", "--focus", "3m", "--dof", "real",
                     "--sensor", "S35", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    real = doc["dof_real"]
    assert real["focusing"] == "collimated" and real["centre"]["focusing"] == "collimated"
    c = real["centre"]
    model_mid = 0.5 * (doc["dof"]["near_from_film_mm"] + doc["dof"]["far_from_film_mm"])
    assert c["band_shift_mm"] == pytest.approx(0.5 * (c["near_from_film_mm"] + c["far_from_film_mm"]) - model_mid)
    assert main(["report", "--lens", "dgauss_50mm", "--fstop", "2.8", "--focus", "3m", "--dof", "real",
                 "--sensor", "S35"]) == 0
    out = capsys.readouterr().out
    assert "real-ray focusing" in out and "collimated: the lens's best focus at the mark" in out
    assert "mm nearer" in out or "mm farther" in out
