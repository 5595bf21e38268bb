"""Old paths of modules that moved (issue 43: the sensor into ``optics/``, the analyses into packages
named by concept): ``import physcam.onset.sensors`` keeps working for one version, with a
DeprecationWarning naming the new path, and gives the very module at the new path (one module
object, so ``isinstance`` and monkeypatching see the same classes).

The old paths are answered by an import hook, not by shim files left at the old paths: a file kept
there would stop git's rename detection from carrying other branches' edits of the old file to the
new one. :data:`MOVED` is the one table; docs/CHANGELOG lists it.
"""

from __future__ import annotations

import sys
from importlib import import_module
from importlib.machinery import ModuleSpec  # (importlib.abc and .util would cost every command 25 ms)

#: old module path -> new module path (removed in physcam :data:`UNTIL`)
MOVED = {
    "physcam.onset.sensors": "physcam.optics.sensors",
    "physcam.analysis.lens_compare": "physcam.onset.lens_compare",
    "physcam.analysis.thin_lens_gap": "physcam.onset.thin_lens_gap",
}
UNTIL = "0.3"


class _MovedLoader:
    """A loader (importlib's protocol: create_module, exec_module) that puts the moved module in place."""

    def create_module(self, spec):
        return None  # a placeholder: exec_module puts the real module in its place

    def exec_module(self, module):
        import warnings

        new = MOVED[module.__name__]
        warnings.warn(f"{module.__name__} moved to {new}; the old path goes in physcam {UNTIL}",
                      DeprecationWarning, stacklevel=2)  # warnings skips importlib's own frames
        sys.modules[module.__name__] = import_module(new)


class _MovedFinder:
    """Finds only the old paths of :data:`MOVED`; every other import goes on to Python's own finders."""

    def find_spec(self, name, path=None, target=None):
        if name in MOVED:
            return ModuleSpec(name, _MovedLoader())
        return None


def install() -> None:
    """Put the finder first on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, _MovedFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, _MovedFinder())
