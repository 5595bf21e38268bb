"""A keyword renamed in the public API keeps working for one version, with a DeprecationWarning."""

from __future__ import annotations

import functools
import warnings

from ..errors import InputError


def renamed_keyword(old: str, new: str, *, removed_in: str):
    """Decorator: ``fn(old=v)`` is ``fn(new=v)`` with a DeprecationWarning naming both and the
    version that drops ``old``; giving both is an InputError."""

    def wrap(fn):
        @functools.wraps(fn)
        def renamed(*args, **kwargs):
            if old in kwargs:
                if new in kwargs:
                    raise InputError(f"{fn.__name__}: give {new} only ({old} is its old name)")
                warnings.warn(f"{fn.__name__}({old}=...) is now {fn.__name__}({new}=...), the same distance; "
                              f"{old} goes in physcam {removed_in}", DeprecationWarning, stacklevel=2)
                kwargs[new] = kwargs.pop(old)
            return fn(*args, **kwargs)

        return renamed

    return wrap
