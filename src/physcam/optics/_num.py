"""Scalars stay Python floats, arrays go through numpy: one formula serves both.

The on-set report works on single numbers and must start fast (numpy costs ~0.1 s to
import), while analyses broadcast the same formulas over arrays. These helpers import
numpy only when an array actually arrives.
"""

from __future__ import annotations

import math
from numbers import Real

from ..errors import InputError, OpticsError, WrongTypeError


def value(x):
    """A Python float for a real scalar, else a float numpy array."""
    if isinstance(x, Real) and not isinstance(x, bool):
        return float(x)
    import numpy as np

    a = np.asarray(x, dtype=float)
    return float(a) if a.ndim == 0 else a


def positive(name: str, x, *, allow_inf: bool = False, unit: str = "mm"):
    """:func:`value` of ``x`` after checking that it is a number above 0 (and finite, unless
    ``allow_inf``); an :class:`~physcam.errors.InputError` (a :class:`~physcam.errors.WrongTypeError`
    for a non-number) saying what was given otherwise. Every public formula of :mod:`physcam.optics`
    takes its inputs through here, so none answers NaN or raises a Python error (issue 24)."""
    if type(x) is float and (0.0 < x if allow_inf else 0.0 < x < math.inf):  # the common case, at once (issue 47)
        return x
    if isinstance(x, (bool, str, bytes)) or x is None:
        raise WrongTypeError(f"{name} must be a number of {unit}, got {type(x).__name__} {x!r:.40}")
    try:
        v = value(x)
    except (TypeError, ValueError):
        raise WrongTypeError(f"{name} must be a number of {unit} (or an array of them), got {x!r:.40}") from None
    ok = v > 0.0 if allow_inf else (v > 0.0) & isfinite(v)
    if not all_true(ok):
        bad = v if isinstance(v, float) else next(float(b) for b, g in zip(v.ravel(), ok.ravel()) if not g)
        more = "" if allow_inf else " and finite"
        raise InputError(f"{name} must be above 0{more}, got {bad:g}{' ' + unit if unit else ''}")
    return v


def finite(name: str, x, *, unit: str = "mm"):
    """:func:`value` of ``x`` after checking it is a finite number (any sign)."""
    if isinstance(x, (bool, str, bytes)) or x is None:
        raise WrongTypeError(f"{name} must be a number of {unit}, got {type(x).__name__} {x!r:.40}")
    try:
        v = value(x)
    except (TypeError, ValueError):
        raise WrongTypeError(f"{name} must be a number of {unit} (or an array of them), got {x!r:.40}") from None
    if not all_true(isfinite(v)):
        raise InputError(f"{name} must be a finite number of {unit}")
    return v


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


class float_errors_ignored:
    """numpy's overflow and divide warnings off (the results are checked by :func:`out`); a no-op for
    Python floats, whose division by a positive number never raises."""

    def __enter__(self):
        import sys

        np = sys.modules.get("numpy")
        self._ctx = np.errstate(over="ignore", divide="ignore", invalid="ignore") if np is not None else None
        if self._ctx is not None:
            self._ctx.__enter__()
        return self

    def __exit__(self, *exc):
        if self._ctx is not None:
            self._ctx.__exit__(*exc)
        return False


def log2(x):
    if isinstance(x, float):
        return math.log2(x)
    import numpy as np

    return np.log2(x)


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


def out(x, *, allow_inf: bool = False, what: str = "the result"):
    """Collapse 0-d arrays to floats, after checking that no NaN (and, unless ``allow_inf``, no infinity:
    a number too large for a float) leaves: an :class:`~physcam.errors.OpticsError` instead."""
    if isinstance(x, float):
        if x != x or (not allow_inf and not math.isfinite(x)):
            raise OpticsError(f"{what} is not a finite number ({x}): the inputs are beyond what a float can hold")
        return x
    import numpy as np

    a = np.asarray(x)
    bad = np.isnan(a) if allow_inf else ~np.isfinite(a)
    if bad.any():
        raise OpticsError(f"{what} is not a finite number: the inputs are beyond what a float can hold")
    return float(a) if a.ndim == 0 else a
