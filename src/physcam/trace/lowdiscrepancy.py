"""Randomly shifted Kronecker points: low-discrepancy samples for images made by counting rays.

The point ``i`` of the d-dimensional sequence is ``frac(shift + i * alpha)`` with
``alpha_k = 1 / phi_d**k`` (k = 1..d), where ``phi_d`` is the real root of
``x**(d + 1) = x + 1`` (the golden ratio for d = 1, the plastic number for d = 2): M. Roberts,
"The unreasonable effectiveness of quasirandom sequences" (2018), the R_d sequence. Its points
fill the unit cube far more evenly than independent random ones, so a picture made by binning
rays that start from them (a bokeh) is much less noisy for the same number of rays (measured in
docs/ray-tracing.md, "Bokeh sampling"). A uniformly random ``shift`` (Cranley-Patterson rotation)
keeps every point uniformly distributed, so sums over the points remain unbiased estimates.

The arithmetic is exact: the fractions live in 64-bit fixed point (unsigned integers wrap modulo
2**64, which is "frac"), so point ``i`` is the same whatever batch it is made in, and does not
lose digits at large ``i`` as ``i * alpha`` in floating point would.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, require_type

__all__ = ["MAX_DIMENSIONS", "kronecker_points", "random_shift"]

#: phi_d, the real root of x**(d+1) = x + 1, for d = 1, 2, 3
_PHI = {1: 1.6180339887498948482, 2: 1.3247179572447460260, 3: 1.2207440846057594754}
MAX_DIMENSIONS = max(_PHI)
_SCALE = 2.0**64


def _alphas(d: int) -> np.ndarray:
    phi = _PHI[d]
    return np.array([int((phi ** -(k + 1)) * _SCALE) for k in range(d)], dtype=np.uint64)


def random_shift(rng: np.random.Generator, dimensions: int) -> np.ndarray:
    """A uniformly random shift (64-bit fixed point) for :func:`kronecker_points`."""
    require_type("rng", rng, np.random.Generator, "numpy.random.default_rng(seed)")
    if isinstance(dimensions, bool) or not isinstance(dimensions, (int, np.integer)) or not 1 <= dimensions <= 8:
        raise InputError(f"dimensions must be a whole number from 1 to 8, got {dimensions!r:.40}")
    return rng.integers(0, np.iinfo(np.uint64).max, size=dimensions, dtype=np.uint64, endpoint=True)


def kronecker_points(n: int, start: int, shift: np.ndarray) -> list[np.ndarray]:
    """Points ``start .. start + n - 1`` of the shifted R_d sequence in [0, 1): a list of d arrays
    of n coordinates (one per dimension). ``shift`` (from :func:`random_shift`) sets the dimension
    d (1 to :data:`MAX_DIMENSIONS`)."""
    shift = np.asarray(shift)
    d = shift.shape[0] if shift.ndim == 1 else 0
    if shift.dtype != np.uint64 or d not in _PHI:
        raise InputError(f"shift must be 1 to {MAX_DIMENSIONS} unsigned 64-bit integers (random_shift)")
    n, start = int(n), int(start)
    if n < 0 or start < 0 or start + n > 2**53:
        raise InputError(f"Kronecker points need 0 <= start and start + n <= 2**53, got start {start}, n {n}")
    i = np.arange(start, start + n, dtype=np.uint64)
    out = []
    for k, a in enumerate(_alphas(d)):
        u = i * a  # modulo 2**64: the fraction of i * alpha_k, exactly
        u += shift[k]
        u >>= np.uint64(11)  # its top 53 bits: a double in [0, 1), never rounded up to 1
        x = u.view(np.int64).astype(np.float64)
        x *= 2.0**-53
        out.append(x)
    return out
