"""The Owen-scrambled Sobol points behind the bokeh's rays: the (0, m, 2)-net property, the Sobol
construction checked against bit arithmetic done here with Python integers, batch independence,
and the scrambling's uniformity."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import InputError
from physcam.trace.lowdiscrepancy import owen_sobol_2d, random_seed


@pytest.mark.parametrize("seed", [0, 1, 0xDEADBEEF, 2**32 - 1])
@pytest.mark.parametrize("m", [4, 10, 13])
def test_every_power_of_two_prefix_is_a_0_m_2_net(seed, m):
    # each of the 2^m boxes 2^-a x 2^-(m-a) holds exactly one of the first 2^m points, for every a
    x, y = owen_sobol_2d(2**m, 0, seed)
    for a in range(m + 1):
        h = np.histogram2d(x, y, bins=[2**a, 2**(m - a)], range=[[0, 1], [0, 1]])[0]
        assert h.min() == 1 and h.max() == 1, (a, h.min(), h.max())


def _sobol_unscrambled(i: int) -> tuple[int, int]:
    """The textbook 2-D Sobol point i as 32-bit integers: the radical inverse, and the xor of the
    direction numbers of x + 1 (v_1 = 2^31, v_k = v_(k-1) xor v_(k-1) >> 1) over the set bits of i."""
    x = int(f"{i:032b}"[::-1], 2)
    y, v = 0, 1 << 31
    for k in range(32):
        if i >> k & 1:
            y ^= v
        v ^= v >> 1
    return x, y


M32 = 0xFFFFFFFF


def _rev(x: int) -> int:
    return int(f"{x:032b}"[::-1], 2)


def _lk(x: int, seed: int) -> int:
    """Burley (2020), listing 1, in Python integers."""
    x = (x + seed) & M32
    for m in (0x6C50B47C, 0xB82F1E52, 0xC7AFE638, 0x8D22F6E6):
        x ^= (x * m) & M32
    return x


def _nus(x: int, seed: int) -> int:
    return _rev(_lk(_rev(x), seed))


def _mix(seed: int, k: int) -> int:
    return (seed ^ ((k + 0x9E3779B9 + (seed << 6) + (seed >> 2)) & M32)) & M32


def _burley(i: int, seed: int) -> tuple[float, float]:
    """The shuffled, Owen-scrambled 2-D Sobol point i (Burley 2020, listing 3), written out here from
    the paper with Python integers, independently of the vectorised module."""
    s = _mix(seed, i >> 32)
    idx = _nus(i & M32, s)
    x, y = _sobol_unscrambled(idx)
    return _nus(x, _mix(s, 1)) / 2.0**32, _nus(y, _mix(s, 2)) / 2.0**32


@pytest.mark.parametrize("seed", [0, 99, 0xC0FFEE, 2**32 - 1])
def test_points_equal_the_papers_algorithm_worked_in_python_integers(seed):
    # every step (index shuffle, radical inverse, second dimension, both coordinate scrambles, block
    # seeds) must be there: leaving any out changes these values
    for start in (0, 1000, 2**32 - 2, 2**40 + 3):
        x, y = owen_sobol_2d(4, start, seed)
        for j in range(4):
            assert (x[j], y[j]) == _burley(start + j, seed)


def test_positions_inside_the_net_cells_are_scrambled():
    # an unscrambled (or only digitally shifted) net puts every point at the same offset inside its
    # 1/2^m cell: Owen scrambling spreads the offsets over the whole cell
    m = 10
    x, y = owen_sobol_2d(2**m, 0, 4242)
    for c in (x, y):
        frac = (c * 2**m) % 1.0
        assert np.ptp(frac) > 0.9 and 0.4 < frac.mean() < 0.6


def test_the_scrambled_points_are_a_scramble_of_the_textbook_sobol_net():
    # an Owen scramble permutes the elementary boxes: the first 2^m scrambled points fill the same
    # boxes as the first 2^m textbook points (all of them, once each), for both coordinates apart
    m = 8
    x, y = owen_sobol_2d(2**m, 0, 12345)
    ref = np.array([_sobol_unscrambled(i) for i in range(2**m)], dtype=float) / 2.0**32
    for got, want in ((x, ref[:, 0]), (y, ref[:, 1])):
        assert sorted(np.floor(got * 2**m).astype(int)) == sorted(np.floor(want * 2**m).astype(int)) == list(range(2**m))
    # and the textbook points are a net themselves (the construction checked)
    for a in range(m + 1):
        h = np.histogram2d(ref[:, 0], ref[:, 1], bins=[2**a, 2**(m - a)], range=[[0, 1], [0, 1]])[0]
        assert h.min() == h.max() == 1


@settings(max_examples=30, deadline=None)
@given(start=st.integers(0, 10**12), n=st.integers(1, 300), cut=st.integers(0, 300), seed=st.integers(0, 2**32 - 1))
def test_a_point_does_not_depend_on_the_batch_it_is_made_in(start, n, cut, seed):
    cut = min(cut, n)
    whole = owen_sobol_2d(n, start, seed)
    a, b = owen_sobol_2d(cut, start, seed), owen_sobol_2d(n - cut, start + cut, seed)
    for k in range(2):
        assert np.array_equal(whole[k], np.concatenate([a[k], b[k]]))
        assert np.all((whole[k] >= 0) & (whole[k] < 1))


def test_one_point_over_many_seeds_is_uniform():
    # Owen scrambling makes each point uniformly distributed: point 5 over 4000 seeds, in 20 bins,
    # has the counts of a uniform variable (chi-square with 19 degrees of freedom below 43.8, p = 0.001)
    rng = np.random.default_rng(1)
    pts = np.array([[c[0] for c in owen_sobol_2d(1, 5, random_seed(rng))] for _ in range(4000)])
    for k in range(2):
        counts = np.histogram(pts[:, k], bins=20, range=(0, 1))[0]
        chi2 = ((counts - 200.0) ** 2 / 200.0).sum()
        assert chi2 < 43.8, chi2


def test_blocks_of_2_to_the_32_are_sequences_of_their_own():
    x0, _ = owen_sobol_2d(256, 0, 7)
    x1, _ = owen_sobol_2d(256, 2**32, 7)
    assert not np.array_equal(x0, x1)
    for x in (x0, x1):
        assert sorted(np.floor(x * 256).astype(int)) == list(range(256))


def test_bad_arguments_are_refused():
    with pytest.raises(InputError):
        owen_sobol_2d(10, 0, -1)
    with pytest.raises(InputError):
        owen_sobol_2d(10, 0, 2**32)
    with pytest.raises(InputError):
        owen_sobol_2d(10, 0, 1.5)
    with pytest.raises(InputError):
        owen_sobol_2d(-1, 0, 1)
    with pytest.raises(InputError):
        owen_sobol_2d(10, 2**53, 1)
