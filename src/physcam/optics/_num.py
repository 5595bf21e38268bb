"""Scalars stay Python floats, arrays go through numpy: one formula serves both.

The on-set report works on single numbers and must start fast (numpy costs ~0.1 s to
import), while analyses broadcast the same formulas over arrays. These helpers import
numpy only when an array actually arrives.
"""

from __future__ import annotations

import math
from numbers import Real


def value(x):
    """A Python float for a real scalar, else a float numpy array."""
    if isinstance(x, Real) and not isinstance(x, bool):
        return float(x)
    import numpy as np

    a = np.asarray(x, dtype=float)
    return float(a) if a.ndim == 0 else a


def is_scalar(x) -> bool:
    return isinstance(x, float)


def any_true(cond) -> bool:
    if isinstance(cond, bool):
        return cond
    import numpy as np

    return bool(np.any(cond))


def all_true(cond) -> bool:
    if isinstance(cond, bool):
        return cond
    import numpy as np

    return bool(np.all(cond))


def where(cond, a, b):
    if isinstance(cond, bool):
        return a if cond else b
    import numpy as np

    return np.where(cond, a, b)


def sqrt(x):
    if isinstance(x, float):
        return math.sqrt(x)
    import numpy as np

    return np.sqrt(x)


def atan(x):
    if isinstance(x, float):
        return math.atan(x)
    import numpy as np

    return np.arctan(x)


def maximum(x, lo: float):
    if isinstance(x, float):
        return max(x, lo)
    import numpy as np

    return np.maximum(x, lo)


def isfinite(x):
    if isinstance(x, float):
        return math.isfinite(x)
    import numpy as np

    return np.isfinite(x)


def out(x):
    """Collapse 0-d arrays to floats."""
    if isinstance(x, float):
        return x
    import numpy as np

    a = np.asarray(x)
    return float(a) if a.ndim == 0 else a
