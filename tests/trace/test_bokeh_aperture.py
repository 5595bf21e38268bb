"""The bokeh of a defocused point light takes the shape of the iris (seed 002 aperture at the stop)."""

import math

import numpy as np
import pytest

from physcam.analysis.defocus.bokeh import bokeh_image
from physcam.lens.library import load_lens
from physcam.optics import focusing, paraxial
from physcam.optics.state import camera_state
from physcam.trace.aperture import Aperture


def _extents(img, extent):
    x0, x1, y0, y1 = extent
    lit = img.sum(axis=2) > 0
    ys, xs = np.nonzero(lit)
    px = (x1 - x0) / img.shape[1]
    py = (y1 - y0) / img.shape[0]
    return (xs.max() - xs.min() + 1) * px, (ys.max() - ys.min() + 1) * py


@pytest.mark.parametrize("nsides, ratio", [(6, math.cos(math.pi / 6)), (4, 1.0), (0, 1.0)])
def test_hexagonal_iris_gives_hexagonal_bokeh(nsides, ratio):
    # A regular hexagon with a vertex on one axis is 2R across that axis and 2R cos 30 deg across
    # the other; a square (flats on the axes) and a circle are as wide as they are tall. On axis,
    # stopped down to f/8, the lens maps the stop to the blur with negligible pupil aberration.
    lens = load_lens("dgauss_50mm")
    st = focusing.focus(lens, 3000.0)
    stop = paraxial.stop_semi_diameter_for_fstop(st.prescription, 8.0)
    ap = Aperture(nsides=nsides, angle_deg=0.0) if nsides else None
    cam = camera_state(st.prescription, film_z=st.film_z, stop_semi_diameter=stop, aperture=ap)
    res = bokeh_image(cam, 600.0, rays=200_000, pixels=200, fresnel=False)
    w, h = _extents(res.image, res.extent_mm)
    small, big = sorted((w, h))
    assert small / big == pytest.approx(ratio, abs=0.03)


def test_density_ramp_brightens_the_rim():
    lens = load_lens("dgauss_50mm")
    st = focusing.focus(lens, 3000.0)
    stop = paraxial.stop_semi_diameter_for_fstop(st.prescription, 8.0)
    cam = camera_state(st.prescription, film_z=st.film_z, stop_semi_diameter=stop, aperture=Aperture(density=0.8))
    res = bokeh_image(cam, 600.0, rays=200_000, pixels=64, fresnel=False)
    img = res.image.sum(axis=2)
    ys, xs = np.indices(img.shape)
    lit = img > 0
    cy, cx = ys[lit].mean(), xs[lit].mean()
    r = np.hypot(ys - cy, xs - cx)
    rmax = r[lit].max()
    inner = img[lit & (r < 0.4 * rmax)].mean()
    outer = img[lit & (r > 0.6 * rmax) & (r < 0.9 * rmax)].mean()
    # density f(s) = 1 + d (2s - 1): 0.2 at the centre, 1.8 at the rim
    assert outer > 1.8 * inner
