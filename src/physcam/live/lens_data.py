"""Lens distortion for OpenTrackIO samples: OpenCV's normalised coefficients in OpenLensIO's millimetres and order.

OpenTrackIO's ``lens.distortion[]`` follows the OpenLensIO lens model: millimetres on the sensor,
y down, six radial terms in OpenLensIO's order, which camdkit's conversion note and Unreal's Live
Link OpenTrackIO receiver both read the same way; :mod:`physcam.analysis.distortion.openlensio` converts
(its module notes give the units, the order and the direction).

The coefficients come from ONE function, :func:`distortion_for_sample`: the Brown-Conrady U-D model
fitted over the whole frame to the lens's real chief rays at the frame's focus
(:func:`physcam.analysis.distortion.models.fit_brown_conrady`, docs/distortion.md), converted by
its ``opentrackio()``, the entry ``physcam distortion`` writes (y down turns the sign of p1).

Focus distance: OpenTrackIO 1.0.1 defines ``lens.focusDistance`` only as "focus distance/position of
the lens" in metres, and the camera-metadata readers that fill it (camdkit's ARRI, RED, Sony
readers) copy the lens's focus mark, which is measured from the film plane; physcam sends that.
Unreal's CineCamera measures its manual focus distance (centimetres) from the camera's origin, the
entrance pupil when the transform chain applies ``entrancePupilOffset``:
:func:`focus_for_consumer` converts (docs/live.md).
"""

from __future__ import annotations

import math

from ..analysis.distortion.openlensio import DISTORTION_MODEL, RADIAL_TERMS, opencv_to_opentrackio, opentrackio_to_opencv
from ..errors import InputError, renamed_parameter, require_finite, require_positive
from ..lens.prescription import Prescription, takes_prescription

__all__ = ["DISTORTION_MODEL", "RADIAL_TERMS", "opencv_to_opentrackio", "opentrackio_to_opencv",
           "distortion_for_sample", "focus_for_consumer"]


@renamed_parameter("focus_from_film_mm", "focus_mm")
def focus_for_consumer(focus_mm, entrance_pupil_mm, consumer: str = "opentrackio") -> float:
    """The focus distance a consumer wants, from the mark physcam sends (mm in front of the film):
    ``"opentrackio"`` the mark itself, metres (module notes); ``"unreal"`` Unreal's CineCamera
    manual focus distance, centimetres from the entrance pupil (``entrancePupilOffset`` in front of
    the film)."""
    d = require_positive("focus distance", focus_mm)
    if consumer == "opentrackio":
        return d / 1000.0
    if consumer == "unreal":
        pupil = require_finite("entrance pupil offset", entrance_pupil_mm)
        if d <= pupil:
            raise InputError(f"the focus mark {d:g} mm is not in front of the entrance pupil ({pupil:g} mm)")
        return (d - pupil) / 10.0
    raise InputError(f"consumer must be opentrackio or unreal, got {consumer!r}")


@renamed_parameter("focus_from_film_mm", "focus_mm")
@takes_prescription
def distortion_for_sample(lens: Prescription, sensor_width_mm, sensor_height_mm, focus_mm,
                          image_size=(4096, None)) -> tuple[dict, float]:
    """(OpenTrackIO distortion object, the pinhole focal length F in mm it is normalised by) of ``lens``
    focused at ``focus_mm`` (mm in front of the film; inf allowed) on a sensor of the given size.

    The one source of the sample's distortion (module notes): Brown-Conrady U-D fitted to real chief
    rays over the frame, in millimetres. ``image_size`` (W, H pixels; H None from the sensor's
    aspect) sets the fit's pixel weighting and the density of traced rays.
    """
    from ..analysis.distortion.models import fit_brown_conrady, samples_from_field
    from ..analysis.distortion.stmap import MAX_SIDE_PX, distortion_field

    w = require_positive("sensor width", sensor_width_mm)
    h = require_positive("sensor height", sensor_height_mm)
    focus = float(focus_mm) if focus_mm == math.inf else require_positive(
        "focus distance", focus_mm)
    if not isinstance(image_size, (tuple, list)) or len(image_size) != 2:
        raise InputError("image_size is (width, height) in pixels; height may be None")
    W = image_size[0]
    H = image_size[1] if image_size[1] is not None else max(16, min(MAX_SIDE_PX, round(W * h / w)))
    from ..optics.state import camera_state

    field = distortion_field(camera_state(lens, focus_mm=focus, sensor_mm=(w, h)), width_px=W, height_px=H, maps=False)
    fit = fit_brown_conrady(samples_from_field(field), "U-D", max_residual_px=math.inf)
    c = fit.coefficients
    f = float(c["fy_mm"])  # the Y pinhole: an anamorphic's F / squeeze is its X focal length
    return fit.opentrackio(), f
