"""The shifted R_d (Kronecker) points behind the bokeh's rays, checked against exact integer
arithmetic done here with Python's big integers, and for even coverage."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import InputError
from physcam.trace.lowdiscrepancy import MAX_DIMENSIONS, kronecker_points, random_shift

# phi_d solves x^(d+1) = x + 1 (Roberts 2018): check the constants' defining equation here
PHI = {1: (1 + 5**0.5) / 2, 2: 1.324717957244746, 3: 1.2207440846057596}


@pytest.mark.parametrize("d", [1, 2, 3])
def test_points_are_the_fractions_of_i_alpha_worked_in_integers(d):
    phi = PHI[d]
    assert abs(phi ** (d + 1) - phi - 1) < 1e-14
    shift = random_shift(np.random.default_rng(d), d)
    alphas = [int(phi ** -(k + 1) * 2.0**64) for k in range(d)]
    starts = [0, 1, 12345, 2**40 + 7, 2**53 - 3]
    for i in starts:
        got = kronecker_points(3, i, shift)
        for j in range(3):
            for k in range(d):
                exact = ((int(shift[k]) + (i + j) * alphas[k]) % 2**64) >> 11
                assert got[k][j] == exact / 2.0**53
                assert 0.0 <= got[k][j] < 1.0
    assert alphas[0] / 2.0**64 == pytest.approx(1 / phi, abs=1e-15)


@settings(max_examples=30, deadline=None)
@given(start=st.integers(0, 10**12), n=st.integers(1, 300), cut=st.integers(0, 300), seed=st.integers(0, 2**32))
def test_a_point_does_not_depend_on_the_batch_it_is_made_in(start, n, cut, seed):
    cut = min(cut, n)
    s = random_shift(np.random.default_rng(seed), 2)
    whole = kronecker_points(n, start, s)
    a, b = kronecker_points(cut, start, s), kronecker_points(n - cut, start + cut, s)
    for k in range(2):
        assert np.array_equal(whole[k], np.concatenate([a[k], b[k]]))


def test_points_cover_the_square_evenly():
    # 40,000 points in a 20 x 20 grid: 100 per cell expected. Independent random points miss that by
    # about 10 (Poisson); the R_2 points by at most a few, in every cell.
    u, v = kronecker_points(40_000, 0, random_shift(np.random.default_rng(7), 2))
    counts = np.histogram2d(u, v, bins=20, range=[[0, 1], [0, 1]])[0]
    assert np.abs(counts - 100).max() <= 4
    rnd = np.random.default_rng(7).random((2, 40_000))
    assert np.abs(np.histogram2d(rnd[0], rnd[1], bins=20, range=[[0, 1], [0, 1]])[0] - 100).max() > 20


def test_bad_arguments_are_refused():
    s = random_shift(np.random.default_rng(0), 2)
    with pytest.raises(InputError):
        kronecker_points(10, 0, np.zeros(2))  # not 64-bit unsigned
    with pytest.raises(InputError):
        kronecker_points(10, 0, random_shift(np.random.default_rng(0), MAX_DIMENSIONS + 1))
    with pytest.raises(InputError):
        kronecker_points(-1, 0, s)
    with pytest.raises(InputError):
        kronecker_points(10, 2**53, s)
