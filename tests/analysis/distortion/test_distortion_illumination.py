"""Real distortion and relative illumination against closed forms (tests/analysis/_analysis_lenses.py)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.analysis._chief import aim_from_infinity, field_direction
from physcam.analysis.distortion.field import fit_standard_distortion, real_distortion
from physcam.analysis.image_quality.illumination import relative_illumination
from physcam.errors import InputError, OpticsError
from physcam.lens.library import load_lens
from physcam.optics.paraxial import stop_semi_diameter_for_fstop
from physcam.optics.state import as_designed
from physcam.trace import RayBatch, trace_through

from _analysis_lenses import concentric


@pytest.fixture(scope="module")
def dgauss():
    return load_lens("dgauss.50mm")


@settings(max_examples=8, deadline=None)
@given(st.floats(1.0, 45.0))
def test_concentric_sphere_has_no_distortion(theta):
    # chief ray through the nodal point (centre of curvature): h = EFL tan(theta), EFL = R / (n - 1) = 100
    r = real_distortion(concentric(), [theta])
    p = r.points[0]
    assert r.efl_y_mm == pytest.approx(100.0, rel=1e-12)
    assert p.real_height_mm == pytest.approx(100.0 * math.tan(math.radians(theta)), rel=1e-9)
    assert abs(p.distortion_pct) < 1e-7


def test_chief_rays_pass_the_stop_centre(dgauss):
    aimed = aim_from_infinity(dgauss, field_direction(np.radians([3.0, 12.0, 21.0])), wavelength_nm=587.5618)
    k = dgauss.stop_index
    out = trace_through(dgauss.with_surfaces(dgauss.surfaces[: k + 1]),
                        RayBatch.from_arrays(aimed.start, aimed.direction), clip=False)
    assert aimed.ok.all()
    assert np.hypot(out.x, out.y).max() < 1e-8


def test_distortion_is_third_order_at_small_fields(dgauss):
    # Seidel: percent distortion grows as tan^2(theta) near the axis
    r = real_distortion(dgauss, [0.5, 1.0])
    d1, d2 = (p.distortion_pct for p in r.points)
    assert d2 / d1 == pytest.approx(4.0, rel=2e-3)


def test_fit_reproduces_traced_distortion(dgauss):
    r = real_distortion(dgauss)
    assert len(r.points) == 15 and r.points[0].distortion_pct == 0.0
    fitted = r.fit.distortion_pct([p.paraxial_height_mm for p in r.points])
    traced = np.array([p.distortion_pct for p in r.points])
    assert np.abs(fitted - traced).max() < 0.005  # percent
    assert r.fit.max_residual_pct < 0.005
    # the fit is exact for data made by the model itself
    f = fit_standard_distortion([3.0, 9.0, 18.0], [100 * (-0.02 * x**2 + 0.003 * x**4) for x in (1 / 6, 0.5, 1.0)], 18.0)
    assert (f.k1, f.k2) == pytest.approx((-0.02, 0.003), abs=1e-12)
    usd = r.fit.usd_attributes()
    assert usd["lensDistortion:type"] == "standard" and usd["lensDistortion:k1"] == r.fit.k1


def test_anamorphic_has_both_meridians():
    r = real_distortion(load_lens("navarro_anamorphic_2x"), n_fields=4)
    assert {p.axis for p in r.points} == {"x", "y"}
    assert r.efl_x_mm != pytest.approx(r.efl_y_mm, rel=0.1)
    assert all(math.isfinite(p.distortion_pct) for p in r.points)


def test_fields_the_lens_cannot_image_are_refused(dgauss):
    with pytest.raises(OpticsError, match="choose fields up to"):
        real_distortion(dgauss, [40.0])
    with pytest.raises(InputError):
        real_distortion(dgauss, [90.0])
    with pytest.raises(InputError):
        real_distortion(dgauss, n_fields=1)


def test_relative_illumination_follows_cos4_without_vignetting():
    r = relative_illumination(concentric(), [0.0, 10.0, 20.0, 30.0], grid=200)
    for p in r.points:
        assert p.relative_illumination == pytest.approx(math.cos(math.radians(p.field_deg)) ** 4, rel=1e-3)
        assert p.vignetting_factor == pytest.approx(1.0, abs=1e-3)
    # dA/d(omega) of a distortion-free lens: f^2 / cos^3(theta) (mm^2 per steradian)
    for p in r.points:
        assert p.mapping_mm2_per_sr == pytest.approx(100.0**2 / math.cos(math.radians(p.field_deg)) ** 3, rel=1e-6)


def test_relative_illumination_of_a_real_lens(dgauss):
    full = relative_illumination(dgauss, [0.0, 8.0, 16.0], grid=120)
    sd = stop_semi_diameter_for_fstop(dgauss, 8.0)
    slow = relative_illumination(as_designed(dgauss, stop_semi_diameter=sd), [0.0, 8.0, 16.0], grid=120)
    assert full.points[0].relative_illumination == 1.0
    ri = [p.relative_illumination for p in full.points]
    assert ri[0] > ri[1] > ri[2] > 0
    # stopping down removes vignetting by the element rims: more light off axis
    for a, b in zip(full.points[1:], slow.points[1:]):
        assert b.vignetting_factor > a.vignetting_factor
        assert b.relative_illumination > a.relative_illumination
    assert all(np.isfinite([p.relative_illumination for p in slow.points]))
    with pytest.raises(OpticsError):
        relative_illumination(dgauss, [60.0], grid=32)
    with pytest.raises(InputError):
        relative_illumination(dgauss, [0.0], grid=4)
