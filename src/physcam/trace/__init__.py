"""physcam.trace: real (sequential) ray tracing through lens prescriptions.

See docs/ray-tracing.md. Data flow: :mod:`.surfaces` flattens a Prescription, :mod:`.kernels`
traces a :class:`.rays.RayBatch` (numba JIT or numpy), :mod:`.trace` is the public API.
The names below load on first use (PEP 562), so that :mod:`.single` (one ray in Python floats,
the on-set report's chief rays) does not import numpy.
"""

from importlib import import_module

__all__ = [
    "OK", "MISSED", "CLIPPED", "TIR", "RayBatch",
    "CameraRays", "camera_rays", "paraxial_image_z", "trace_path", "trace_through", "trace_to_film",
]
_HOME = {**dict.fromkeys(("OK", "MISSED", "CLIPPED", "TIR", "RayBatch"), ".rays"),
         **dict.fromkeys(("CameraRays", "camera_rays", "paraxial_image_z", "trace_path", "trace_through",
                          "trace_to_film"), ".trace")}


def __getattr__(name: str):
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(_HOME[name], __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(list(globals()) + __all__)
