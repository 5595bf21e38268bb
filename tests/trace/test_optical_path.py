"""The kernels' optical path (``opl``): a closed form through a plate, the sum of n (p' - p) . d
over legs traced one surface at a time (the pupil engine's former method), and the numba and numpy
kernels bit for bit."""

import math

import numpy as np
import pytest

from physcam.lens.library import load_lens
from physcam.lens.prescription import Medium, Prescription, Surface
from physcam.trace import OK, RayBatch
from physcam.trace.kernels import c_available, get_kernel, numba_available
from physcam.trace.kernels._layout import pack
from physcam.trace.surfaces import surface_table
from physcam.trace.tables import packed_table
from physcam.trace.trace import trace_packed

BACKENDS = ["numpy"] + (["numba"] if numba_available() else []) + (["c"] if c_available() else [])


def fan(n, seed, sd, mixed):
    rng = np.random.default_rng(seed)
    p = np.stack([rng.uniform(-sd, sd, n), rng.uniform(-sd, sd, n), np.full(n, -3.0)], axis=1)
    d = np.stack([rng.normal(0, 0.15, n), rng.normal(0, 0.15, n), np.ones(n)], axis=1)
    return RayBatch.from_arrays(p, d, rng.uniform(420, 680, n) if mixed else 546.1)


@pytest.mark.parametrize("backend", BACKENDS)
def test_plate_path_is_the_closed_form(backend):
    # stop at z = 0, a flat plate of index 1.5 (non-dispersive) from z = 2 to z = 12: a ray from
    # z = -3 at angle u to the axis has the path 5 / cos u in air and 1.5 * 10 / cos u' in glass,
    # sin u' = sin u / 1.5 (Snell)
    lens = Prescription((Surface(0.0, 2.0, Medium(), 20.0, "stop"), Surface(0.0, 10.0, Medium(1.5, 0.0), 20.0, "flat"),
                         Surface(0.0, 5.0, Medium(), 20.0, "flat")))
    u = np.radians(np.linspace(0.0, 40.0, 9))
    rays = RayBatch.from_arrays(np.zeros((u.size, 3)) + [0.0, 0.0, -3.0],
                                np.stack([np.zeros_like(u), np.sin(u), np.cos(u)], axis=1), 550.0)
    p = packed_table(lens)
    opl = np.zeros(u.size)
    trace_packed(get_kernel(backend), rays, p.S, p.kinds, clip=True, fresnel=False, end_z=None, opl=opl)
    assert (rays.flag == OK).all()
    expect = 5.0 / np.cos(u) + 15.0 / np.cos(np.arcsin(np.sin(u) / 1.5))
    np.testing.assert_allclose(opl, expect, rtol=1e-14, atol=0)


def legwise(lens, rays):
    """Sum of n (p' - p) . d per leg, tracing one surface at a time (independent of the kernels' opl)."""
    table = surface_table(lens)
    S, kinds = pack(table)
    kern = get_kernel("numpy")
    nb = np.stack([table.index_before(w) for w in rays.wavelength_nm])
    opl = np.zeros(len(rays))
    for k in range(S.shape[0]):
        x0, y0, z0, L0, M0, N0 = (a.copy() for a in rays.columns()[:6])
        trace_packed(kern, rays, S[k:k + 1], kinds[k:k + 1], clip=True, fresnel=False, end_z=None)
        opl += nb[:, k] * ((rays.x - x0) * L0 + (rays.y - y0) * M0 + (rays.z - z0) * N0)
    return opl


@pytest.mark.parametrize("slug", ["dgauss_50mm", "canon_rf_85mm_f1_2", "navarro_anamorphic_2x"])
@pytest.mark.parametrize("mixed", [False, True])
def test_path_in_one_call_is_the_sum_over_legs_and_the_kernels_agree(slug, mixed):
    lens = load_lens(slug)
    rays = fan(3000, 5, 0.6 * lens.surfaces[0].semi_diameter, mixed)
    ref = rays.copy()
    want = legwise(lens, ref)
    S, kinds = pack(surface_table(lens))
    got = {}
    for backend in BACKENDS:
        r = rays.copy()
        opl = np.zeros(len(r))
        trace_packed(get_kernel(backend), r, S, kinds, clip=True, fresnel=False, end_z=None, opl=opl)
        np.testing.assert_array_equal(r.flag, ref.flag)
        ok = r.flag == OK
        assert ok.sum() > 300
        # the same legs, summed as n t |d|^2 instead of n (p' - p) . d: equal to rounding (paths ~100 mm)
        np.testing.assert_allclose(opl[ok], want[ok], rtol=0, atol=1e-10 * math.ceil(np.abs(want[ok]).max()))
        got[backend] = opl
    if len(got) == 2:
        np.testing.assert_array_equal(got["numba"], got["numpy"])
