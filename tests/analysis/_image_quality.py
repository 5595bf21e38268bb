"""Closed forms worked by hand for the image-quality tests (independent of physcam's code), and a
lens whose image is perfect on axis.

The perfect lens: a stop in air, a flat face into glass of index n, then a hyperboloid of conic
k = -n^2 and vertex radius R = -(n - 1) f back into air. A collimated axial beam crosses the
flat face undeviated and the hyperboloid (a Cartesian oval for a plane wave: n z + |F - P| =
const) sends every ray exactly through the point F a distance f behind its vertex. Its sine
condition does not hold: a ray at height h leaves at sin u' = h / sqrt(h^2 + (f - z(h))^2)
with z(h) the surface's sag, so its real numerical aperture is a little below h / f.
"""

from __future__ import annotations

import math

import numpy as np

from physcam.lens.prescription import LensMetadata, Medium, Prescription, Surface

F_MM = 100.0
N_GLASS = 1.5
STOP_Z = 0.0
VERTEX_Z = 10.0  # stop 5 mm in front of the flat face, 5 mm of glass


def perfect_lens(stop_sd: float = 6.25) -> Prescription:
    r = -(N_GLASS - 1.0) * F_MM
    return Prescription(
        (Surface(0.0, 5.0, semi_diameter=stop_sd, kind="stop"),
         Surface(0.0, 5.0, Medium(N_GLASS, 0.0), 20.0, kind="flat"),
         Surface(r, F_MM, semi_diameter=20.0, kind="aspheric", conic=-N_GLASS ** 2)),
        LensMetadata(name="stigmatic plano-hyperbolic singlet"),
    ).validate()


def hyperbola_sag(h):
    """z of the hyperboloid at height h from its vertex: r^2 = 2 R z - (1 + k) z^2 solved for z."""
    r = -(N_GLASS - 1.0) * F_MM
    k = -N_GLASS ** 2
    h = np.asarray(h, dtype=float)
    c = 1.0 / r
    return c * h * h / (1.0 + np.sqrt(1.0 - (1.0 + k) * c * c * h * h))


def sin_u(h):
    """sin of the image-space angle of the ray entering at height h (it passes through F)."""
    h = np.asarray(h, dtype=float)
    return h / np.sqrt(h * h + (F_MM - hyperbola_sag(h)) ** 2)


def textbook_mtf(x):
    """(2/pi)(acos x - x sqrt(1 - x^2)): an aberration-free circular pupil, x = nu / cut-off."""
    x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
    return (2.0 / np.pi) * (np.arccos(x) - x * np.sqrt(1.0 - x * x))


def _gauss(a, b, n=400):
    t, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (b - a) * t + 0.5 * (a + b), 0.5 * (b - a) * w


def defocus_otf(s, w20):
    """OTF of a circular pupil with defocus W = w20 rho^2 (waves), s = nu / cut-off.

    Shear the unit pupil by +-s along x: the phase difference is w20 ((x + s)^2 - (x - s)^2) = 4 w20 s x
    waves over the lens-shaped overlap |y| <= sqrt(1 - (|x| + s)^2), |x| <= 1 - s, so
    OTF = (4/pi) int_0^{1-s} cos(8 pi w20 s x) sqrt(1 - (x + s)^2) dx (H. H. Hopkins, Proc. R. Soc.
    A 231, 91 (1955), in one-dimensional form). With x + s = sin(phi) the integrand is smooth:
    (4/pi) int_{asin s}^{pi/2} cos(8 pi w20 s (sin phi - s)) cos^2 phi d phi, Gauss-Legendre.
    """
    s = float(s)
    if s >= 1.0:
        return 0.0
    phi, w = _gauss(math.asin(s), math.pi / 2)
    return float((4.0 / math.pi) * np.sum(w * np.cos(8 * math.pi * w20 * s * (np.sin(phi) - s)) * np.cos(phi) ** 2))


def strehl_defocus(w20):
    """Intensity at the centre of a defocused circular pupil's PSF over the focused peak:
    |int_0^1 exp(2 pi i w20 t) dt|^2 = (sin(pi w20) / (pi w20))^2 (t = rho^2)."""
    x = math.pi * w20
    return 1.0 if x == 0 else (math.sin(x) / x) ** 2


def defocus_opd_exact(sin_theta, R, dz):
    """OPD (mm) between a spherical wave converging to F and the reference sphere centred dz beyond
    F (radius R + dz through the same pupil point), along the ray at angle theta: the ray from the
    wave's point P meets the reference sphere at t with (t - R)^2 - 2 (t - R) dz cos(theta) + dz^2 =
    (R + dz)^2, so W = -t = sqrt((R + dz)^2 - dz^2 sin^2 theta) - R - dz cos(theta)
    (~ dz (1 - cos theta) to first order)."""
    s = np.asarray(sin_theta, dtype=float)
    return np.sqrt((R + dz) ** 2 - dz * dz * s * s) - R - dz * np.sqrt(1.0 - s * s)


def reference_sine(sin_theta, R, dz):
    """sin of the angle under which the reference sphere's centre (dz beyond the focus F, radius
    R + dz) sees the point where a ray converging to F at angle theta crosses that sphere: with F
    at the origin the ray is t (sin, cos) (t < 0 before F) and |t d - dz z|^2 = (R + dz)^2 gives
    t = dz cos - sqrt((R + dz)^2 - dz^2 sin^2); the point's height |t| sin over R + dz. Hopkins'
    cut-off for the refocused plane is 2 n' sin / lambda with this sine: the pupil seen from the
    plane's centre, a / (R + dz) rather than a / R."""
    s = np.asarray(sin_theta, dtype=float)
    c = np.sqrt(1.0 - s * s)
    t = dz * c - np.sqrt((R + dz) ** 2 - dz * dz * s * s)
    return np.abs(t) * s / (R + dz)


def bessel_j1(z):
    """J1(z) = (1/pi) int_0^pi cos(tau - z sin tau) d tau (Bessel's integral), Gauss-Legendre."""
    tau, w = _gauss(0.0, math.pi)
    z = np.atleast_1d(np.asarray(z, dtype=float))
    return (np.cos(tau[None, :] - z[:, None] * np.sin(tau[None, :])) @ w) / math.pi


def disk_mtf(nu, radius_mm):
    """MTF of a uniformly lit disk of ``radius_mm`` (a geometric defocus blur): |2 J1(z) / z|, z = 2 pi nu a."""
    z = 2 * math.pi * np.asarray(nu, dtype=float) * radius_mm
    out = np.ones_like(z)
    nz = z != 0
    out[nz] = np.abs(2 * bessel_j1(z[nz]) / z[nz])
    return out
