"""Exit-pupil bounds and camera rays (film -> scene)."""

import numpy as np
import pytest

from physcam.trace import camera_rays
from physcam.trace.aperture import Aperture
from physcam.trace.pupil_bounds import exit_pupil_bounds


def test_bounds_keep_every_passing_ray_and_cut_waste(dgauss):
    pb = exit_pupil_bounds(dgauss, 18.0, 12.0, nx=5, ny=5, samples=32)
    rng = np.random.default_rng(4)
    n = 20_000
    film = np.stack([rng.uniform(-18, 18, n), rng.uniform(-12, 12, n)], axis=1)
    u = rng.random((n, 2))
    full = camera_rays(dgauss, film, u)
    ok = full.ok
    # every ray aimed through the full rear square that passes was aimed inside its bounds
    r = dgauss.surfaces[-1].semi_diameter
    ax, ay = -r + 2 * r * u[:, 0], -r + 2 * r * u[:, 1]
    x0, x1, y0, y1 = pb.rect_at(film[:, 0], film[:, 1])
    inside = (ax >= x0) & (ax <= x1) & (ay >= y0) & (ay <= y1)
    assert inside[ok].all()
    bounded = camera_rays(dgauss, film, rng.random((n, 2)), bounds=pb)
    assert bounded.ok.mean() > ok.mean()  # fewer wasted samples
    assert np.isfinite(bounded.origin).all() and np.isfinite(bounded.weight).all()


def test_camera_rays_on_axis_are_symmetric_and_leave_toward_the_scene(dgauss):
    u = np.random.default_rng(1).random((4000, 2))
    res = camera_rays(dgauss, np.zeros((4000, 2)), u)
    ok = res.ok
    assert ok.sum() > 500
    assert (res.direction[ok, 2] < 0).all()  # camera space looks down -Z
    assert abs(res.origin[ok, 0].mean()) < 0.3 and abs(res.origin[ok, 1].mean()) < 0.3
    hexa = camera_rays(dgauss, np.zeros((4000, 2)), u, aperture=Aperture(6, 0.0, 0.0, 0.0))
    assert hexa.ok.sum() < ok.sum()  # the hexagon is inside the circular stop
    assert (hexa.weight[~hexa.ok] == 0).all()


def test_camera_ray_weights_are_unbiased_and_match_the_pupil_solid_angle(dgauss):
    # pbrt's estimator E = cos^4(theta) A / d^2 is an unbiased Monte Carlo estimate of the
    # irradiance integral over the rear region: sampling the full rear square or only the tight
    # exit-pupil bounds must give the same mean weight. On axis that mean is the solid angle of
    # the exit pupil seen from the film in cos^4 measure, ~ pi / (4 N_w^2) with N_w the working
    # f-number (Gaussian engine), to the accuracy of the paraxial pupil.
    import math

    import numpy as np

    from physcam.optics import paraxial
    from physcam.trace import camera_rays, paraxial_image_z

    film_z = paraxial_image_z(dgauss)
    pb = exit_pupil_bounds(dgauss, 18.0, 12.0, nx=5, ny=5, samples=32)
    rng = np.random.default_rng(1)
    n = 400_000
    for xy in ((0.0, 0.0), (12.0, 8.0)):
        film = np.tile(xy, (n, 1))
        full = camera_rays(dgauss, film, rng.random((n, 2)), film_z).weight.mean()
        tight = camera_rays(dgauss, film, rng.random((n, 2)), film_z, bounds=pb).weight.mean()
        assert tight == pytest.approx(full, rel=0.02)
    g = paraxial.gaussian(dgauss)
    on_axis = camera_rays(dgauss, np.zeros((n, 2)), rng.random((n, 2)), film_z, bounds=pb).weight.mean()
    # (the f-number at infinity is the working f-number here: the film is at the focal plane)
    assert on_axis == pytest.approx(math.pi / (4 * g.f_number**2), rel=0.02)


def test_camera_rays_to_world(dgauss):
    # camera turned 90 deg about +Y (it looks down world -X) and placed at (100, 50, 0) cm: a ray
    # leaving along camera -Z leaves along world -X, from a point offset accordingly
    import math

    from physcam.trace import paraxial_image_z

    cr = camera_rays(dgauss, [[0.0, 0.0]], [[0.5, 0.5]], paraxial_image_z(dgauss))
    c, s = math.cos(math.pi / 2), math.sin(math.pi / 2)
    m = np.array([[c, 0, -s, 0], [0, 1, 0, 0], [s, 0, c, 0], [100, 50, 0, 1]])
    o, d = cr.to_world(m, mm_per_unit=10.0)
    ox, oy, oz = cr.origin[0] / 10.0
    assert o[0] == pytest.approx([100 + oz, 50 + oy, -ox], abs=1e-9)
    assert d[0] == pytest.approx([cr.direction[0][2], cr.direction[0][1], -cr.direction[0][0]], abs=1e-12)
    assert d[0][0] == pytest.approx(-1.0, abs=1e-9)  # on axis: straight out along world -X


@pytest.mark.parametrize("name", ["sony_zeiss_55mm_f1_8_za", "sigma_28mm_f1_4_art"])
def test_bounds_find_the_spot_behind_a_cover_glass(name):
    """A flat cover glass 1 mm in front of the film (Sony Zeiss 55 f/1.8, Sigma 28 f/1.4 Art) makes
    the passing rays cross the rear-vertex plane in a spot ~0.6 mm wide, under one sample spacing of
    the 46 mm rear square at 64 samples: the centre's rectangle must still hold the spot. Oracles: a
    dense trace (401 x 401 aims over +-0.6 mm), and the closed form of its half width, d / (2N) for
    the film-to-rear-vertex distance d and the lens's f-number N (paraxial marginal ray in air)."""
    import math

    from physcam.lens.library import load_lens
    from physcam.optics.focusing import gaussian_at_focus
    from physcam.trace.trace import paraxial_image_z

    q = load_lens(name)
    film_z = paraxial_image_z(q)
    r, d = q.surfaces[-1].semi_diameter, film_z - q.vertex_z[-1]
    pb = exit_pupil_bounds(q, 12.0, 8.0, film_z, nx=3, ny=3, samples=64)
    x0, x1, y0, y1 = pb.rects[1, 1]
    u = np.linspace(-0.6, 0.6, 401)
    ax, ay = [a.ravel() for a in np.meshgrid(u, u)]
    ok = camera_rays(q, np.zeros((ax.size, 2)), np.stack([(ax + r) / (2 * r), (ay + r) / (2 * r)], axis=1),
                     film_z).ok
    assert ok.sum() > 1000
    assert (ax[ok] >= x0).all() and (ax[ok] <= x1).all() and (ay[ok] >= y0).all() and (ay[ok] <= y1).all()
    half = d / (2 * gaussian_at_focus(q, math.inf).f_number)
    assert 0.5 * (x1 - x0) == pytest.approx(half, rel=0.1)
    assert (pb.rects[..., 1] > pb.rects[..., 0]).all()  # every node of the 24 x 16 mm film passes light


def test_one_trace_for_several_irises_is_the_tracer_stopped_to_each(dgauss):
    # iris_camera_rays traces once with the stop opened; each iris's mask and weights must be what the
    # tracer itself gives with the stop set to that size (camera_rays with stop_semi_diameter=s)
    from physcam.trace.pupil_bounds import iris_camera_rays
    from physcam.trace.trace import paraxial_image_z

    film_z = paraxial_image_z(dgauss)
    rng = np.random.default_rng(7)
    film, u = rng.uniform(-15, 15, (3000, 2)), rng.random((3000, 2))
    semi = dgauss.surfaces[dgauss.stop_index].semi_diameter
    stops = [semi * f for f in (1.0, 0.71, 0.5, 0.25)]
    res, passing = iris_camera_rays(dgauss, film, u, film_z, stops)
    for s, ok in zip(stops, passing):
        ref = camera_rays(dgauss, film, u, film_z, stop_semi_diameter=s)
        assert 100 < ref.ok.sum() < 3000
        assert np.array_equal(ok, ref.ok)
        assert np.array_equal(res.weight[ok], ref.weight[ref.ok])


@pytest.mark.parametrize("name", ["navarro_anamorphic_2x", "arri_signature_prime_58mm_ex1"])
def test_stopped_bounds_are_the_bounds_of_the_stopped_lens(name):
    # stopped_pupil_bounds (one trace per round for every iris and node) against exit_pupil_bounds of
    # the prescription with its stop set to each size; the Signature's cover glass sends its nodes
    # through the window search (a spot under one sample of the rear square)
    import dataclasses
    import math

    from physcam.lens.library import load_lens
    from physcam.optics.focusing import focus
    from physcam.trace.pupil_bounds import stopped_pupil_bounds

    st = focus(load_lens(name), math.inf)
    q = st.prescription
    semi = q.surfaces[q.stop_index].semi_diameter
    stops = [semi, 0.5 * semi, 0.25 * semi]
    got = stopped_pupil_bounds(q, stops, 12.0, 8.0, st.film_z, nx=3, ny=3, samples=24)
    for s, pb in zip(stops, got):
        surfs = list(q.surfaces)
        surfs[q.stop_index] = dataclasses.replace(surfs[q.stop_index], semi_diameter=s)
        ref = exit_pupil_bounds(q.with_surfaces(surfs), 12.0, 8.0, st.film_z, nx=3, ny=3, samples=24)
        assert (ref.rects[..., 1] > ref.rects[..., 0]).all()
        assert np.array_equal(pb.rects, ref.rects)


@pytest.mark.parametrize("name", ["navarro_anamorphic_2x", "arri_signature_prime_58mm_ex1"])
def test_mirrored_bounds_are_the_whole_grids(name):
    # mirror=True traces the nodes with x >= 0 and y >= 0 and mirrors them (every prescription is symmetric about
    # x = 0 and y = 0): the whole grid's rectangles to the rounding of the aims' places, the same empty nodes; the
    # Signature's nodes go through the window search (above), so the search mirrors too
    import math

    from physcam.errors import InputError
    from physcam.lens.library import load_lens
    from physcam.optics.focusing import focus
    from physcam.trace.pupil_bounds import stopped_pupil_bounds

    st = focus(load_lens(name), math.inf)
    q = st.prescription
    semi = q.surfaces[q.stop_index].semi_diameter
    stops = [semi, 0.5 * semi]
    whole = stopped_pupil_bounds(q, stops, 12.0, 8.0, st.film_z, nx=5, ny=5, samples=24)
    half = stopped_pupil_bounds(q, stops, 12.0, 8.0, st.film_z, nx=5, ny=5, samples=24, mirror=True)
    for a, b in zip(whole, half):
        assert np.array_equal(a.xs, b.xs) and np.array_equal(a.ys, b.ys)
        assert ((a.rects[..., 1] > a.rects[..., 0]) == (b.rects[..., 1] > b.rects[..., 0])).all()
        np.testing.assert_allclose(b.rects, a.rects, rtol=0, atol=1e-12)
    with pytest.raises(InputError, match="odd number of nodes"):
        stopped_pupil_bounds(q, stops, 12.0, 8.0, st.film_z, nx=4, ny=5, samples=24, mirror=True)
