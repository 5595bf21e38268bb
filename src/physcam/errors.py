"""One exception hierarchy for physcam.

Every error physcam raises on purpose derives from :class:`PhysCamError`, so a
pipeline can catch one class and the CLI can print one line and exit 2. A bug
(anything else) still shows a traceback.
"""

from __future__ import annotations

import math
from numbers import Real

__all__ = [
    "PhysCamError",
    "InputError",
    "UnitError",
    "OpticsError",
    "SensorError",
    "LensFileError",
    "MetadataError",
    "ExportError",
    "BackendError",
    "PhysCamWarning",
    "WrongTypeError",
    "require_type",
    "require_finite",
    "require_positive",
    "renamed_parameter",
]


class PhysCamError(Exception):
    """Root of every error physcam raises deliberately."""


class InputError(PhysCamError, ValueError):
    """A value given by the user is out of range or inconsistent; the message says what to change."""


class UnitError(InputError):
    """A distance or angle could not be read (unknown unit, not a number)."""


class OpticsError(PhysCamError):
    """The optics have no answer: no real image, the lens cannot focus there, no ray passes."""


class SensorError(InputError):
    """Unknown sensor or film-gate name; the message lists the closest known names."""


class LensFileError(PhysCamError):
    """A lens file could not be read or does not describe a valid lens.

    ``path`` and ``line`` (1-based, ``None`` when not known) say where.
    """

    def __init__(self, message: str, path: str | None = None, line: int | None = None):
        self.path = None if path is None else str(path)
        self.line = line
        self.reason = message
        where = ""
        if self.path is not None:
            where = self.path if line is None else f"{self.path}:{line}"
            where += ": "
        super().__init__(where + message)


class MetadataError(InputError):
    """A camera metadata file (physcam.metadata) could not be read: truncated, an unknown layout, not
    the format it claims, a unit other than the one expected.

    ``path`` and ``line`` (1-based; for a binary file the byte offset, ``line`` None) say where.
    """

    def __init__(self, message: str, path: str | None = None, line: int | None = None,
                 offset: int | None = None):
        self.path = None if path is None else str(path)
        self.line = line
        self.offset = offset
        self.reason = message
        where = ""
        if self.path is not None:
            where = self.path
            if line is not None:
                where += f":{line}"
            elif offset is not None:
                where += f": byte {offset}"
            where += ": "
        super().__init__(where + message)


class ExportError(PhysCamError):
    """A file could not be written (exists without --force, bad stage, foreign prim)."""


class BackendError(PhysCamError):
    """An array backend (numba, numpy) was asked for but cannot be used."""


class MissingExtraError(PhysCamError, ImportError):
    """A feature needs one of physcam's optional extras (``pip install 'physcam[usd]'``...), and it is
    not installed: :func:`physcam.extras.require_extra`. Both a :class:`PhysCamError` (the CLI's one
    line and exit 2) and an :class:`ImportError`."""


class WrongTypeError(PhysCamError, TypeError):
    """An argument of the Python API has the wrong type (a name where a lens object is needed, ...).

    Both a :class:`PhysCamError` and a :class:`TypeError`, so either ``except`` catches it.
    """


def shown_briefly(value) -> str:
    """``value`` as an error message shows it, in at most about 60 characters; an integer beyond 20
    digits by its digit count (``repr`` of a 5000-digit integer raises ValueError in Python 3.11+)."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**20:
        return f"an integer of about {int(value.bit_length() * 0.30103) + 1} digits"
    try:
        text = repr(value)
    except Exception:  # a value whose repr fails is described by its type
        return f"a {type(value).__name__}"
    return text if len(text) <= 60 else text[:57] + "..."


def require_type(name: str, value, cls, hint: str = ""):
    """Return ``value`` if it is an instance of ``cls``, else raise :class:`WrongTypeError` saying what
    was expected (``hint``: how to get one, e.g. "physcam.lens.library.load_lens(name)")."""
    if not isinstance(value, cls):
        want = cls.__name__ if isinstance(cls, type) else " or ".join(c.__name__ for c in cls)
        extra = f" ({hint})" if hint else ""
        raise WrongTypeError(f"{name} must be a {want}{extra}, got {type(value).__name__} {shown_briefly(value)}")
    return value


class PhysCamWarning(UserWarning):
    """An approximation was made; the message says which."""


def renamed_parameter(old: str, new: str, until: str = "0.3"):
    """Decorator: the keyword ``old`` still works as ``new`` with a DeprecationWarning, until version
    ``until`` (one name per concept, docs/conventions.md); giving both is an InputError."""
    import functools
    import warnings

    def wrap(fn):
        @functools.wraps(fn)
        def renamed(*args, **kwargs):
            if old in kwargs:
                if new in kwargs:
                    raise InputError(f"give {new}, not both {new} and {old} (its old name)")
                warnings.warn(f"{fn.__name__}({old}=...) is now {new}=...; {old} goes in physcam {until}",
                              DeprecationWarning, stacklevel=2)
                kwargs[new] = kwargs.pop(old)
            return fn(*args, **kwargs)

        return renamed

    return wrap


def require_finite(name: str, value, *, error=InputError) -> float:
    """Return ``value`` as float, or raise ``error`` naming ``name`` when it is NaN, inf or not a number."""
    if type(value) is float and math.isfinite(value):  # the common case, at once (issue 47)
        return value
    if isinstance(value, bool) or not isinstance(value, (Real,)) and not hasattr(value, "__float__"):
        raise error(f"{name} must be a number, got {shown_briefly(value)}")
    try:
        v = float(value)
    except OverflowError:
        raise error(f"{name} must be a finite number, got {shown_briefly(value)}") from None
    except (TypeError, ValueError):
        raise error(f"{name} must be a number, got {shown_briefly(value)}") from None
    if not math.isfinite(v):
        raise error(f"{name} must be a finite number, got {v}")
    return v


def require_positive(name: str, value, *, unit: str = "mm", error=InputError) -> float:
    """Return ``value`` as a finite float > 0, or raise ``error`` with a message naming ``name``."""
    v = require_finite(name, value, error=error)
    if v <= 0.0:
        raise error(f"{name} must be greater than 0 {unit}".rstrip() + f", got {v:g}")
    return v
