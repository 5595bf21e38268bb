"""OpenCV's normalised Brown-Conrady coefficients as an OpenTrackIO ``lens.distortion`` entry, and back.

One conversion for every writer of that entry (``physcam live``'s samples, ``physcam distortion``'s
and ``physcam calibrate``'s OpenTrackIO blocks).

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
"""

from __future__ import annotations

from ...errors import InputError, require_finite, require_positive

__all__ = ["DISTORTION_MODEL", "RADIAL_TERMS", "opencv_to_opentrackio", "opentrackio_to_opencv"]

DISTORTION_MODEL = "Brown-Conrady U-D"
#: radial coefficients physcam sends: OpenLensIO's six (module notes: Unreal reads fewer as none)
RADIAL_TERMS = 6


def opencv_to_opentrackio(k1, k2, k3, p1, p2, focal_length_mm, k4=0.0, k5=0.0, k6=0.0, *,
                          direction: str = "U-D") -> dict:
    """OpenCV's k1-k6, p1, p2 (normalised coordinates, y down as OpenLensIO's: a y-up fit's p1 changes
    sign) as OpenTrackIO ``radial`` (six terms in OpenLensIO's order: k1, k4, k2, k5, k3, k6 each
    over F^2n) and ``tangential`` (p / F) in millimetres for a pinhole of ``focal_length_mm`` (module
    notes); ``direction`` "U-D" (undistorted to distorted, OpenCV's) or "D-U" names the model.

    >>> opencv_to_opentrackio(-0.1, 0.02, 0.0, 0.0, 0.0, 10.0)["radial"]
    [-0.001, 0.0, 2e-06, 0.0, 0.0, 0.0]
    """
    names = (("k1", k1), ("k2", k2), ("k3", k3), ("k4", k4), ("k5", k5), ("k6", k6))
    k = dict((n, require_finite(n, v)) for n, v in names)
    ps = [require_finite(n, v) for n, v in (("p1", p1), ("p2", p2))]
    f = require_positive("pinhole focal length", focal_length_mm)
    if direction not in ("U-D", "D-U"):
        raise InputError(f"direction must be 'U-D' or 'D-U', got {direction!r}")
    return {"model": f"Brown-Conrady {direction}",
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
