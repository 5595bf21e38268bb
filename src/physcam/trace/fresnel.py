"""Fresnel transmission at a refracting surface, and three coating models.

Uncoated: the Fresnel equations for a dielectric interface (Hecht, *Optics*, 5th ed., §4.6.2,
eqs. 4.42-4.43):

    r_s = (n1 cos i - n2 cos t) / (n1 cos i + n2 cos t)
    r_p = (n2 cos i - n1 cos t) / (n2 cos i + n1 cos t)
    R_s = r_s^2, R_p = r_p^2,   T_s = 1 - R_s, T_p = 1 - R_p   (no absorption)

One surface passes unpolarised light with T = (T_s + T_p) / 2. Through several surfaces the s
and p halves stay separate (the planes of incidence of a centred lens's meridional ray coincide;
for skew rays this is the usual scalar approximation that ignores the rotation between
successive planes of incidence), so T = (prod T_s + prod T_p) / 2, which is larger than
prod((T_s + T_p) / 2) at oblique incidence. The tracer carries both (``RayBatch.weight`` and
``weight_sp``); :func:`fresnel_transmittances` gives (T_s, T_p) for one surface.

Coatings are modelled as a factor on R that the tracer applies at every angle and wavelength,
to each polarisation (``R_coated(i) = min(1, s * R_uncoated(i))`` for R_s and R_p), with ``s`` fixed per surface from normal
incidence at the d line:

- ``"none"``: s = 1.
- ``"single"``: one quarter-wave layer of MgF2 (n = 1.38) on each glass-air surface; at its
  design wavelength its normal reflectance is ((n1 n2 - nf^2) / (n1 n2 + nf^2))^2 (Hecht §9.7.1,
  eq. 9.100 with a quarter-wave layer), so s = that / ((n1 - n2) / (n1 + n2))^2. Cemented
  (glass-glass) surfaces stay uncoated.
- ``"multi"``: a broadband multi-layer coating with a residual reflectance of 0.25 % per
  glass-air surface (a typical figure for modern multi-coated cine lenses, not a specific stack).

This ignores the wavelength and angle dependence of the coating itself (a quarter-wave layer is
exact only at its design wavelength); it is meant for throughput and ghost ranking, not for
coating design.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["COATINGS", "MGF2_INDEX", "MULTI_RESIDUAL_REFLECTANCE", "reflectance_scale", "fresnel_transmittance",
           "fresnel_transmittances"]

COATINGS = ("none", "single", "multi")
MGF2_INDEX = 1.38
MULTI_RESIDUAL_REFLECTANCE = 0.0025


def _normal_reflectance(n1: float, n2: float) -> float:
    return ((n1 - n2) / (n1 + n2)) ** 2


def reflectance_scale(coating: str, n1: float, n2: float) -> float:
    """Factor on the uncoated Fresnel reflectance of the n1 -> n2 surface for ``coating``."""
    if coating not in COATINGS:
        raise InputError(f"unknown coating {coating!r}; use one of {', '.join(COATINGS)}")
    r0 = _normal_reflectance(n1, n2)
    glass_air = (n1 == 1.0) != (n2 == 1.0)
    if coating == "none" or r0 == 0.0 or not glass_air:
        return 1.0
    if coating == "single":
        nf2 = MGF2_INDEX**2
        r1 = ((n1 * n2 - nf2) / (n1 * n2 + nf2)) ** 2
        return r1 / r0
    return min(1.0, MULTI_RESIDUAL_REFLECTANCE / r0)


def fresnel_transmittances(n1, n2, cos_i, r_scale=1.0):
    """(T_s, T_p): the s and p transmittances of the n1 -> n2 surface at incidence cosine ``cos_i``.

    Each is 1 - min(1, r_scale R); both 0 beyond the critical angle (total internal
    reflection). Broadcasts.
    """
    n1 = np.asarray(n1, dtype=float)
    n2 = np.asarray(n2, dtype=float)
    ci = np.abs(np.asarray(cos_i, dtype=float))
    eta = n1 / n2
    k = 1.0 - eta * eta * (1.0 - ci * ci)
    ct = np.sqrt(np.maximum(k, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct)
        rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct)
        Rs = rs * rs * r_scale
        Rp = rp * rp * r_scale
    Rs = np.where(Rs < 1.0, Rs, 1.0)  # NaN (0/0 at grazing incidence) -> 1
    Rp = np.where(Rp < 1.0, Rp, 1.0)
    tir = k < 0.0
    return np.where(tir, 0.0, 1.0 - Rs), np.where(tir, 0.0, 1.0 - Rp)


def fresnel_transmittance(n1, n2, cos_i, r_scale=1.0):
    """Unpolarised transmittance (T_s + T_p) / 2 of the n1 -> n2 surface at incidence cosine
    ``cos_i`` (one surface; see the module notes for several). 0 beyond the critical angle. Broadcasts.
    """
    ts, tp = fresnel_transmittances(n1, n2, cos_i, r_scale)
    return 0.5 * (ts + tp)
