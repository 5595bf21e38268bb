"""Fresnel transmission of unpolarised light through several surfaces: s and p kept apart.

Expected values are worked here from Hecht's Fresnel equations (*Optics*, 5th ed., eqs.
4.42-4.43) with Snell's invariant n sin(theta) along a stack of plates, and from an independent
meridional (y-z) trace of the dgauss 50 mm written in this file; none comes from the tracer.
"""

import math

import numpy as np
import pytest

from physcam.lens.library import load_lens
from physcam.lens.prescription import Medium, Prescription, Surface
from physcam.trace import RayBatch, camera_rays, trace_through
from physcam.trace.aperture import Aperture
from physcam.trace.fresnel import fresnel_transmittance, fresnel_transmittances

BACKENDS = ["numba", "numpy"]
# air | 1.5 | 1.8 (cemented) | air | 1.6 | air: five flat interfaces
PLATE_INDICES = [1.0, 1.5, 1.8, 1.0, 1.6, 1.0]


def plate_stack():
    media = PLATE_INDICES[1:]
    return Prescription(tuple(Surface(0.0, 3.0, Medium(n, 0.0), 100.0, "flat") for n in media))


def hecht_ts_tp(n1, n2, sin_invariant):
    """T_s, T_p of the n1 -> n2 interface for a ray with n sin(theta) = ``sin_invariant``."""
    ci = math.sqrt(1.0 - (sin_invariant / n1) ** 2)
    ct = math.sqrt(1.0 - (sin_invariant / n2) ** 2)
    rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct)
    rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct)
    return 1.0 - rs * rs, 1.0 - rp * rp


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("theta_deg", [0.0, 30.0, 55.0, 70.0])
def test_plate_stack_unpolarised_transmission_by_hand(backend, theta_deg):
    th = math.radians(theta_deg)
    prod_s = prod_p = prod_mean = 1.0
    for n1, n2 in zip(PLATE_INDICES[:-1], PLATE_INDICES[1:]):
        ts, tp = hecht_ts_tp(n1, n2, math.sin(th))
        prod_s, prod_p, prod_mean = prod_s * ts, prod_p * tp, prod_mean * 0.5 * (ts + tp)
    rays = RayBatch.from_arrays([[0.0, 0.0, -1.0]], [[0.0, math.sin(th), math.cos(th)]], weight=2.0)
    out = trace_through(plate_stack(), rays, fresnel=True, backend=backend)
    assert out.ok.all()
    assert out.weight[0] == pytest.approx(2.0 * 0.5 * (prod_s + prod_p), rel=1e-12)
    assert out.weight_s[0] == pytest.approx(2.0 * prod_s, rel=1e-12)
    assert out.weight_p[0] == pytest.approx(2.0 * prod_p, rel=1e-12)
    if theta_deg >= 30.0:  # the old per-surface average is measurably wrong at oblique incidence
        assert abs(out.weight[0] - 2.0 * prod_mean) > 1e-4


def test_fresnel_transmittances_brewster_and_mean():
    n = 1.5
    tb = math.atan(n)  # Brewster: r_p = 0
    ts, tp = fresnel_transmittances(1.0, n, math.cos(tb))
    assert float(tp) == pytest.approx(1.0, abs=1e-15)
    rs = -math.sin(tb - math.asin(math.sin(tb) / n)) / math.sin(tb + math.asin(math.sin(tb) / n))
    assert float(ts) == pytest.approx(1.0 - rs * rs, abs=1e-15)
    assert float(fresnel_transmittance(1.0, n, math.cos(tb))) == pytest.approx(0.5 * (2.0 - rs * rs), abs=1e-15)
    # beyond the critical angle both vanish
    assert fresnel_transmittances(1.5, 1.0, math.cos(math.radians(60.0))) == (0.0, 0.0)


def meridional_transmission(lens, h):
    """Independent 2-D (y-z) trace of a collimated ray at height ``h`` through spheres and flats,
    with the Hecht s and p transmittances at each index change: (T_unpolarised, prod of means)."""
    y, z, my, mz, n, vz = h, -1.0, 0.0, 1.0, 1.0, 0.0
    ps = pp = pm = 1.0
    for s in lens.surfaces:
        n2, r = s.medium.nd, s.radius
        if s.kind == "stop" or r == 0.0:
            y, z, ny, nz = y + (vz - z) / mz * my, vz, 0.0, -1.0
        else:
            cz = vz + r
            b = y * my + (z - cz) * mz
            c = y * y + (z - cz) ** 2 - r * r
            roots = (-b - math.sqrt(b * b - c), -b + math.sqrt(b * b - c))
            t = min(roots, key=lambda u: abs(z + u * mz - vz))  # the cap through the vertex
            y, z = y + t * my, z + t * mz
            ny, nz = y / r, (z - cz) / r
        assert abs(y) <= s.semi_diameter
        if s.kind != "stop" and n2 != n:
            ci = abs(my * ny + mz * nz)
            sgn = 1.0 if my * ny + mz * nz > 0 else -1.0  # unit normal along the travel
            ky, kz = sgn * ny, sgn * nz
            eta = n / n2
            ct = math.sqrt(1.0 - eta * eta * (1.0 - ci * ci))
            rs = (n * ci - n2 * ct) / (n * ci + n2 * ct)
            rp = (n2 * ci - n * ct) / (n2 * ci + n * ct)
            ps, pp, pm = ps * (1 - rs * rs), pp * (1 - rp * rp), pm * (1 - 0.5 * (rs * rs + rp * rp))
            my, mz = eta * my + (ct - eta * ci) * ky, eta * mz + (ct - eta * ci) * kz
            n = n2
        vz += s.thickness
    return 0.5 * (ps + pp), pm


@pytest.mark.parametrize("backend", BACKENDS)
def test_dgauss_rim_ray_transmission_against_independent_trace(backend):
    # The marginal ray at the rim of the entrance pupil (12.47 mm; 12.478 is clipped), d line,
    # uncoated. Issue 8 quoted 0.580 for the old product of per-surface averages and 0.609 for
    # the s/p model; the independent trace here gives 0.5796 and 0.5860.
    lens = load_lens("dgauss_50mm")
    h = 12.47
    t_unpol, t_mean = meridional_transmission(lens, h)
    assert t_mean == pytest.approx(0.5796, abs=1e-4) and t_unpol == pytest.approx(0.5860, abs=1e-4)
    out = trace_through(lens, RayBatch.collimated([0.0], [h], -1.0), fresnel=True, backend=backend)
    assert out.ok.all()
    assert out.weight[0] == pytest.approx(t_unpol, rel=1e-10)


@pytest.mark.parametrize("backend", BACKENDS)
def test_aperture_density_scales_s_and_p_alike(backend):
    # A polarisation-blind factor (the aperture density at the stop) must scale both halves:
    # weight_s / weight_p is then the same with and without the density.
    lens = load_lens("dgauss_50mm")
    rng = np.random.default_rng(4)
    film = np.column_stack([rng.uniform(-10, 10, 400), rng.uniform(-8, 8, 400)])
    uv = rng.random((400, 2))
    plain = camera_rays(lens, film, uv, fresnel=True, backend=backend)
    dense = camera_rays(lens, film, uv, fresnel=True, aperture=Aperture(density=0.8), backend=backend)
    both = plain.ok & dense.ok
    assert both.sum() > 50
    a, b = plain.lens_rays, dense.lens_rays
    np.testing.assert_allclose(a.weight_s[both] * b.weight_p[both], a.weight_p[both] * b.weight_s[both],
                               rtol=1e-12, atol=0)
    assert (b.weight_sp[~b.ok] == 0).all() and (b.weight[~b.ok] == 0).all()
