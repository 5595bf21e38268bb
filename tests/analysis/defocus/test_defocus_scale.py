"""A kernel made coarser for a layer blurred at 1/s resolution (layers._kernel_at_scale): its map
M = V diag(c) V^T, c_i^2 = 1 - (5 s^2 / 12) / lambda_i (at least 1/4), against numpy's eigh of the
kernel's covariance computed directly, and the covariance it leaves: M Sigma M / s^2 plus the tent's
1/6 coarse px^2 per axis, i.e. s^2 C_coarse = Sigma - (s^2 / 4) I (docstring of _kernel_at_scale)."""

from __future__ import annotations

import numpy as np
import pytest

from physcam.analysis.defocus.layers import _kernel_at_scale, _scale_map


def _gauss(r, sxx, syy, sxy):
    y, x = np.mgrid[-r:r + 1, -r:r + 1].astype(float)
    p = np.linalg.inv([[sxx, sxy], [sxy, syy]])
    g = np.exp(-0.5 * (p[0, 0] * x * x + 2 * p[0, 1] * x * y + p[1, 1] * y * y))
    return g / g.sum()


def _cov(m):
    r = m.shape[0] // 2
    y, x = np.mgrid[-r:r + 1, -r:r + 1].astype(float)
    t = m.sum()
    mx, my = (m * x).sum() / t, (m * y).sum() / t
    return np.array([[(m * (x - mx) ** 2).sum(), (m * (x - mx) * (y - my)).sum()],
                     [(m * (x - mx) * (y - my)).sum(), (m * (y - my) ** 2).sum()]]) / t


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("s", [2, 4, 8])
def test_scale_map_is_eighs_v_diag_c_vt(seed, s):
    rng = np.random.default_rng(seed)
    m = rng.random((21, 21)) ** 4 * (rng.random((21, 21)) < 0.6)  # lopsided, with holes; small variances clip c at 1/2
    lam, vec = np.linalg.eigh(_cov(m))
    c = np.sqrt(np.clip(1.0 - (5.0 * s * s / 12.0) / np.maximum(lam, 1e-12), 0.25, 1.0))
    want = (vec * c) @ vec.T
    m00, m01, m11 = _scale_map(m, s)
    assert np.allclose([[m00, m01], [m01, m11]], want, rtol=0, atol=1e-12)


def test_scale_map_of_a_round_kernel_is_c_times_the_identity():
    m = _gauss(20, 50.0, 50.0, 0.0)
    m00, m01, m11 = _scale_map(m, 4)
    c = np.sqrt(1.0 - (5.0 * 16 / 12.0) / _cov(m)[0, 0])
    assert (m00, m11) == pytest.approx((c, c), abs=1e-12) and m01 == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("s", [2, 4, 8])
def test_the_coarse_kernel_keeps_the_covariance_less_the_grids_blur(s):
    sigma = np.array([[120.0, 30.0], [30.0, 60.0]])
    k = _gauss(60, sigma[0, 0], sigma[1, 1], sigma[0, 1])[..., None].astype(np.float32)
    coarse = _kernel_at_scale(k, s)
    assert coarse.sum() == pytest.approx(1.0, abs=1e-6)
    got = _cov(coarse[..., 0].astype(float)) * s * s
    # the tent adds its 1/6 coarse px^2 only on average over where fine pixels fall in coarse ones: on
    # the grid of a small s less (s = 2, fractions 0 and 1/2: 1/8), so within s^2 / 24 fine px^2
    assert np.allclose(got, sigma - s * s / 4 * np.eye(2), rtol=0, atol=s * s / 24)
