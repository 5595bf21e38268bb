"""Aperture shapes and the shutter curve against closed forms and rejection sampling."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import InputError
from physcam.trace.aperture import Aperture, Shutter


def test_regular_polygon_area_closed_form():
    # straight-sided regular n-gon of circumradius 1: area = n/2 sin(2 pi / n)
    for n in (3, 5, 6, 9):
        assert Aperture(n).area() == pytest.approx(n / 2 * math.sin(2 * math.pi / n), rel=1e-6)
    assert Aperture(0).area() == pytest.approx(math.pi, rel=1e-9)
    assert Aperture(6, roundness=1.0).area() == pytest.approx(math.pi, rel=1e-9)


@settings(max_examples=25, deadline=None)
@given(n=st.integers(0, 9), angle=st.floats(0, 90), rnd=st.floats(-1, 1), den=st.floats(-1, 1))
def test_samples_lie_inside_the_shape(n, angle, rnd, den):
    ap = Aperture(n, angle, rnd, den)
    pts = ap.sample(np.random.default_rng(1).random((400, 2)))
    r = np.hypot(pts[:, 0], pts[:, 1])
    assert (r <= ap.rim_radius(np.arctan2(pts[:, 1], pts[:, 0])) * (1 + 1e-9)).all()


@pytest.mark.parametrize("ap", [Aperture(5, 18.0, 0.0, 0.0), Aperture(6, 0.0, -0.6, 0.8), Aperture(0, 0, 0, -1.0)])
def test_importance_sampling_matches_rejection_sampling(ap):
    # Independent estimate: uniform points in the square, kept with probability density/2.
    rng = np.random.default_rng(7)
    q = rng.uniform(-1, 1, (400_000, 2))
    f = ap.density_at(q[:, 0], q[:, 1])
    keep = rng.random(len(q)) < f / 2.0
    ref = q[keep]
    got = ap.sample(rng.random((200_000, 2)))
    for stat in (lambda p: np.hypot(p[:, 0], p[:, 1]).mean(), lambda p: (p[:, 0] ** 2).mean(), lambda p: p[:, 1].mean()):
        assert stat(got) == pytest.approx(stat(ref), abs=4e-3)


def test_shutter_exposure_and_sampling():
    sh = Shutter(0.2, 0.6)
    assert sh.exposure_fraction == pytest.approx(0.5 * (1 + 0.6 - 0.2))
    t = np.linspace(0, 1, 200_001)
    assert np.trapezoid(sh.opening(t), t) == pytest.approx(sh.exposure_fraction, abs=1e-8)
    s = sh.sample_times(np.random.default_rng(0).random(400_000))
    hist, edges = np.histogram(s, bins=20, range=(0, 1), density=True)
    expect = np.array([np.mean(sh.opening(np.linspace(a, b, 101))) for a, b in zip(edges[:-1], edges[1:])])
    np.testing.assert_allclose(hist, expect / sh.exposure_fraction, atol=0.03)
    assert Shutter(0, 1).exposure_fraction == 1.0 and Shutter(0.5, 0.5).exposure_fraction == 0.5


def test_bad_aperture_and_shutter_are_refused():
    with pytest.raises(InputError):
        Aperture(6, roundness=1.5)
    with pytest.raises(InputError):
        Aperture(6, density=float("nan"))
    with pytest.raises(InputError):
        Shutter(0.7, 0.3)
