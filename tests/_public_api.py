"""The library's public names, for the tests that hold every one of them to a rule."""

from __future__ import annotations

import importlib
import pkgutil

import physcam


def public_objects(skip_modules: tuple[str, ...]):
    """(module name, name, object) for every name in the ``__all__`` of physcam's modules that the
    module itself defines, skipping modules whose name contains one of ``skip_modules``."""
    for m in pkgutil.walk_packages(physcam.__path__, "physcam."):
        if any(s in m.name for s in skip_modules):
            continue
        mod = importlib.import_module(m.name)
        for name in getattr(mod, "__all__", []):
            obj = getattr(mod, name, None)
            if getattr(obj, "__module__", None) == mod.__name__:
                yield mod.__name__, name, obj
