"""The bokeh's low-discrepancy rays: a cleaner picture than counting noise allows random rays,
no bias, and a picture that does not depend on the chunk size."""

import inspect
import math

import numpy as np
import pytest

from physcam.analysis.defocus.bokeh import bokeh_image
from physcam.lens.library import load_lens
from physcam.optics import focusing
from physcam.optics.state import camera_state


def _scene():
    st = focusing.focus(load_lens("dgauss_50mm"), math.inf)
    return st.prescription, st.film_z


def test_error_is_well_below_the_poisson_noise_of_random_rays():
    lens, film_z = _scene()
    cam = camera_state(lens, film_z=film_z)
    ref = bokeh_image(cam, 1000.0, rays=4_000_000, pixels=64, seed=99)
    img = bokeh_image(cam, 1000.0, rays=100_000, pixels=64, extent_mm=ref.extent_mm, seed=3)
    R, I = ref.image[..., 0], img.image[..., 0]
    lit = R > 0.2 * R.max()
    # rays per lit pixel, hence the relative RMS error 1/sqrt(lambda) random rays would have
    lam = img.rays_passed * I[lit].sum() / I.sum() / lit.sum()
    poisson = 1 / math.sqrt(lam)
    err = np.sqrt(np.mean((I[lit] - R[lit]) ** 2)) / R[lit].mean()
    assert err < 0.5 * poisson, (err, poisson)
    # unbiased: the total flux agrees with the reference's to the reference's own accuracy
    assert I.sum() == pytest.approx(R.sum(), rel=2e-3)


def test_the_picture_does_not_depend_on_the_chunk_size():
    lens, film_z = _scene()
    cam = camera_state(lens, film_z=film_z)
    a = bokeh_image(cam, 1000.0, 2.0, -1.0, rays=30_000, chunk=7_000, pixels=32, spectral=True)
    b = bokeh_image(cam, 1000.0, 2.0, -1.0, rays=30_000, chunk=30_000, pixels=32, spectral=True)
    assert a.extent_mm == b.extent_mm and a.rays_passed == b.rays_passed
    np.testing.assert_allclose(a.image, b.image, rtol=1e-12, atol=1e-300)


def test_spectral_rays_split_evenly_between_the_wavelengths():
    # ray i goes to wavelength i mod 3, each wavelength with its own Sobol sequence: with no
    # colour-dependent losses to speak of on the axis, each channel gets a third of the flux
    lens, film_z = _scene()
    img = bokeh_image(camera_state(lens, film_z=film_z), 1000.0, rays=30_000, pixels=32, spectral=True, fresnel=False)
    share = img.image.sum(axis=(0, 1)) / img.image.sum()
    np.testing.assert_allclose(share, 1 / 3, atol=2e-3)


def test_api_and_cli_default_ray_counts_agree():
    from physcam.cli import build_parser

    p = build_parser()
    args = p.parse_args(["bokeh", "dgauss_50mm"])
    assert args.rays == inspect.signature(bokeh_image).parameters["rays"].default == 250_000


def test_flux_agrees_with_independent_random_rays():
    """The image's total (relative irradiance x area) against the same estimate from independent
    uniform random rays built here (Monte Carlo over the front element: pi R^2 / dz^2 x mean of
    cos^3 x transmission over the rays that reach the window); 2e6 random rays leave ~3e-4 of noise."""
    from physcam.trace import RayBatch, trace_to_film

    lens, film_z = _scene()
    depth, x_l = 1000.0, 150.0
    img = bokeh_image(camera_state(lens, film_z=film_z), depth, x_l, rays=250_000, pixels=64)
    rng = np.random.default_rng(11)
    n = 2_000_000
    z_src = film_z - depth
    R = lens.surfaces[0].semi_diameter
    r = R * np.sqrt(rng.random(n))
    phi = 2 * np.pi * rng.random(n)
    d = np.stack([r * np.cos(phi) - x_l, r * np.sin(phi), np.full(n, -z_src)])
    d /= np.linalg.norm(d, axis=0)
    out = trace_to_film(lens, RayBatch(np.full(n, x_l), np.zeros(n), np.full(n, z_src), d[0], d[1], d[2],
                                       np.full(n, lens.wavelength_nm), d[2] ** 3, np.zeros(n, dtype=np.uint8)),
                        film_z, fresnel=True)
    x0, x1, y0, y1 = img.extent_mm
    inside = out.ok & (out.x >= x0) & (out.x < x1) & (out.y >= y0) & (out.y < y1)
    flux_random = out.weight[inside].sum() * np.pi * R * R / (z_src * z_src) / n
    assert img.image.sum() == pytest.approx(flux_random, rel=2e-3)
