"""Lens distortion for OpenTrackIO samples: OpenCV's normalised coefficients in OpenLensIO's millimetres.

OpenTrackIO's ``lens.distortion[]`` follows the OpenLensIO lens model (v1.0.1, section 1.1 and 4.1;
SMPTE RIS-OSVP, shipped with camdkit as ``OpenLensIO_v1-0-1.pdf``): screen coordinates ε are
**millimetres on the sensor**, origin at the centre, x right, y down, and the undistorted point is
ε_u = F (x/z, y/z) with F the pinhole focal length in mm (``pinholeFocalLength``). OpenCV's
coefficients act on the **normalised** coordinates x' = X/Z (dimensionless). With ε = F x' and
r_ε = F r the same polynomial reads, term by term::

    radial      k_n(OpenTrackIO) = k_n(OpenCV) / F^(2n)       (n = 1, 2, 3: r^2, r^4, r^6)
    tangential  p_n(OpenTrackIO) = p_n(OpenCV) / F            (the p terms are quadratic in ε, the
                                                                image is F times the normalised one)

(camdkit's "Conversion of OpenCV to OpenTrackIO lens calibration parameters" gives the radial rule;
its tangential line divides by F^2 by comparing terms without the outer factor F; the dimensions
above give F. physcam's prescriptions are centred, so p1 = p2 = 0 and the two readings agree.)

Direction: OpenCV's model maps an undistorted (pinhole) point to where the lens puts it, the
direction OpenLensIO calls U^-1; OpenTrackIO names coefficients of that direction
``"Brown-Conrady U-D"`` (its default, ``"Brown-Conrady D-U"``, is the inverse map).

Order: ``radial`` lists the numerator's r^2, r^4, r^6 coefficients (k1, k2, k3), as OpenCV and
Unreal's Brown-Conrady models number them. OpenLensIO's own equation (17) numbers a rational
model's coefficients alternately (k1, k3, k5 above, k2, k4, k6 below); physcam sends only the
polynomial k1-k3 (the fit's ``k1k2k3`` terms), so no denominator term is ever sent.

The coefficients come from ONE function, :func:`distortion_for_sample`: the Brown-Conrady U-D model
fitted over the whole frame to the lens's real chief rays at the frame's focus
(:func:`physcam.analysis.distortion_models.fit_brown_conrady`, docs/distortion.md), whose
``opentrackio()`` makes this same conversion (y down turns the sign of p1).
"""

from __future__ import annotations

import math

from ..errors import InputError, require_finite, require_positive
from ..lens.prescription import Prescription, takes_prescription

__all__ = ["DISTORTION_MODEL", "opencv_to_opentrackio", "opentrackio_to_opencv", "distortion_for_sample"]

DISTORTION_MODEL = "Brown-Conrady U-D"


def opencv_to_opentrackio(k1, k2, k3, p1, p2, focal_length_mm) -> dict:
    """OpenCV's k1, k2, k3, p1, p2 (normalised coordinates) as OpenTrackIO ``radial``/``tangential``
    in millimetres for a pinhole of ``focal_length_mm`` (module notes).

    >>> opencv_to_opentrackio(-0.1, 0.02, 0.0, 0.0, 0.0, 10.0)["radial"]
    [-0.001, 2e-06, 0.0]
    """
    ks = [require_finite(n, v) for n, v in (("k1", k1), ("k2", k2), ("k3", k3))]
    ps = [require_finite(n, v) for n, v in (("p1", p1), ("p2", p2))]
    f = require_positive("pinhole focal length", focal_length_mm)
    return {"model": DISTORTION_MODEL,
            "radial": [ks[0] / f**2, ks[1] / f**4, ks[2] / f**6],
            "tangential": [ps[0] / f, ps[1] / f]}


def opentrackio_to_opencv(distortion, focal_length_mm) -> dict:
    """The inverse of :func:`opencv_to_opentrackio`: an OpenTrackIO distortion object (``radial`` of
    1 to 3 terms, optional ``tangential``) back to OpenCV's k1, k2, k3, p1, p2 for ``focal_length_mm``."""
    if not isinstance(distortion, dict) or not isinstance(distortion.get("radial"), list):
        raise InputError("a distortion object needs a 'radial' list")
    model = distortion.get("model", "Brown-Conrady D-U")
    if model != DISTORTION_MODEL:
        raise InputError(f"only {DISTORTION_MODEL!r} coefficients convert to OpenCV's direction, got {model!r}")
    radial = [require_finite("radial coefficient", v) for v in distortion["radial"]]
    tangential = [require_finite("tangential coefficient", v) for v in distortion.get("tangential", [])]
    if not 1 <= len(radial) <= 3 or len(tangential) > 2:
        raise InputError("physcam reads 1 to 3 radial (k1-k3) and up to 2 tangential (p1, p2) coefficients")
    f = require_positive("pinhole focal length", focal_length_mm)
    radial += [0.0] * (3 - len(radial))
    tangential += [0.0] * (2 - len(tangential))
    return {"k1": radial[0] * f**2, "k2": radial[1] * f**4, "k3": radial[2] * f**6,
            "p1": tangential[0] * f, "p2": tangential[1] * f}


@takes_prescription
def distortion_for_sample(lens: Prescription, sensor_width_mm, sensor_height_mm, focus_from_film_mm,
                          image_size=(4096, None)) -> tuple[dict, float]:
    """(OpenTrackIO distortion object, the pinhole focal length F in mm it is normalised by) of ``lens``
    focused at ``focus_from_film_mm`` (mm in front of the film; inf allowed) on a sensor of the given size.

    The one source of the sample's distortion (module notes): Brown-Conrady U-D fitted to real chief
    rays over the frame, in millimetres. ``image_size`` (W, H pixels; H None from the sensor's
    aspect) sets the fit's pixel weighting and the density of traced rays.
    """
    from ..analysis.distortion_models import fit_brown_conrady, samples_from_field
    from ..analysis.stmap import MAX_SIDE_PX, distortion_field

    w = require_positive("sensor width", sensor_width_mm)
    h = require_positive("sensor height", sensor_height_mm)
    focus = float(focus_from_film_mm) if focus_from_film_mm == math.inf else require_positive(
        "focus distance", focus_from_film_mm)
    if not isinstance(image_size, (tuple, list)) or len(image_size) != 2:
        raise InputError("image_size is (width, height) in pixels; height may be None")
    W = image_size[0]
    H = image_size[1] if image_size[1] is not None else max(16, min(MAX_SIDE_PX, round(W * h / w)))
    field = distortion_field(lens, focus_mm=focus, sensor_width_mm=w, sensor_height_mm=h, width_px=W, height_px=H,
                             maps=False)
    fit = fit_brown_conrady(samples_from_field(field), "U-D", max_residual_px=math.inf)
    return fit.opentrackio(), float(fit.coefficients["fy_mm"])
