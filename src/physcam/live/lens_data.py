"""Lens distortion for OpenTrackIO samples: OpenCV's normalised coefficients in OpenLensIO's millimetres and order.

OpenTrackIO's ``lens.distortion[]`` follows the OpenLensIO lens model (v1.0.1, sections 1.1 and 4.1;
SMPTE RIS-OSVP, shipped with camdkit as ``OpenLensIO_v1-0-1.pdf``): screen coordinates ε are
**millimetres on the sensor**, origin at the centre, x right, y down, and the undistorted point is
ε_u = F (x/z, y/z) with F the pinhole focal length in mm (``pinholeFocalLength``). OpenCV's
coefficients act on the **normalised** coordinates x' = X/Z (dimensionless). With ε = F x' and
r_ε = F r the same polynomial reads, term by term::

    radial      l = k(OpenCV) / F^(2n)       (n = 1, 2, 3: r^2, r^4, r^6)
    tangential  q = p(OpenCV) / F            (the p terms are quadratic in ε, the image is F times
                                              the normalised one)

**Order** (what consumers read): OpenLensIO's rational model numbers its six radial coefficients
alternately, numerator and denominator: ``radial = [l1, l2, l3, l4, l5, l6]`` with l1, l3, l5 the
numerator's r^2, r^4, r^6 terms (OpenCV's k1, k2, k3) and l2, l4, l6 the denominator's (OpenCV's
k4, k5, k6). camdkit's note "Conversion of OpenCV to OpenTrackIO (OpenLensIO) lens calibration
parameters" (SMPTE/ris-osvp-metadata-camdkit, ``src/main/resources/lyx/OpenCV_to_OpenTrackIO.tex``,
corrected 2025-09-02) gives l1 = k1/F^2, l3 = k2/F^4, l5 = k3/F^6, l2 = k4/F^2, l4 = k5/F^4,
l6 = k6/F^6; Epic's Live Link OpenTrackIO receiver (Unreal Engine 5.6+, plugin ``LiveLinkOpenTrackIO``)
reads the same order into its spherical (OpenCV-style) model, K1 = l1 F^2, K2 = l3 F^4,
K3 = l5 F^6, and reads a list of fewer than six terms as no distortion at all. physcam therefore
sends **six** radial terms in this order, the denominator's as 0 (its fit is the polynomial k1-k3),
which both read the same way; a three-term list would be read by camdkit's note as l1, l2, l3 (k1,
k4, k2) and by Unreal as nothing.

Tangential: camdkit's note divides p by F^2 (it compares the terms without the outer factor F); the
dimensions above give F. physcam's prescriptions are centred, so p1 = p2 = 0 and every reading
agrees; the sample's p is p/F.

Direction: OpenCV's model maps an undistorted (pinhole) point to where the lens puts it, the
direction OpenLensIO calls U^-1; OpenTrackIO names coefficients of that direction
``"Brown-Conrady U-D"`` (its default, ``"Brown-Conrady D-U"``, is the inverse map).

The coefficients come from ONE function, :func:`distortion_for_sample`: the Brown-Conrady U-D model
fitted over the whole frame to the lens's real chief rays at the frame's focus
(:func:`physcam.analysis.distortion_models.fit_brown_conrady`, docs/distortion.md), converted here
(y down turns the sign of p1).

Focus distance: OpenTrackIO 1.0.1 defines ``lens.focusDistance`` only as "focus distance/position of
the lens" in metres, and the camera-metadata readers that fill it (camdkit's ARRI, RED, Sony
readers) copy the lens's focus mark, which is measured from the film plane; physcam sends that.
Unreal's CineCamera measures its manual focus distance (centimetres) from the camera's origin, the
entrance pupil when the transform chain applies ``entrancePupilOffset``:
:func:`focus_for_consumer` converts (docs/live.md).
"""

from __future__ import annotations

import math

from ..errors import InputError, require_finite, require_positive
from ..lens.prescription import Prescription, takes_prescription

__all__ = ["DISTORTION_MODEL", "RADIAL_TERMS", "opencv_to_opentrackio", "opentrackio_to_opencv",
           "distortion_for_sample", "focus_for_consumer"]

DISTORTION_MODEL = "Brown-Conrady U-D"
#: radial coefficients physcam sends: OpenLensIO's six (module notes: Unreal reads fewer as none)
RADIAL_TERMS = 6


def opencv_to_opentrackio(k1, k2, k3, p1, p2, focal_length_mm, k4=0.0, k5=0.0, k6=0.0) -> dict:
    """OpenCV's k1-k6, p1, p2 (normalised coordinates) as OpenTrackIO ``radial`` (six terms in
    OpenLensIO's order: k1, k4, k2, k5, k3, k6 each over F^2n) and ``tangential`` (p / F) in
    millimetres for a pinhole of ``focal_length_mm`` (module notes).

    >>> opencv_to_opentrackio(-0.1, 0.02, 0.0, 0.0, 0.0, 10.0)["radial"]
    [-0.001, 0.0, 2e-06, 0.0, 0.0, 0.0]
    """
    names = (("k1", k1), ("k2", k2), ("k3", k3), ("k4", k4), ("k5", k5), ("k6", k6))
    k = dict((n, require_finite(n, v)) for n, v in names)
    ps = [require_finite(n, v) for n, v in (("p1", p1), ("p2", p2))]
    f = require_positive("pinhole focal length", focal_length_mm)
    return {"model": DISTORTION_MODEL,
            "radial": [k["k1"] / f**2, k["k4"] / f**2, k["k2"] / f**4, k["k5"] / f**4, k["k3"] / f**6,
                       k["k6"] / f**6],
            "tangential": [ps[0] / f, ps[1] / f]}


def opentrackio_to_opencv(distortion, focal_length_mm, *, rational: bool = False) -> dict:
    """The inverse of :func:`opencv_to_opentrackio`: an OpenTrackIO distortion object (``radial`` of 1
    to 6 terms in OpenLensIO's order, missing terms 0; optional ``tangential``) as OpenCV's k1, k2,
    k3, p1, p2 for ``focal_length_mm`` (with ``rational`` also k4-k6). Denominator terms (l2, l4, l6)
    that are not 0 raise unless ``rational``: OpenCV's five-coefficient form cannot hold them."""
    if not isinstance(distortion, dict) or not isinstance(distortion.get("radial"), list):
        raise InputError("a distortion object needs a 'radial' list")
    model = distortion.get("model", "Brown-Conrady D-U")
    if model != DISTORTION_MODEL:
        raise InputError(f"only {DISTORTION_MODEL!r} coefficients convert to OpenCV's direction, got {model!r}")
    radial = [require_finite("radial coefficient", v) for v in distortion["radial"]]
    tangential = [require_finite("tangential coefficient", v) for v in distortion.get("tangential", [])]
    if not 1 <= len(radial) <= RADIAL_TERMS or len(tangential) > 2:
        raise InputError("physcam reads 1 to 6 radial (OpenLensIO l1-l6) and up to 2 tangential coefficients")
    f = require_positive("pinhole focal length", focal_length_mm)
    radial += [0.0] * (RADIAL_TERMS - len(radial))
    tangential += [0.0] * (2 - len(tangential))
    out = {"k1": radial[0] * f**2, "k2": radial[2] * f**4, "k3": radial[4] * f**6,
           "p1": tangential[0] * f, "p2": tangential[1] * f}
    below = {"k4": radial[1] * f**2, "k5": radial[3] * f**4, "k6": radial[5] * f**6}
    if rational:
        out.update(below)
    elif any(below.values()):
        raise InputError("the distortion has denominator terms (OpenLensIO l2, l4, l6); OpenCV's k1-k3, p1, p2 "
                         "cannot hold them")
    return out


def focus_for_consumer(focus_from_film_mm, entrance_pupil_mm, consumer: str = "opentrackio") -> float:
    """The focus distance a consumer wants, from the mark physcam sends (mm in front of the film):
    ``"opentrackio"`` the mark itself, metres (module notes); ``"unreal"`` Unreal's CineCamera
    manual focus distance, centimetres from the entrance pupil (``entrancePupilOffset`` in front of
    the film)."""
    d = require_positive("focus distance", focus_from_film_mm)
    if consumer == "opentrackio":
        return d / 1000.0
    if consumer == "unreal":
        pupil = require_finite("entrance pupil offset", entrance_pupil_mm)
        if d <= pupil:
            raise InputError(f"the focus mark {d:g} mm is not in front of the entrance pupil ({pupil:g} mm)")
        return (d - pupil) / 10.0
    raise InputError(f"consumer must be opentrackio or unreal, got {consumer!r}")


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
    c = fit.coefficients
    f = float(c["fy_mm"])  # the Y pinhole: an anamorphic's F / squeeze is its X focal length
    return opencv_to_opentrackio(c["k1"], c["k2"], c["k3"], -c["p1"], c["p2"], f), f
