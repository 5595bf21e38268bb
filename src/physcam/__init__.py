"""physcam: physical cameras for film and VFX.

On-set lens reports (thin-lens and datasheet models, exact depth of field, CoC,
hyperfocal, inversions from measured DOF, anamorphic squeeze, entrance pupil),
real lens prescriptions, and cameras for OpenUSD, RenderMan, Blender and pbrt.
Millimetres throughout; see docs/conventions.md.
"""

from . import _moved
from .errors import (
    BackendError,
    ExportError,
    InputError,
    LensFileError,
    OpticsError,
    PhysCamError,
    PhysCamWarning,
    SensorError,
    UnitError,
)

__version__ = "0.2.0"

_moved.install()  # old module paths (issue 43) answer for one version, with a DeprecationWarning

__all__ = [
    "__version__",
    "PhysCamError",
    "InputError",
    "UnitError",
    "OpticsError",
    "SensorError",
    "LensFileError",
    "ExportError",
    "BackendError",
    "PhysCamWarning",
]
