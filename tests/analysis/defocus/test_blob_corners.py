"""polygon_corners counts an iris polygon's corners and not the noise on its rim: images of regular
polygons drawn by hand (a pixel is lit by the share of its 4 x 4 subsamples inside), one with a bump
on a flat side the size of a 512-sample Cycles render's noise."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physcam.analysis.defocus.blob import polygon_corners


def _polygon(n: int, corner_deg: float, r_px: float = 40.0, size: int = 128, bump=None) -> np.ndarray:
    """A regular n-gon of circumradius r_px about the image centre, a corner corner_deg from +x; ``bump``
    (angle deg, radius px): a disk of that radius centred on the flat side's middle at that angle."""
    sub = (np.arange(size * 4) + 0.5) / 4 - size / 2
    x, y = np.meshgrid(sub, sub)
    th = np.arctan2(y, x) - math.radians(corner_deg)
    half = math.pi / n
    a = np.mod(th + half, 2 * half) - half  # angle from the nearest corner, in (-pi/n, pi/n]
    inside = np.hypot(x, y) * np.cos(half - np.abs(a)) <= r_px * math.cos(half)
    if bump is not None:
        ang, rb = math.radians(bump[0]), bump[1]
        d = r_px * math.cos(half)
        inside |= np.hypot(x - d * math.cos(ang), y - d * math.sin(ang)) <= rb
    return inside.reshape(size, 4, size, 4).mean(axis=(1, 3))


@pytest.mark.parametrize("n", [5, 6, 7, 9])
def test_a_regular_polygon_has_its_corners(n):
    """Sharp corners: the rim low-passed to 12 harmonics rings, a maximum 0.01 px high in the middle of
    each flat side (counted before corners had to stand out: 10 for the pentagon, 12 for the hexagon)."""
    got, harmonic, corner = polygon_corners(_polygon(n, 15.0))
    assert (got, harmonic) == (n, n)
    assert abs((corner - 15.0 + 180.0 / n) % (360.0 / n) - 180.0 / n) < 1.0


def test_a_small_bump_on_a_flat_side_is_not_a_corner():
    """A 1 px disk on the middle of a hexagon's flat side (45 deg: corners at 15 and 75) makes a maximum
    0.04 px above the troughs either side of the rim low-passed to 12 harmonics (corners and flats 4.2 px
    apart), the size of the bump a 512-sample Cycles render's noise made on the double Gauss's bokeh
    (tests/blender/test_extension_bokeh.py: 0.04 px of 2.5, a seventh corner)."""
    got, harmonic, corner = polygon_corners(_polygon(6, 15.0, bump=(45.0, 1.0)))
    assert (got, harmonic) == (6, 6)
    assert abs((corner - 15.0 + 30.0) % 60.0 - 30.0) < 1.0
