"""Refractive index against wavelength from a glass's (nd, Vd).

Model: the two-term Cauchy dispersion formula n(λ) = A + B / λ², fitted so that
n(λd) = nd and (nd − 1) / (nF − nC) = Vd exactly, with the Fraunhofer lines
d = 587.5618 nm (He), F = 486.1327 nm (H), C = 656.2725 nm (H) as in the
Schott catalogue definitions of nd and Vd. Source: F. A. Jenkins & H. E. White,
*Fundamentals of Optics*, 4th ed., §23.3 (Cauchy's formula); Schott TIE-29
(definitions of nd, Vd). Outside roughly 400-700 nm a two-term fit drifts from a
real glass by a few 1e-3; a catalogue glass with Sellmeier terms can replace it.

A medium with Vd = 0 is non-dispersive (air, index matching oil as given).
"""

from __future__ import annotations

import numpy as np

__all__ = ["LINE_D_NM", "LINE_F_NM", "LINE_C_NM", "WAVELENGTH_RANGE_NM", "cauchy_coefficients", "refractive_index",
           "require_wavelength"]

LINE_D_NM = 587.5618
LINE_F_NM = 486.1327
LINE_C_NM = 656.2725

#: Wavelengths physcam traces (nm): near UV to near IR, where camera sensors respond and a
#: two-term dispersion fit from (nd, Vd) still means something.
WAVELENGTH_RANGE_NM = (300.0, 1100.0)


def require_wavelength(wavelength_nm, name: str = "wavelength"):
    """Raise :class:`~physcam.errors.InputError` unless every wavelength is finite and in
    :data:`WAVELENGTH_RANGE_NM`; return it unchanged."""
    from ..errors import InputError

    lam = np.asarray(wavelength_nm, dtype=float)
    lo, hi = WAVELENGTH_RANGE_NM
    if not (np.all(np.isfinite(lam)) and np.all(lam >= lo) and np.all(lam <= hi)):
        bad = lam[~(np.isfinite(lam) & (lam >= lo) & (lam <= hi))].ravel()
        raise InputError(f"{name} must lie between {lo:g} and {hi:g} nm (visible light is 380-780 nm), "
                         f"got {bad[0]:g} nm")
    return wavelength_nm


def cauchy_coefficients(nd, vd):
    """(A, B) of n = A + B/λ² (λ in nm) reproducing nd and Vd; B = 0 when Vd = 0."""
    nd = np.asarray(nd, dtype=float)
    vd = np.asarray(vd, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        dn = np.where(vd > 0, (nd - 1.0) / np.where(vd > 0, vd, 1.0), 0.0)  # nF - nC
    b = dn / (LINE_F_NM**-2 - LINE_C_NM**-2)
    a = nd - b / LINE_D_NM**2
    return a, b


def refractive_index(nd, vd, wavelength_nm):
    """Index at ``wavelength_nm`` of a glass given by ``nd`` and Abbe number ``vd`` (broadcasts).

    >>> round(float(refractive_index(1.5168, 64.17, 587.5618)), 6)
    1.5168
    """
    a, b = cauchy_coefficients(nd, vd)
    lam = np.asarray(wavelength_nm, dtype=float)
    return a + b / (lam * lam)
