"""Chief-ray aiming on wide fields (issue 8, item 3): the bundled pbrt fisheye.10mm.

The independent figures: a separately written Snell tracer (``_snell.py``) follows the aimed
chief ray through every spherical surface; it must cross the stop plane at the stop centre and
land on the film where physcam's tracer says. The oracle of issue 8 has the chief ray passing to
at least 65.2 deg (the full-frame corner: atan(21.63 / 9.99)).
"""

import math

import numpy as np
import pytest

from physcam.analysis._chief import aim_from_infinity, field_direction
from physcam.analysis.distortion.field import real_distortion
from physcam.lens.library import load_lens
from physcam.trace import RayBatch, paraxial_image_z, trace_through

from _snell import trace_spherical


@pytest.fixture(scope="module")
def fisheye():
    lens = load_lens("fisheye_10mm")
    assert all(s.medium.vd == 0.0 for s in lens.surfaces)  # no dispersion: nd is the index
    assert all(s.kind in ("spherical", "stop") for s in lens.surfaces)
    return lens


@pytest.mark.parametrize("theta", [30.0, 61.8, 65.2])
def test_fisheye_chief_ray_passes_at_wide_fields(fisheye, theta):
    aimed = aim_from_infinity(fisheye, field_direction(np.radians([theta])), wavelength_nm=587.5618)
    assert aimed.ok.all()
    film = paraxial_image_z(fisheye)
    k = fisheye.stop_index
    hits, _ = trace_spherical(fisheye, aimed.start[0], aimed.direction[0], end_z=film)
    assert hits is not None
    # the independent tracer: through the stop centre, and inside every clear aperture
    assert math.hypot(hits[k][0], hits[k][1]) < 1e-6
    for s, q in zip(fisheye.surfaces, hits):
        assert math.hypot(q[0], q[1]) <= s.semi_diameter
    # physcam's tracer (clipping at every rim) lands where the independent one does
    out = trace_through(fisheye, RayBatch.from_arrays(aimed.start, aimed.direction), end_z=film, clip=True)
    assert out.ok.all()
    assert out.y[0] == pytest.approx(hits[-1][1], abs=1e-9)
    assert out.y[0] > 0  # light travelling toward +y comes from -y in the scene: inverted image at +y


def test_fisheye_field_limit_is_at_least_the_corner(fisheye):
    from physcam.analysis.framing.field_of_view import chief_ray_field_limit

    assert chief_ray_field_limit(fisheye) >= 65.2
    r = real_distortion(fisheye, sensor_width_mm=36.0, sensor_height_mm=24.0)  # 15 fields to the full-frame corner, 65.21 deg
    assert r.points[-1].field_deg == pytest.approx(math.degrees(math.atan(math.hypot(18, 12) / r.efl_y_mm)), abs=1e-9)
    assert not r.notes[:1] or "pass only" not in r.notes[0]


def test_fisheye_field_limit_is_where_the_chief_ray_meets_the_front_rim(fisheye):
    from physcam.analysis.framing.field_of_view import chief_ray_field_limit

    limit = chief_ray_field_limit(fisheye)  # beyond the full-frame corner: searched up to 89 deg
    assert 65.2 < limit < 89.0
    # independent: the Snell tracer follows the aimed chief rays just inside and just outside the limit
    dirs = field_direction(np.radians([limit, limit + 0.02]))
    aimed = aim_from_infinity(fisheye, dirs, wavelength_nm=587.5618)
    assert aimed.ok.all()  # aimed without clipping: both cross the stop centre
    heights = []
    for start, d in zip(aimed.start, dirs):
        hits, _ = trace_spherical(fisheye, start, d)
        assert math.hypot(*hits[fisheye.stop_index][:2]) < 1e-6
        heights.append([math.hypot(q[0], q[1]) for q in hits])
    rims = [s.semi_diameter for s in fisheye.surfaces]
    assert all(hh <= r for hh, r in zip(heights[0], rims))  # inside every clear aperture at the limit
    assert heights[1][0] > rims[0]  # 0.02 deg further the chief ray meets the front element outside its rim
    assert all(hh <= r for hh, r in zip(heights[1][1:], rims[1:]))
