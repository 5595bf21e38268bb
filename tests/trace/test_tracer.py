"""The real ray tracer against hand-worked optics and independent computations."""

import math

import numpy as np
import pytest

from physcam.errors import InputError, OpticsError
from physcam.lens.geometry import sag
from physcam.lens.prescription import Medium, Prescription, Surface
from physcam.trace import CLIPPED, MISSED, OK, TIR, RayBatch, paraxial_image_z, trace_through, trace_to_film

from _trace_lenses import DGAUSS_BFL, DGAUSS_ROWS, equal_area_disk

BACKENDS = ["numba", "numpy"]


def single_sphere(radius=50.0, n=1.5, semi=20.0, kind="spherical", **kw):
    return Prescription((Surface(radius, 100.0, Medium(n, 0.0), semi, kind, **kw),))


@pytest.mark.parametrize("backend", BACKENDS)
def test_single_sphere_snell_by_hand(backend):
    # Ray parallel to the axis at height h meets a sphere of radius R (centre at z = R):
    # hit z = R - sqrt(R^2 - h^2); incidence sin i = h / R; sin r = sin i / n; the refracted ray
    # makes the angle i - r with the axis, bending toward it.
    R, n, h = 50.0, 1.5, 10.0
    out = trace_through(single_sphere(R, n), RayBatch.collimated([0.0], [h], -5.0), backend=backend)
    i = math.asin(h / R)
    r = math.asin(math.sin(i) / n)
    assert out.flag[0] == OK
    assert out.z[0] == pytest.approx(R - math.sqrt(R * R - h * h), abs=1e-12)
    assert out.y[0] == pytest.approx(h, abs=1e-12)
    assert out.M[0] == pytest.approx(-math.sin(i - r), abs=1e-12)
    assert out.N[0] == pytest.approx(math.cos(i - r), abs=1e-12)
    assert out.L[0] == 0.0


@pytest.mark.parametrize("backend", BACKENDS)
def test_flat_surface_snell_and_fresnel_at_brewster(backend):
    # n1 sin(t1) = n2 sin(t2) at a plane; at Brewster's angle tan(t1) = n2/n1 the p reflectance
    # vanishes and R = rs^2 / 2 with rs = -sin(t1 - t2) / sin(t1 + t2) (Hecht eq. 4.42).
    n = 1.5
    t1 = math.atan(n)
    lens = Prescription((Surface(0.0, 10.0, Medium(n, 0.0), 50.0, "flat"),))
    rays = RayBatch.from_arrays([[0.0, -1.0, -1.0]], [[0.0, math.sin(t1), math.cos(t1)]])
    out = trace_through(lens, rays, fresnel=True, backend=backend)
    t2 = math.asin(math.sin(t1) / n)
    assert out.M[0] == pytest.approx(math.sin(t2), abs=1e-13)
    rs = -math.sin(t1 - t2) / math.sin(t1 + t2)
    assert out.weight[0] == pytest.approx(1.0 - rs * rs / 2, abs=1e-13)
    assert 1.0 - out.weight[0] == pytest.approx(0.0740, abs=1e-4)


@pytest.mark.parametrize("backend", BACKENDS)
def test_glass_plate_normal_incidence_transmission(backend):
    # Two uncoated faces at normal incidence: T = (1 - ((n-1)/(n+1))^2)^2 = 0.96^2 for n = 1.5.
    lens = Prescription(
        (Surface(0.0, 5.0, Medium(1.5, 0.0), 10.0, "flat"), Surface(0.0, 5.0, Medium(), 10.0, "flat"))
    )
    out = trace_through(lens, RayBatch.collimated([0.0, 3.0], [0.0, 1.0], -1.0), fresnel=True, backend=backend)
    np.testing.assert_allclose(out.weight, 0.96**2, rtol=0, atol=1e-14)


@pytest.mark.parametrize("backend", BACKENDS)
def test_total_internal_reflection_is_flagged_not_nan(backend):
    # Inside glass (n = 1.5) a ray parallel to the axis at height 10 meets a sphere of radius 12
    # at sin i = 10/12 > 1/1.5: total internal reflection. At height 5, sin i = 5/12: it passes.
    lens = Prescription(
        (Surface(0.0, 20.0, Medium(1.5, 0.0), 11.0, "flat"), Surface(-12.0, 10.0, Medium(), 11.0, "spherical"))
    )
    out = trace_through(lens, RayBatch.collimated([0.0, 0.0], [10.0, 5.0], -1.0), end_z=40.0, backend=backend)
    assert out.flag.tolist() == [TIR, OK]
    assert out.weight[0] == 0.0 and out.weight[1] == 1.0
    for a in out.columns()[:8]:
        assert np.isfinite(a).all()


@pytest.mark.parametrize("backend", BACKENDS)
def test_clipped_and_missed_rays_are_flagged_and_finite(backend, dgauss):
    ys = np.array([0.0, 13.0, 30.0, 500.0])
    out = trace_to_film(dgauss, RayBatch.collimated(np.zeros(4), ys, -1.0), backend=backend)
    assert out.flag[0] == OK
    assert (out.flag[1:] != OK).all()
    assert (out.weight[1:] == 0).all()
    assert out.flag[1] == CLIPPED and out.flag[3] == MISSED
    for a in out.columns()[:8]:
        assert np.isfinite(a).all()


def paraxial_abcd(rows):
    """Independent y-nu paraxial trace (Smith, Modern Optical Engineering, ch. 3) of pbrt rows.

    Returns (effective focal length, back focal distance from the last vertex).
    """
    y, nu, n = 1.0, 0.0, 1.0
    for i, (r, t, nn, _ap) in enumerate(rows):
        n2 = 1.0 if nn == 0 else nn
        c = 0.0 if r == 0 else 1.0 / r
        nu = nu - y * (n2 - n) * c
        n = n2
        if i < len(rows) - 1:
            y = y + t * nu / n
    u = nu / n
    return -1.0 / u, -y / u


def test_paraxial_limit_matches_known_focus(dgauss):
    efl, bfl = paraxial_abcd(DGAUSS_ROWS)
    assert bfl == pytest.approx(DGAUSS_BFL, abs=1e-4)
    z = paraxial_image_z(dgauss)
    assert z - dgauss.vertex_z[-1] == pytest.approx(bfl, abs=1e-8)
    # focal length from a near-axis real ray: f = h / tan(u')
    out = trace_through(dgauss, RayBatch.collimated([0.0], [1e-4], -1.0), clip=False)
    assert 1e-4 / (-out.M[0] / out.N[0]) == pytest.approx(efl, rel=1e-7)


@pytest.mark.parametrize("backend", BACKENDS)
def test_forward_then_backward_returns_to_start(backend, dgauss):
    rng = np.random.default_rng(5)
    n = 2000
    r = 9.0 * np.sqrt(rng.random(n))
    p = 2 * np.pi * rng.random(n)
    ang = np.radians(8.0) * rng.random(n)
    start = np.stack([r * np.cos(p), r * np.sin(p), np.full(n, -10.0)], axis=1)
    dirn = np.stack([np.sin(ang), np.zeros(n), np.cos(ang)], axis=1)
    wl = rng.uniform(450, 650, n)
    glass = trace_through(dgauss, RayBatch.from_arrays(start, dirn, wl), end_z=70.0, backend=backend)
    ok = glass.ok
    assert ok.sum() > n // 2
    back = glass.take(ok)
    back.L, back.M, back.N = -back.L, -back.M, -back.N
    home = trace_through(dgauss, back, reverse=True, end_z=-10.0, backend=backend)
    assert home.ok.all()
    np.testing.assert_allclose(home.x, start[ok, 0], atol=1e-9)
    np.testing.assert_allclose(home.y, start[ok, 1], atol=1e-9)
    np.testing.assert_allclose(-home.L, dirn[ok, 0], atol=1e-12)
    np.testing.assert_allclose(-home.N, dirn[ok, 2], atol=1e-12)


def test_dgauss_on_axis_rms_spot_radius(dgauss):
    # Issue 5 acceptance: 6.7099 um +- 0.001 at the paraxial image plane, wavelength d,
    # rays filling a disk of 11 mm radius uniformly (deterministic equal-area sampling).
    x, y = equal_area_disk(11.0, 300)
    film = dgauss.vertex_z[-1] + DGAUSS_BFL
    out = trace_to_film(dgauss, RayBatch.collimated(x, y, -1.0, wavelength_nm=587.5618), film)
    assert out.ok.all()
    rms = np.sqrt(((out.x - out.x.mean()) ** 2 + (out.y - out.y.mean()) ** 2).mean())
    assert rms * 1000 == pytest.approx(6.7099, abs=0.001)


@pytest.mark.parametrize("backend", BACKENDS)
def test_even_asphere_newton_hits_the_sag_surface(backend):
    s = Surface(30.0, 10.0, Medium(1.6, 0.0), 12.0, "aspheric", conic=-0.8, aspheric=(2e-5, -3e-8, 1e-10))
    lens = Prescription((s,))
    rng = np.random.default_rng(2)
    x, y = rng.uniform(-8, 8, 200), rng.uniform(-8, 8, 200)
    out = trace_through(lens, RayBatch.collimated(x, y, -2.0, direction=(0.05, -0.02, 1.0)), backend=backend)
    assert out.ok.all()
    r = np.hypot(out.x, out.y)
    expect = np.array([sag(s, ri) for ri in r])  # independent sag (physcam.lens.geometry)
    np.testing.assert_allclose(out.z, expect, atol=1e-11)


def test_conic_closed_form_equals_newton_path():
    plain = Surface(-25.0, 10.0, Medium(1.7, 0.0), 10.0, "aspheric", conic=-1.0)
    tiny = Surface(-25.0, 10.0, Medium(1.7, 0.0), 10.0, "aspheric", conic=-1.0, aspheric=(1e-300,))
    rays = RayBatch.collimated(np.linspace(-9, 9, 37), np.linspace(9, -9, 37) * 0.3, -1.0, direction=(0.1, 0, 1))
    a = trace_through(Prescription((plain,)), rays, end_z=30.0, backend="numpy")
    b = trace_through(Prescription((tiny,)), rays, end_z=30.0, backend="numpy")
    for u, v in zip(a.columns()[:6], b.columns()[:6]):
        np.testing.assert_allclose(u, v, atol=1e-12)


@pytest.mark.parametrize("backend", BACKENDS)
def test_cylindrical_x_focuses_only_in_x(backend):
    # One cylinder (R = 20, n = 1.5) curved in X-Z: paraxial focus at n R / (n - 1) = 60 mm
    # behind the vertex in X; rays in the Y-Z plane go straight on.
    lens = Prescription((Surface(20.0, 100.0, Medium(1.5, 0.0), 15.0, "cylindrical_x"),))
    out = trace_through(lens, RayBatch.collimated([1e-3, 0.0, 0.0], [0.0, 5.0, -7.0], -1.0), backend=backend)
    assert out.ok.all()
    zc = out.z[0] - out.x[0] * out.N[0] / out.L[0]
    assert zc == pytest.approx(60.0, abs=1e-5)
    np.testing.assert_array_equal(out.M[1:], 0.0)
    np.testing.assert_array_equal(out.N[1:], 1.0)


def test_no_image_and_bad_input_are_refused():
    diverging = Prescription((Surface(-20.0, 5.0, Medium(1.5, 0.0), 10.0), Surface(0.0, 1.0, Medium(), 10.0, "flat")))
    with pytest.raises(OpticsError):
        paraxial_image_z(diverging)
    with pytest.raises(InputError):
        RayBatch.from_arrays([[0.0, 0.0, float("nan")]], [[0, 0, 1]])
    with pytest.raises(InputError):
        RayBatch.from_arrays([[0.0, 0.0, 0.0]], [[0, 0, 0]])


def test_trace_path_keeps_every_hit_and_ends_where_the_full_trace_ends(dgauss):
    # surface-by-surface tracing must land where one full trace lands (same kernel, same
    # numbers), and each recorded hit must sit on its surface (vertex z for the flat stop)
    import numpy as np

    from physcam.trace import trace_path

    rays = RayBatch.collimated([0.0, 3.0, -5.0], [0.0, 4.0, 6.0], -5.0)
    pts, out = trace_path(dgauss, rays, end_z=70.0)
    full = trace_to_film(dgauss, rays, 70.0, backend="numpy")
    assert pts.shape == (len(dgauss.surfaces) + 2, 3, 3)
    np.testing.assert_allclose(pts[-1], np.stack([full.x, full.y, full.z], axis=1), atol=1e-12)
    assert (out.flag == full.flag).all()
    k = dgauss.stop_index
    np.testing.assert_allclose(pts[k + 1, :, 2], dgauss.vertex_z[k], atol=1e-12)
