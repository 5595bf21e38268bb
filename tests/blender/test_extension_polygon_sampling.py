"""The extension's OSL camera samples a bladed iris's polygon instead of the round iris's ellipse where the
iris alone bounds the passing set (physcam_lens.osl.in, "the polygon"): the polygon must hold every ray the
lens passes, or the picture loses light. The oracle is physcam's tracer run the plain way with the bladed
aperture (physcam.trace.aperture.Aperture) on a dense grid of aim points about the ellipse, at the lens
state the shader blends (two focus states), random f-stop, film radius, blade count, rotation and
roundness; the shader's choice and polygon are written here again from its text (the fill of the round
iris's ellipse, the polygon's scale, and which way the stop's image turns: a paraxial ray's height at the
stop)."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.export.blender_focus import focus_table
from physcam.export.blender_pupil import cell_area, interpolated_area, interpolated_ellipse
from physcam.export.osl import template_text
from physcam.lens.library import load_lens
from physcam.optics.focusing import focus
from physcam.trace.aperture import Aperture
from physcam.trace.rays import OK, RayBatch
from physcam.trace.surfaces import surface_table
from physcam.trace.trace import trace_through

pytestmark = pytest.mark.slow

#: the shader's #defines: the fill that picks the polygon, and the polygon's growth
POLY_FILL, POLY_GROW = (float(re.search(rf"^#define {name} (\S+)$", template_text(), re.M).group(1))
                        for name in ("POLY_FILL", "POLY_GROW"))


#: the double Gauss, and the lens whose stop's image strays farthest from the ellipse's polygon of the
#: bundled ones tried (2026-11-29, 150 random cases each: the double Gauss, Canon RF 85, Sigma 28, Zeiss
#: Distagon 35, the 250 mm telephoto, the Nikkor fisheye and this retrofocus; where the shader picks the
#: polygon, its passing aims reach 1.036 of the ellipse's polygon here, 0.999 on the double Gauss)
LENSES = ["dgauss_50mm", "canon_wide_angle_us4310222_14mm_f2_8"]


@pytest.fixture(scope="module", params=LENSES)
def table(request):
    """(lens, a 4-state focus table, its focus states)."""
    lens = load_lens(request.param)
    ft = focus_table(lens, n_focus=4)
    return lens, ft, [focus(lens, float(m)).prescription for m in ft.marks_mm]


def _stop_turn(q, film_z: float) -> float:
    """+1 where the stop's image on the aim plane is upright, -1 where it is turned half round: the sign of
    the height at the stop of a paraxial ray from the axial film point through height 1 on the rear
    vertex plane (the shader's loop over the rows film side first)."""
    t = surface_table(q, reverse=True)
    stop = int(np.flatnonzero(t.kind == 1)[0])
    n1, n2 = t.index_before(q.wavelength_nm), t.index_after(q.wavelength_nm)
    y, u = 1.0, 1.0 / (film_z - t.vertex_z[0])
    for s in range(stop):
        c = -t.curvature[s] if t.kind[s] >= 2 else 0.0
        u = (n1[s] * u - y * c * (n2[s] - n1[s])) / n2[s]
        y += u * (t.vertex_z[s] - t.vertex_z[s + 1])
    return -1.0 if y < 0 else 1.0


def _shader_polygon(ft, k0, fw, rho, s, ap):
    """(polygon's corner scale or 0 where the shader samples the ellipse, cx, ax, ay) as the shader reads them."""
    reads = []
    for k in (k0, k0 + 1):
        raw = ft.radial[k].copy()
        raw[..., 3] = cell_area(raw[..., 3])  # the fill reads the area whether or not the cell is trusted
        reads.append((interpolated_ellipse(ft.radial[k], ft.levels, rho, s), interpolated_area(raw, ft.levels, rho, s)))
    (e0, a0), (e1, a1) = reads
    cx, ax, ay = (1 - fw) * e0 + fw * e1
    bump = fw * (1 - fw) * abs(e1[0] - e0[0])
    fill = ((1 - fw) * a0 + fw * a1) / (math.pi * ax * ay)
    c = math.cos(math.pi / ap.nsides)
    kp = POLY_GROW * (1 + ap.roundness * (1 - c) / c)
    poly = kp * kp * 0.5 * ap.nsides * math.sin(2 * math.pi / ap.nsides)
    return (kp if poly < math.pi and fill >= POLY_FILL else 0.0), cx, ax + bump, ay + bump


@settings(max_examples=40, deadline=None)
@given(k=st.floats(0.0, 0.999), fw=st.floats(0.0, 1.0), log_n=st.floats(0.0, 1.0), rho=st.floats(0.0, 21.6),
       blades=st.integers(5, 9), angle=st.floats(0.0, 360.0), roundness=st.sampled_from([0.0, 0.3]))
def test_the_sampled_polygon_holds_every_passing_ray(table, k, fw, log_n, rho, blades, angle, roundness):
    """No ray the lens passes through the bladed iris (film point (rho, 0), f/2 to f/22) aims outside the
    polygon the shader samples there; and where the shader samples it, the polygon is drawn the right
    way round (an odd blade count turned half round would leave its corners' rays out)."""
    lens, ft, states = table
    k0 = int(k * (len(states) - 1))
    q = states[k0].with_surfaces([dataclasses.replace(a, thickness=(1 - fw) * a.thickness + fw * b.thickness)
                                  for a, b in zip(states[k0].surfaces, states[k0 + 1].surfaces)])
    film_z = (1 - fw) * ft.film_z[k0] + fw * ft.film_z[k0 + 1]
    ap = Aperture(blades, angle, roundness)
    n = max(ft.fstop_min, 2.0) * (22.0 / max(ft.fstop_min, 2.0)) ** log_n
    s = ap.corner_semi(ft.iris_k / n, ft.levels[0])
    kp, cx, ax, ay = _shader_polygon(ft, k0, fw, rho, s, ap)
    if kp == 0.0:
        return  # the ellipse (tests/export/test_blender_pupil.py holds it to every passing ray)
    m = 160
    gx, gy = np.meshgrid(cx + ((np.arange(m) + 0.5) / m * 2 - 1) * 1.05 * ax, ((np.arange(m) + 0.5) / m * 2 - 1) * 1.05 * ay)
    gx, gy = gx.ravel(), gy.ravel()
    rays = RayBatch.from_arrays(np.broadcast_to([rho, 0.0, film_z], (gx.size, 3)),
                                np.stack([gx - rho, gy, np.full(gx.size, q.vertex_z[-1] - film_z)], axis=1),
                                q.wavelength_nm)
    trace_through(q, rays, reverse=True, clip=True, stop_semi_diameter=s, aperture=ap, in_place=True)
    ok = rays.flag == OK
    # the aim's stop-plane direction (film point on +x: radial = x, tangential = y), over the polygon's scale
    turn = _stop_turn(q, film_z)
    px, py = turn * (gx[ok] - cx) / ax, turn * gy[ok] / ay
    poly = Aperture(blades, angle)  # the sampled polygon: straight sides, corners at kp
    gauge = np.hypot(px, py) / (kp * poly.rim_radius(np.arctan2(py, px)))
    assert ok.sum() > 200
    assert gauge.max() <= 1.0, (lens.name, k0, fw, n, rho, blades, float(gauge.max()))


def test_the_polygon_is_sampled_where_the_iris_alone_bounds_the_set(table):
    """The shader picks the polygon stopped down (f/5.6 and f/11, the axis to 10 mm: the set is the iris's
    image) and keeps the ellipse wide open off axis (f/2.8 at 15-20 mm: other surfaces cut the set, and
    the polygon drawn on its ellipse would leave passing rays out), so the test above is not vacuous."""
    lens, ft, states = table
    ap = Aperture(5, 0.0)
    for n in (5.6, 11.0):
        for rho in (0.0, 5.0, 10.0):
            assert _shader_polygon(ft, 1, 0.5, rho, ap.corner_semi(ft.iris_k / n, ft.levels[0]), ap)[0] > 0, (n, rho)
    for rho in (15.0, 20.0):
        assert _shader_polygon(ft, 1, 0.5, rho, ap.corner_semi(ft.iris_k / 2.8, ft.levels[0]), ap)[0] == 0, rho
