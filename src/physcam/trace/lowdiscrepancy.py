"""Owen-scrambled Sobol points: low-discrepancy samples for pictures made by counting rays.

The 2-D Sobol sequence (first dimension: the base-2 radical inverse of the index; second: the
Sobol dimension of primitive polynomial x + 1, direction numbers v_1 = 1/2, v_k = v_(k-1) xor
v_(k-1)/2), with Owen's nested uniform scrambling of each coordinate and of the index, done by
hashing as in B. Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020 (the
Laine-Karras permutation on bit-reversed values). Every prefix of 2^m points is a (0, m, 2)-net:
each of the 2^m equal-area boxes of any shape 2^-a x 2^-(m-a) holds exactly one point, so a picture
binned from rays that start at them is much less noisy than one from independent random rays
(docs/ray-tracing.md, "Bokeh sampling"). Owen scrambling makes every point uniformly distributed
(sums over the points stay unbiased) and leaves no lattice: unscrambled or Kronecker (R_2) points
drew spirals and moire into bokeh images.

Indices are 64-bit; each block of 2^32 indices is its own scrambled sequence (its seed mixed with
the block number). Point i is the same whatever batch it is made in.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, require_type

__all__ = ["MAX_INDEX", "owen_sobol_2d", "random_seed"]

#: Largest index + 1 accepted (bokeh rays go up to 1e11)
MAX_INDEX = 2**53
_U32 = np.uint32


def _v2() -> np.ndarray:
    v, out = 1 << 31, []
    for _ in range(32):
        out.append(v)
        v ^= v >> 1
    return np.array(out, dtype=np.uint32)


_V2 = _v2()


def _byte_tables() -> np.ndarray:
    """T[j, b] = xor of the direction numbers v_(8j+k) for the bits k set in byte b: the second
    dimension is then four table lookups per point instead of 32 bit tests."""
    t = np.zeros((4, 256), dtype=np.uint32)
    for j in range(4):
        for b in range(256):
            acc = 0
            for k in range(8):
                if b >> k & 1:
                    acc ^= int(_V2[8 * j + k])
            t[j, b] = acc
    return t


_T2 = _byte_tables()


def _reverse_bits(x: np.ndarray) -> np.ndarray:
    x = ((x >> _U32(1)) & _U32(0x55555555)) | ((x & _U32(0x55555555)) << _U32(1))
    x = ((x >> _U32(2)) & _U32(0x33333333)) | ((x & _U32(0x33333333)) << _U32(2))
    x = ((x >> _U32(4)) & _U32(0x0F0F0F0F)) | ((x & _U32(0x0F0F0F0F)) << _U32(4))
    return x.byteswap()


def _laine_karras(x: np.ndarray, seed) -> np.ndarray:
    """Burley (2020), listing 1: a hash that flips each bit depending only on the bits below it."""
    x = x + seed
    x ^= x * _U32(0x6C50B47C)
    x ^= x * _U32(0xB82F1E52)
    x ^= x * _U32(0xC7AFE638)
    x ^= x * _U32(0x8D22F6E6)
    return x


def _scramble(x: np.ndarray, seed) -> np.ndarray:
    """Owen's nested uniform scramble of 32-bit fractions (Burley 2020, listing 2)."""
    return _reverse_bits(_laine_karras(_reverse_bits(x), seed))


def _mix(seed, k) -> np.ndarray:
    """A seed for stream ``k`` (hash_combine of Burley's listing 3, 32-bit)."""
    seed = np.asarray(seed, dtype=np.uint32)
    k = np.asarray(k, dtype=np.uint32)
    return seed ^ (k + _U32(0x9E3779B9) + (seed << _U32(6)) + (seed >> _U32(2)))


def random_seed(rng: np.random.Generator) -> int:
    """A 32-bit scrambling seed drawn from ``rng``."""
    require_type("rng", rng, np.random.Generator, "numpy.random.default_rng(seed)")
    return int(rng.integers(0, 2**32, dtype=np.uint64))


def owen_sobol_2d(n: int, start: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Points ``start .. start + n - 1`` of the shuffled, Owen-scrambled 2-D Sobol sequence of
    ``seed`` (a 32-bit integer, :func:`random_seed`): two arrays of n coordinates in [0, 1)."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) < 2**32:
        raise InputError(f"the scrambling seed must be a whole number from 0 to 2**32 - 1, got {seed!r:.40}")
    n, start = int(n), int(start)
    if n < 0 or start < 0 or start + n > MAX_INDEX:
        raise InputError(f"Sobol points need 0 <= start and start + n <= 2**53, got start {start}, n {n}")
    x, y = np.empty(n), np.empty(n)
    for a in range(0, n, _BLOCK):  # in blocks that stay in the cache: twice as fast as one pass
        b = min(n, a + _BLOCK)
        x[a:b], y[a:b] = _points(start + a, b - a, seed)
    return x, y


_BLOCK = 32768


def _points(start: int, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    i = np.arange(start, start + n, dtype=np.uint64)
    s = _mix(_U32(seed), (i >> np.uint64(32)).astype(np.uint32))  # one stream per block of 2^32
    idx = _scramble((i & np.uint64(0xFFFFFFFF)).astype(np.uint32), s)  # Burley's shuffled order
    x = _reverse_bits(idx)  # Sobol dimension 1: the radical inverse
    y = _T2[0][idx & _U32(0xFF)]  # Sobol dimension 2: xor of v_k over the index's set bits k
    for j in (1, 2, 3):
        y ^= _T2[j][(idx >> _U32(8 * j)) & _U32(0xFF)]
    x = _scramble(x, _mix(s, 1))
    y = _scramble(y, _mix(s, 2))
    return x * 2.0**-32, y * 2.0**-32
