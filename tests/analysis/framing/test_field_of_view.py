"""Real-ray field of view (issue 8, item 2) against independent computations.

- Forward: the chief ray of collimated light at half the real horizontal (vertical) field, aimed
  from object space (a different code path from the reverse aim from the film), must land on
  the sensor edge (top).
- The Nikkor fisheye's corner, beyond 90 deg half angle: a separately written Snell tracer
  (``_snell.py``) follows the ray from the film corner out of the lens, through the stop centre
  and every clear aperture, and measures its angle.
- Paraxial figures: 2 atan(w / 2 EFL) at infinity (Gaussian EFL), and a tiny sensor's real
  field equals the paraxial one (ABCD) at a finite focus.
"""

import json
import math

import numpy as np
import pytest

from physcam.analysis._chief import aim_from_film, aim_from_infinity, field_direction
from physcam.analysis.framing.field_of_view import chief_ray_field_limit, real_field_of_view
from physcam.errors import InputError
from physcam.lens.library import load_lens
from physcam.optics import focusing
from physcam.optics.paraxial import gaussian_xy
from physcam.trace import RayBatch, trace_through

from _snell import trace_spherical


@pytest.fixture(scope="module")
def nikkor():
    return load_lens("nikkor_fisheye_16mm_f2_8")


def _forward_height(lens, half_deg, axis, film_z):
    aimed = aim_from_infinity(lens, field_direction(np.radians([half_deg]), axis), wavelength_nm=lens.wavelength_nm)
    out = trace_through(lens, RayBatch.from_arrays(aimed.start, aimed.direction), end_z=film_z)
    assert aimed.ok.all() and out.ok.all()
    return abs(float(out.x[0] if axis == "x" else out.y[0]))


def test_fisheye_real_field_far_wider_than_paraxial(nikkor):
    r = real_field_of_view(nikkor, 36.0, 24.0)
    efl = gaussian_xy(nikkor)["x"].efl
    assert r.paraxial_horizontal_deg == pytest.approx(2 * math.degrees(math.atan(18.0 / efl)), rel=1e-9)  # 97.7
    assert r.paraxial_diagonal_deg == pytest.approx(2 * math.degrees(math.atan(math.hypot(18, 12) / efl)), rel=1e-9)
    assert 139.0 < r.horizontal_deg < 141.0  # issue 8: traced chief rays give about 140 deg
    assert r.differs_from_paraxial and r.covered and r.reason is None
    assert r.horizontal_difference_pct == pytest.approx(100 * (r.horizontal_deg / r.paraxial_horizontal_deg - 1))
    # independent: collimated light at the half angles, aimed from object space, lands on the edge and the top
    film = focusing.focus(nikkor, math.inf).film_z
    assert r.film_z_mm == pytest.approx(film)
    assert _forward_height(nikkor, r.horizontal_deg / 2, "x", film) == pytest.approx(18.0, abs=1e-6)
    assert _forward_height(nikkor, r.vertical_deg / 2, "y", film) == pytest.approx(12.0, abs=1e-6)


def test_fisheye_corner_beyond_ninety_degrees(nikkor):
    r = real_field_of_view(nikkor, 36.0, 24.0)
    assert 180.0 < r.diagonal_deg < 181.0 and math.isfinite(r.diagonal_difference_pct)
    # independent: the Snell tracer follows the chief ray from the film corner out of the lens
    assert all(s.kind in ("spherical", "flat", "stop") for s in nikkor.surfaces)
    aimed = aim_from_film(nikkor, [[18.0, 12.0]], r.film_z_mm, wavelength_nm=587.5618)
    hits, d = trace_spherical(nikkor, aimed.start[0], aimed.direction[0], reverse=True)
    assert hits is not None
    assert math.hypot(*hits[nikkor.stop_index][:2]) < 1e-6
    assert all(math.hypot(q[0], q[1]) <= s.semi_diameter for q, s in zip(hits, nikkor.surfaces))
    assert d[2] > 0  # leaving toward +z: light from behind the front vertex plane
    half = math.degrees(math.atan2(math.hypot(d[0], d[1]), -d[2]))
    assert r.diagonal_deg == pytest.approx(2 * half, abs=1e-7)
    assert json.loads(json.dumps(r.to_dict(), allow_nan=False))["diagonal_deg"] == r.diagonal_deg


def test_rectilinear_lenses_real_close_to_paraxial():
    canon = real_field_of_view(load_lens("canon_rf_85mm_f1_2"), 36.0, 24.0)
    for pct in (canon.horizontal_difference_pct, canon.vertical_difference_pct, canon.diagonal_difference_pct):
        assert abs(pct) < 1.0
    assert not canon.differs_from_paraxial
    # the double Gauss has 1 % barrel at the sensor edge: its real field is that much wider
    dg = load_lens("dgauss_50mm")
    r = real_field_of_view(dg, 36.0, 24.0)
    assert 0.0 < r.horizontal_difference_pct < 1.1 and 0.0 < r.diagonal_difference_pct < 1.6
    assert _forward_height(dg, r.horizontal_deg / 2, "y", r.film_z_mm) == pytest.approx(18.0, abs=1e-6)


def test_tiny_sensor_at_finite_focus_equals_paraxial(nikkor):
    for lens in (nikkor, load_lens("dgauss_50mm")):
        r = real_field_of_view(lens, 0.02, 0.01, focus_mm=3000.0)
        assert r.focus_from_film_mm == 3000.0
        assert r.horizontal_deg == pytest.approx(r.paraxial_horizontal_deg, rel=1e-5)
        assert r.vertical_deg == pytest.approx(r.paraxial_vertical_deg, rel=1e-5)
    # breathing: the fisheye at 3 m sees a little less than at infinity
    assert real_field_of_view(nikkor, 36, 24, focus_mm=3000.0).horizontal_deg < \
        real_field_of_view(nikkor, 36, 24).horizontal_deg


def test_film_points_outside_the_image_circle():
    fish = load_lens("fisheye_10mm")
    r = real_field_of_view(fish, 36.0, 24.0)
    assert r.horizontal_deg is None and r.diagonal_deg is None and r.vertical_deg is not None
    assert r.not_covered == ("horizontal", "diagonal") and not r.covered
    assert "image circle" in r.reason and "(18, 0)" in r.reason
    assert json.loads(json.dumps(r.to_dict(), allow_nan=False))["horizontal_deg"] is None
    # independent: the widest chief ray that passes (74.77 deg, checked with the Snell tracer in
    # test_chief_rays_wide.py) lands between the top (12 mm) and the edge (18 mm)
    limit = chief_ray_field_limit(fish)
    h = _forward_height(fish, limit, "y", r.film_z_mm)
    assert 12.0 < h < 18.0


def test_bad_input():
    lens = load_lens("dgauss_50mm")
    with pytest.raises(InputError):
        real_field_of_view(lens, -36.0, 24.0)
    with pytest.raises(InputError):
        real_field_of_view(lens, 36.0, float("nan"))
    with pytest.raises(InputError):
        real_field_of_view(lens, 36.0, 24.0, focus_mm=3000.0, film_z=100.0)
    with pytest.raises(InputError):
        real_field_of_view(lens, 36.0, 24.0, film_z=1.0)  # in front of the last vertex


def test_real_breathing_corner_beyond_ninety_degrees(nikkor):
    # breathing-real measured the corner's angle with |N|, folding 90.13 deg back to 89.87; the
    # independent Snell trace of the corner ray (test above) leaves at half of 180.26 deg
    from physcam.analysis.framing.breathing_real import real_breathing

    row = real_breathing(nikkor, [math.inf], sensor_width_mm=36.0, sensor_height_mm=24.0).rows[0]
    fov = real_field_of_view(nikkor, 36.0, 24.0)
    assert row.dfov_real_deg == pytest.approx(fov.diagonal_deg, abs=1e-9)
    assert row.dfov_real_deg > 180.0
    assert row.hfov_real_deg == pytest.approx(fov.horizontal_deg, abs=1e-9)
