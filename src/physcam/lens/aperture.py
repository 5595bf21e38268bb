"""A lens file's system aperture sizes its stop: the paraxial marginal ray at the primary wavelength.

Zemax OpticStudio states a design's aperture as one of (user manual, "System Explorer:
Aperture"; the ``.zmx`` keyword and its flag): ``ENPD D`` the entrance-pupil diameter;
``FNUM N 0`` the image-space F/#, EFL / EPD at infinite conjugates; ``FNUM N 1`` the paraxial
working F/#, 1 / (2 n'u') of the marginal ray at the design's own conjugate; ``OBNA NA 0`` the
object-space numerical aperture n sin U of the marginal ray; ``OBNA a 1`` the object cone
half-angle in degrees; ``FLOA`` float by stop size, the stop's own semi-diameter. Each but
``FLOA`` fixes the stop's semi-diameter, which is the height at the stop of the paraxial
marginal ray, as OpticStudio computes it. For ``OBNA`` the paraxial slope is u = tan(asin(NA/n))
(the marginal ray's real angle, as optiland's ``objectNA`` aperture does).

The trace is the y-nu trace (W. J. Smith, *Modern Optical Engineering*, 4th ed., eqs. 2.31-2.32:
n'u' = nu - y c (n' - n), y_next = y + t n'u' / n'), the same arithmetic as
:func:`physcam.optics.paraxial.paraxial_trace`, repeated here because this layer (the lens
files) may not use the optics layer. It needs each medium's index at the primary wavelength:
:func:`design_index` takes it as :func:`physcam.optics.glass.dispersion` does (tests check the
two agree), from the maker's formula shifted to the file's nd for a catalogue glass, SCHOTT's
normal-line Cauchy model for a model glass, nd for an undispersed medium.
"""

from __future__ import annotations

import math
from dataclasses import replace

from ..errors import InputError, require_type
from .catalog import find_glass, match_glass
from .prescription import Medium, Prescription, takes_prescription

__all__ = ["APERTURE_KINDS", "design_index", "marginal_ray", "size_stop"]

#: Aperture kinds, by their ``.zmx`` keyword and flag.
APERTURE_KINDS = ("ENPD", "FNUM 0", "FNUM 1", "OBNA 0", "OBNA 1", "FLOA")

_D_NM = 587.5618
_D_UM, _F_UM, _C_UM, _G_UM = 0.5875618, 0.4861327, 0.6562725, 0.4358343
# physcam.optics.glass: SCHOTT's normal line of P_gF (TIE-29) and the nd/Vd match tolerances
_PGF_LINE, _MATCH_ND, _MATCH_VD = (0.6438, -0.001682), 5e-5, 0.05


def _normal_line(nd: float, vd: float, dpgf: float, lam_um: float) -> float:
    """n = A + B u + C u^2 (u = 1/l^2, l in um) through nd, nF - nC = (nd - 1)/Vd and
    ng - nF = P_gF (nF - nC), P_gF on SCHOTT's normal line moved by ``dpgf`` (Cramer's rule)."""
    uf, uc, ud, ug, u = (1.0 / (x * x) for x in (_F_UM, _C_UM, _D_UM, _G_UM, lam_um))
    dn = (nd - 1.0) / vd
    pgf = _PGF_LINE[0] + _PGF_LINE[1] * vd + dpgf
    a11, a12, a21, a22 = uf - uc, uf * uf - uc * uc, ug - uf, ug * ug - uf * uf
    det = a11 * a22 - a12 * a21
    b = (dn * a22 - a12 * pgf * dn) / det
    c = (a11 * pgf * dn - a21 * dn) / det
    return nd + b * (u - ud) + c * (u * u - ud * ud)


def design_index(medium: Medium, wavelength_nm: float) -> float:
    """Index of ``medium`` at ``wavelength_nm``, chosen as :func:`physcam.optics.glass.dispersion`
    chooses (module notes); nd itself at the d line, where every model passes through nd."""
    require_type("medium", medium, Medium, "a lens surface's medium, e.g. lens.surfaces[0].medium")
    wavelength_nm = float(wavelength_nm)
    lam = wavelength_nm / 1000.0
    if wavelength_nm == _D_NM or medium.is_air:
        return medium.nd
    g = None
    if medium.glass:
        try:
            g = find_glass(medium.glass, [medium.catalog] if medium.catalog else None)
        except InputError:
            g = None
    if g is None and medium.vd and not medium.dpgf:
        g = match_glass(medium.nd, medium.vd, _MATCH_ND, _MATCH_VD)
    if g is not None and g.formula is not None:
        return medium.nd + float(g.index(wavelength_nm)) - float(g.index(_D_NM))
    if not medium.vd:
        return medium.nd
    return _normal_line(medium.nd, medium.vd, medium.dpgf, lam)


@takes_prescription
def marginal_ray(p: Prescription, y0: float, nu0: float) -> tuple[float, float]:
    """Trace (``y0`` at the first vertex, reduced angle ``nu0`` in air) to the stop and on to the
    last surface: (height at the stop vertex, n'u' after the last surface), at ``p``'s
    design wavelength."""
    n_before, y, nu, at_stop = 1.0, float(y0), float(nu0), None
    for i, s in enumerate(p.surfaces):
        n_after = design_index(s.medium, p.wavelength_nm)
        if s.is_stop:
            at_stop = y
        nu = nu - y * s.curvature * (n_after - n_before)
        y = y + s.thickness * nu / n_after
        n_before = n_after
    return at_stop, nu


@takes_prescription
def size_stop(p: Prescription, kind: str, value: float, object_distance_mm: float = math.inf) -> Prescription:
    """``p`` with its stop's semi-diameter set by the aperture ``kind`` = ``value``
    (:data:`APERTURE_KINDS`) for an object ``object_distance_mm`` in front of the first vertex
    (``inf``: at infinity); ``FLOA`` returns ``p``. :class:`InputError` for an aperture the
    lens cannot have (an NA with the object at infinity, an afocal lens, a stop at the image)."""
    if kind == "FLOA":
        return p
    if kind not in APERTURE_KINDS:
        raise InputError(f"aperture type {kind!r} is not one of {', '.join(APERTURE_KINDS)}")
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"aperture {kind} {value!r} must be a positive number")
    finite = math.isfinite(object_distance_mm)
    if kind.startswith("OBNA"):
        if not finite:
            raise InputError("an object-space NA or cone angle (OBNA) needs an object at a finite distance; "
                             "this file's object is at infinity")
        if kind == "OBNA 0" and value >= 1.0:
            raise InputError(f"object-space NA {value:g} must be below 1 (the object space is air)")
        u = math.tan(math.asin(value)) if kind == "OBNA 0" else math.tan(math.radians(value))
        height = abs(marginal_ray(p, u * object_distance_mm, u)[0])
    elif kind == "FNUM 1":
        unit = marginal_ray(p, object_distance_mm, 1.0) if finite else marginal_ray(p, 1.0, 0.0)
        if unit[1] == 0.0:
            raise InputError("a paraxial working F/# needs a lens that forms a finite image")
        height = abs(unit[0]) / (2.0 * value * abs(unit[1]))
    else:
        y_stop, nu_last = marginal_ray(p, 1.0, 0.0)  # a ray parallel to the axis meets the stop
        epd = value if kind == "ENPD" else _efl(nu_last) / value  # in scale with the EP (any conjugate)
        height = abs(y_stop) * epd / 2.0
    if not (math.isfinite(height) and height > 0):
        raise InputError(f"aperture {kind} {value:g} gives no stop size (the stop is where the image or object is)")
    k = p.stop_index
    return p.with_surfaces(p.surfaces[:k] + (replace(p.surfaces[k], semi_diameter=height),) + p.surfaces[k + 1:])


def _efl(nu_last: float) -> float:
    """EFL (in air, 1/power) from the n'u' after the lens of a ray entering parallel at height 1."""
    if nu_last == 0.0:
        raise InputError("an image-space F/# needs a lens with a focal length (this one is afocal)")
    return abs(1.0 / nu_last)
