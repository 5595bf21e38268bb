"""The diagram's own meridional real-ray trace, against closed forms and published data."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "optics"))
from _gauss_lenses import dgauss, stop  # noqa: E402

from physcam.analysis.lens_cards.diagram import lens_diagram, trace_meridional_ray  # noqa: E402
from physcam.lens.prescription import AIR, Medium, Prescription, Surface  # noqa: E402


def test_near_axis_real_ray_crosses_at_the_published_back_focus():
    # a real ray 0.01 mm off axis behaves paraxially: after the last surface it crosses
    # the axis at F', BFL = 36.1059 mm behind the last vertex (track 32.04 mm)
    pts = trace_meridional_ray(dgauss(), 0.01, -10.0, 0.0, 1.0, film_z=100.0)
    assert len(pts) == 13  # start, 11 surfaces, film
    (z1, y1), (z2, y2) = pts[-2], pts[-1]
    z_cross = z1 - y1 * (z2 - z1) / (y2 - y1)
    assert z_cross == pytest.approx(32.04 + 36.1059, abs=1e-3)


def test_refraction_at_a_sphere_obeys_snell():
    # a ray parallel to the axis at height h meets a sphere of radius R at incidence asin(h/R)
    r, n, h = 40.0, 1.5, 10.0
    p = Prescription((stop(0.0, 20.0), Surface(r, 30.0, Medium(n, 0.0), 20.0), Surface(0.0, 0.0, AIR, 20.0, "flat")))
    pts = trace_meridional_ray(p, h, -5.0, 0.0, 1.0)
    (za, ya), (zb, yb) = pts[2], pts[3]
    assert za == pytest.approx(r - math.sqrt(r * r - h * h), rel=1e-9)
    i = math.asin(h / r)
    t = math.asin(math.sin(i) / n)
    slope = math.tan(i - t)  # the ray bends toward the axis by i - i'
    assert (yb - ya) / (zb - za) == pytest.approx(-slope, rel=1e-7)


def test_diagram_rays_reach_the_film_on_axis():
    d = lens_diagram(dgauss(), rays=3)
    marginal = [pts for kind, pts in d.rays if kind == "marginal"]
    assert len(marginal) == 3
    for pts in marginal:  # spherical aberration of an f/2 double Gauss: well under 0.2 mm at paraxial focus
        assert pts[-1][0] == pytest.approx(32.04 + 36.1059, abs=1e-3)
        assert abs(pts[-1][1]) < 0.2
