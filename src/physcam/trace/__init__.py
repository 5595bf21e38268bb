"""physcam.trace: real (sequential) ray tracing through lens prescriptions.

See docs/ray-tracing.md. Data flow: :mod:`.surfaces` flattens a Prescription, :mod:`.kernels`
traces a :class:`.rays.RayBatch` (numba JIT or numpy), :mod:`.trace` is the public API.
"""

from .rays import CLIPPED, MISSED, OK, TIR, RayBatch
from .trace import CameraRays, camera_rays, paraxial_image_z, trace_path, trace_through, trace_to_film

__all__ = [
    "OK", "MISSED", "CLIPPED", "TIR", "RayBatch",
    "CameraRays", "camera_rays", "paraxial_image_z", "trace_path", "trace_through", "trace_to_film",
]
