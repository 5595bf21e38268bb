"""The door of every function that takes a camera first (issue 28): a
:class:`~physcam.optics.state.CameraState` as it is, or a Prescription focused and stopped by
:func:`~physcam.optics.state.camera_state` from the function's own ``focus_mm`` and ``fstop``."""

from __future__ import annotations

from ..errors import InputError, require_type
from .state import CameraState, camera_state

__all__ = ["as_camera", "iris_set"]


def as_camera(lens, *, focus_mm=None, fstop=None, **state) -> CameraState:
    """``lens`` as a CameraState: one as it is (then ``focus_mm`` and ``fstop`` must be None: an
    InputError), or a Prescription through ``camera_state(lens, focus_mm=, fstop=, **state)``."""
    if isinstance(lens, CameraState):
        if focus_mm is not None or fstop is not None:
            raise InputError("a CameraState carries its own focus and f-stop: give them to camera_state(), not here")
        return lens
    return camera_state(lens, focus_mm=focus_mm, fstop=fstop, **state)


def iris_set(state: CameraState) -> bool:
    """Whether the state's iris was set to an f-stop; False: the lens as its file stops it
    (``camera_state(fstop=None)`` keeps the file's stop semi-diameter exactly)."""
    require_type("state", state, CameraState, "physcam.optics.state.camera_state(lens, focus_mm=..., fstop=...)")
    return state.stop_semi_diameter != float(state.lens.surfaces[state.lens.stop_index].semi_diameter)
