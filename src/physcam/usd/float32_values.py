"""Attribute values a refresh recomputes from a camera's 32-bit attributes: the same as the file's at float32
precision (reading back through float32 moves doubles by a few 1e-8, not a change), and shown as JSON.
"""

from __future__ import annotations


def _numbers(v):
    """The numbers of a scalar, vector or array value, or None for any other value."""
    if isinstance(v, bool):
        return None
    if isinstance(v, (int, float)):
        return [float(v)]
    try:
        out = [float(x) for x in v]
    except (TypeError, ValueError):
        return None
    return None if isinstance(v, str) else out


#: two values computed from one camera's 32-bit attributes are the same when they differ by at most
#: this much relative: two float32 rounding steps (2 x 2^-23), the round trip's, not a change
_F32_SAME = 2.0 ** -22


def _same_value(a, b) -> bool:
    """Whether ``a`` and ``b`` (attribute values) are equal at float32 precision (:data:`_F32_SAME`)."""
    x, y = _numbers(a), _numbers(b)
    if x is None or y is None:
        return a == b
    return len(x) == len(y) and all(abs(p - q) <= _F32_SAME * max(abs(p), abs(q)) for p, q in zip(x, y))


def _same_view(old: dict, new: dict, geom: str) -> bool:
    """Whether the companion's (focalLength, horizontalAperture, verticalAperture) before and after give
    one field of view: the aperture / focal length ratios equal at float32 precision and the focal
    lengths within 49 float32 steps (each pick of fov_preserving_float32 lies within 24 of its exact
    focal length, and the two exact ones, a double and its float32 read back, within one)."""
    import numpy as np

    names = [f"{geom}.{n}" for n in ("focalLength", "horizontalAperture", "verticalAperture")]
    if not all(n in old and n in new for n in names):
        return False
    (f0, w0, h0), (f1, w1, h1) = ([float(d[n]) for n in names] for d in (old, new))
    if min(f0, f1) <= 0.0:
        return False
    steps = abs(f0 - f1) / float(np.spacing(np.float32(max(f0, f1))))
    return steps <= 49 and _same_value([w0 / f0, h0 / f0], [w1 / f1, h1 / f1])


def _shown_value(v):
    """An attribute value as JSON: numbers, lists of numbers, text; None for none."""
    if v is None or isinstance(v, (bool, int, float, str)):
        return v
    nums = _numbers(v)
    return nums if nums is not None else str(v)
