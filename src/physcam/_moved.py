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
    # analysis/ split into packages named by concept
    "physcam.analysis.mtf": "physcam.analysis.image_quality.mtf",
    "physcam.analysis.psf": "physcam.analysis.image_quality.psf",
    "physcam.analysis.spot": "physcam.analysis.image_quality.spot",
    "physcam.analysis.wavefront": "physcam.analysis.image_quality.wavefront",
    "physcam.analysis.huygens": "physcam.analysis.image_quality.huygens",
    "physcam.analysis.colour": "physcam.analysis.image_quality.colour",
    "physcam.analysis.illumination": "physcam.analysis.image_quality.illumination",
    "physcam.analysis.ghosts": "physcam.analysis.image_quality.ghosts",
    "physcam.analysis.distortion_focus": "physcam.analysis.distortion.across_focus",
    "physcam.analysis.distortion_models": "physcam.analysis.distortion.models",
    "physcam.analysis.distortion_names": "physcam.analysis.distortion.names",
    "physcam.analysis.anamorphic_distortion": "physcam.analysis.distortion.anamorphic",
    "physcam.analysis.stmap": "physcam.analysis.distortion.stmap",
    "physcam.analysis.openlensio": "physcam.analysis.distortion.openlensio",
    "physcam.analysis.calibrate": "physcam.analysis.calibration.calibrate",
    "physcam.analysis.calibrate_chart": "physcam.analysis.calibration.chart",
    "physcam.analysis.calibrate_compare": "physcam.analysis.calibration.compare",
    "physcam.analysis.calibrate_flat": "physcam.analysis.calibration.flat_field",
    "physcam.analysis.calibrate_names": "physcam.analysis.calibration.names",
    "physcam.analysis.calibrate_sheet": "physcam.analysis.calibration.sheet",
    "physcam.analysis.defocus_exr": "physcam.analysis.defocus.exr",
    "physcam.analysis.defocus_kernels": "physcam.analysis.defocus.kernels",
    "physcam.analysis.bokeh": "physcam.analysis.defocus.bokeh",
    "physcam.analysis.blob": "physcam.analysis.defocus.blob",
    "physcam.analysis.real_dof": "physcam.analysis.defocus.real_dof",
    "physcam.analysis.lightfield": "physcam.analysis.defocus.lightfield",
    "physcam.analysis.field_of_view": "physcam.analysis.framing.field_of_view",
    "physcam.analysis.breathing_real": "physcam.analysis.framing.breathing_real",
    "physcam.analysis.breathing_plot": "physcam.analysis.framing.breathing_plot",
    "physcam.analysis.zoom_plot": "physcam.analysis.framing.zoom_plot",
    "physcam.analysis.lens_card": "physcam.analysis.lens_cards.card",
    "physcam.analysis.diagram": "physcam.analysis.lens_cards.diagram",
    "physcam.analysis.lens_probes": "physcam.analysis.lens_cards.probes",
}
#: old modules whose path is now the package of their concept: the old module's names answer from the
#: package, read from the module now holding them (:func:`folded_names`)
FOLDED = {
    "physcam.analysis.distortion": "physcam.analysis.distortion.field",
    "physcam.analysis.defocus": "physcam.analysis.defocus.render",
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


def folded_names(package: str):
    """The module ``__getattr__`` of a package of :data:`FOLDED`: a name of the old module (one the module
    now holding it defines), with a DeprecationWarning naming its new path. A submodule of the package, a
    dunder or an unknown name is an AttributeError, so Python's import of a submodule goes on as usual
    (and ``from package import submodule`` does not load the old module's code)."""
    import os

    folder = os.path.dirname(sys.modules[package].__file__)

    def __getattr__(name: str):
        if name.startswith("__") or os.path.exists(os.path.join(folder, name + ".py")):
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        new = import_module(FOLDED[package])
        value = getattr(new, name, _MISSING)
        if value is _MISSING or name.startswith("_") or type(value) is type(sys):
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        import warnings

        warnings.warn(f"{package}.{name} moved to {FOLDED[package]}.{name}; the old path goes in physcam {UNTIL}",
                      DeprecationWarning, stacklevel=2)
        return value

    return __getattr__


_MISSING = object()


def install() -> None:
    """Put the finder first on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, _MovedFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, _MovedFinder())
