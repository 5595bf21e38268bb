"""Refractive index against wavelength: a maker's dispersion formula when the glass is known,
else a normal-line model from (nd, Vd).

Which model a medium gets (:func:`dispersion`):

1. **Catalogue glass** (``kind = "sellmeier"``): the medium names a glass of
   :mod:`physcam.lens.catalog` that carries its maker's Sellmeier coefficients
   (``Medium.glass``), or its (nd, Vd) match exactly one such glass within
   |nd - nd_cat| <= :data:`MATCH_TOL_ND` (5e-5, half a unit in the 4th decimal) and
   |Vd - Vd_cat| <= :data:`MATCH_TOL_VD` (0.05, about the rounding of a catalogue's 2-decimal Vd
   plus melt tolerance; SCHOTT N-SF6 25.36 and OHARA S-TIH6 25.42 stay apart). Sellmeier:
   n^2 - 1 = sum_i B_i l^2 / (l^2 - C_i), l in micrometres (SCHOTT TIE-29; the SCHOTT, OHARA
   catalogues). The lens file's own nd is honoured: the formula is shifted by the constant
   nd - n_formula(d) (at most the match tolerance, or a melt's offset), which keeps every d-line
   figure of the file unchanged and takes the dispersion shape from the maker.
2. **Normal-line model** (``kind = "normal-line"``), when only (nd, Vd) are known: the three-term
   Cauchy formula n = A + B / l^2 + C / l^4 (l in um; Jenkins & White, *Fundamentals of Optics*,
   4th ed., 23.3) fitted exactly to n(d) = nd, n(F) - n(C) = (nd - 1) / Vd and
   n(g) - n(F) = P_gF (n(F) - n(C)) with SCHOTT's normal line P_gF = 0.6438 - 0.001682 Vd
   (SCHOTT TIE-29, "Refractive index and dispersion", the line through K7 and F2). The partial
   dispersion thus varies with Vd along the line real "normal" glasses follow, where the
   two-term Cauchy fit used before forced one P_gF on every glass. Against real glasses the
   spread of P_gF around the line is the model's uncertainty: over the 123 glasses of SCHOTT's
   catalogue (2018 data) |dP_gF| has a median of 0.004, 68 % are within 0.0083 and 90 % within
   0.0145 (the outliers are the anomalous FK/PK and dense SF glasses); physcam takes
   :data:`PGF_UNCERTAINTY` = 0.01 as a one-sigma figure (used by the colour analysis).
3. ``kind = "constant"``: Vd = 0 and no glass name: non-dispersive (air, pbrt/ISET files).

All three share one representation (:attr:`Dispersion.coefficients`, 9 numbers):
n(l) = a0 + a1 u + a2 u^2 + [sqrt(1 + sum_i B_i l^2 / (l^2 - C_i)) if any B_i], u = 1 / l^2,
l in um. The tracer's kernels evaluate exactly this per ray (mixed wavelengths) and
:func:`physcam.trace.kernels._layout.set_wavelength` per surface (one wavelength), and the
paraxial engine calls :meth:`Dispersion.index`, which does the same arithmetic: no fitted
approximation anywhere, and the paths agree to rounding.

Fraunhofer lines (Schott's definitions of nd, Vd, P_gF): d 587.5618 nm (He), F 486.1327 nm (H),
C 656.2725 nm (H), g 435.8343 nm (Hg).
"""

from __future__ import annotations

import math
from functools import lru_cache

from .._record import record

__all__ = ["LINE_D_NM", "LINE_F_NM", "LINE_C_NM", "LINE_G_NM", "WAVELENGTH_RANGE_NM", "MATCH_TOL_ND",
           "MATCH_TOL_VD", "PGF_NORMAL_LINE", "PGF_UNCERTAINTY", "Dispersion", "dispersion", "normal_line",
           "normal_line_pgf", "cauchy_coefficients", "refractive_index", "medium_index", "require_wavelength",
           "medium_dispersion", "glass_index", "FIT_TOLERANCE", "FIT_BAND_NM", "glasses_without_dispersion"]

LINE_D_NM = 587.5618
LINE_F_NM = 486.1327
LINE_C_NM = 656.2725
LINE_G_NM = 435.8343

#: Wavelengths physcam traces (nm): near UV to the short-wave infrared (a 1550 nm design loads and
#: traces; issue 25). Beyond :data:`FIT_BAND_NM` a glass known only by nd and Vd, or a catalogue
#: formula refitted into the tracer's form, is extrapolated (docs/lens-formats.md).
WAVELENGTH_RANGE_NM = (300.0, 2500.0)
#: The band a catalogue formula is refitted over (:mod:`physcam.optics.glassfit`): where camera sensors
#: respond, near UV to near IR.
FIT_BAND_NM = (300.0, 1100.0)
#: (nd, Vd) tolerance for identifying a catalogue glass (module notes).
MATCH_TOL_ND = 5e-5
MATCH_TOL_VD = 0.05
#: SCHOTT normal line P_gF = a + b Vd (TIE-29).
PGF_NORMAL_LINE = (0.6438, -0.001682)
#: One-sigma spread of real glasses' P_gF about the normal line (module notes).
PGF_UNCERTAINTY = 0.01


def require_wavelength(wavelength_nm, name: str = "wavelength"):
    """Raise :class:`~physcam.errors.InputError` unless every wavelength is finite and in
    :data:`WAVELENGTH_RANGE_NM`; return it unchanged."""
    from ..errors import InputError

    lo, hi = WAVELENGTH_RANGE_NM
    if type(wavelength_nm) is float and lo <= wavelength_nm <= hi:  # the common scalar case, without numpy
        return wavelength_nm
    import numpy as np

    lam = np.asarray(wavelength_nm, dtype=float)
    if not (np.all(np.isfinite(lam)) and np.all(lam >= lo) and np.all(lam <= hi)):
        bad = lam[~(np.isfinite(lam) & (lam >= lo) & (lam <= hi))].ravel()
        raise InputError(f"{name} must lie between {lo:g} and {hi:g} nm (visible light is 380-780 nm), "
                         f"got {bad[0]:g} nm")
    return wavelength_nm


def normal_line_pgf(vd):
    """P_gF on SCHOTT's normal line at Abbe number ``vd``."""
    if type(vd) is float:  # a lens's medium: no numpy (the on-set report does not import it)
        return PGF_NORMAL_LINE[0] + PGF_NORMAL_LINE[1] * vd
    import numpy as np

    return PGF_NORMAL_LINE[0] + PGF_NORMAL_LINE[1] * np.asarray(vd, dtype=float)


def _u(lam_nm: float) -> float:
    return 1.0 / ((lam_nm / 1000.0) ** 2)


def evaluate(coefficients, wavelength_nm):
    """n at ``wavelength_nm`` from the 9 shared coefficients (a0 a1 a2 B1 B2 B3 C1 C2 C3).

    The arithmetic the kernels repeat: l2 = (lambda / 1000)^2, u = 1 / l2,
    n = a0 + (a1 + a2 u) u [+ sqrt(1 + B1 l2/(l2-C1) + B2 l2/(l2-C2) + B3 l2/(l2-C3))].
    """
    a0, a1, a2, b1, b2, b3, c1, c2, c3 = coefficients
    if type(wavelength_nm) is float:  # one wavelength in Python floats, the same operations (no numpy)
        lam = wavelength_nm
        sqrt = math.sqrt
    else:
        import numpy as np

        lam = np.asarray(wavelength_nm, dtype=float)
        sqrt = np.sqrt
    l2 = (lam / 1000.0) * (lam / 1000.0)
    u = 1.0 / l2
    n = a0 + (a1 + a2 * u) * u
    if b1 != 0.0 or b2 != 0.0 or b3 != 0.0:
        n = n + sqrt(1.0 + b1 * l2 / (l2 - c1) + b2 * l2 / (l2 - c2) + b3 * l2 / (l2 - c3))
    return n


@record
class Dispersion:
    """The dispersion model of one medium (module notes)."""

    kind: str  # "sellmeier", "normal-line" or "constant"
    nd: float
    vd: float
    coefficients: tuple  # a0 a1 a2 B1 B2 B3 C1 C2 C3 (see :func:`evaluate`)
    glass: str | None = None  # catalogue name (sellmeier)
    maker: str | None = None
    matched_by: str | None = None  # "name" or "nd/Vd" (catalogue glasses)
    fit_error: float = 0.0  # max |n - n_formula| of a catalogue formula refitted (kind "catalogue-fit")

    def index(self, wavelength_nm):
        """Refractive index at ``wavelength_nm`` (broadcasts)."""
        return evaluate(self.coefficients, wavelength_nm)

    @property
    def pgf(self) -> float:
        """Relative partial dispersion P_gF = (ng - nF) / (nF - nC) of this model (nan if constant)."""
        ng, nf, nc = (float(self.index(w)) for w in (LINE_G_NM, LINE_F_NM, LINE_C_NM))
        return (ng - nf) / (nf - nc) if nf != nc else math.nan

    def describe(self) -> str:
        how = "named in the lens file" if self.matched_by == "name" else "identified by nd/Vd"
        if self.kind == "sellmeier":
            return f"{self.maker} {self.glass} (maker's Sellmeier formula, {how})"
        if self.kind == "catalogue-fit":
            return f"{self.maker} {self.glass} (maker's formula, refitted to {self.fit_error:.1e}, {how})"
        if self.kind == "normal-line":
            return (f"normal-line model from nd {self.nd:.5f}, Vd {self.vd:.2f} "
                    f"(3-term Cauchy, P_gF {float(normal_line_pgf(self.vd)):.4f} +- {PGF_UNCERTAINTY})")
        return f"non-dispersive, n = {self.nd:.5f}"

    def to_dict(self) -> dict:
        return {"nd": self.nd, "vd": self.vd, "model": self.kind, "glass": self.glass, "maker": self.maker,
                "matched_by": self.matched_by, "pgf": None if self.kind == "constant" else self.pgf,
                "description": self.describe()}


def _cauchy3(nd, vd, pgf):
    """(A, B, C) of n = A + B u + C u^2 (u = 1/l^2, l in um) through nd, nF - nC, ng - nF."""
    uf, uc, ud, ug = (float(_u(w)) for w in (LINE_F_NM, LINE_C_NM, LINE_D_NM, LINE_G_NM))
    dn = (nd - 1.0) / vd
    b, c = _solve2((uf - uc, uf * uf - uc * uc), (ug - uf, ug * ug - uf * uf), dn, pgf * dn)
    return nd - b * ud - c * ud * ud, b, c


def _fma(a: float, b: float, c: float) -> float:
    """a b + c rounded once (exact rationals, then Python's correctly rounded integer division)."""
    (an, ad), (bn, bd), (cn, cd) = a.as_integer_ratio(), b.as_integer_ratio(), c.as_integer_ratio()
    return (an * bn * cd + cn * ad * bd) / (ad * bd * cd)


def _solve2(row0, row1, r0: float, r1: float) -> tuple[float, float]:
    """x of [row0; row1] x = (r0, r1) in Python floats: Gaussian elimination with partial pivoting, the
    operations of LAPACK's dgesv as numpy's OpenBLAS runs them here (the updates of the right-hand
    side fused multiply-adds), so the normal-line coefficients are the ones numpy gave (checked
    against numpy.linalg.solve in tests/optics/test_glass_scalar.py) without importing numpy."""
    (a00, a01), (a10, a11) = row0, row1
    if abs(a10) > abs(a00):
        (a00, a01, r0), (a10, a11, r1) = (a10, a11, r1), (a00, a01, r0)
    lower = a10 / a00
    u11 = a11 - lower * a01
    x1 = _fma(-lower, r0, r1) / u11
    return _fma(-x1, a01, r0) / a00, x1


def normal_line(nd: float, vd: float, pgf: float | None = None) -> Dispersion:
    """The normal-line model of (nd, Vd); ``pgf`` overrides P_gF (for sensitivity studies)."""
    nd, vd = float(nd), float(vd)
    if vd == 0.0:
        return Dispersion("constant", nd, vd, (nd, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    p = float(normal_line_pgf(vd)) if pgf is None else float(pgf)
    a, b, c = _cauchy3(nd, vd, p)
    return Dispersion("normal-line", nd, vd, (float(a), b, c, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))


#: Largest |n_fit - n_formula| accepted for a catalogue formula refitted into the tracer's form
#: (:mod:`physcam.optics.glassfit`); above it a lens still loads, with a :class:`PhysCamWarning`.
FIT_TOLERANCE = 2e-5


def _traced_band(g) -> tuple[float, float]:
    lo, hi = g.range_nm or FIT_BAND_NM
    return max(lo, FIT_BAND_NM[0]), min(hi, FIT_BAND_NM[1])


def _catalogue(nd, vd, g, matched_by) -> Dispersion:
    """A catalogue glass's formula in the shared 9-coefficient form, shifted to the medium's nd."""
    if g.sellmeier is not None:
        b1, b2, b3, c1, c2, c3 = g.sellmeier
        base, kind, err = (0.0, 0.0, 0.0, b1, b2, b3, c1, c2, c3), "sellmeier", 0.0
    else:
        from .glassfit import stored_form, tracer_form

        band = _traced_band(g)
        base, err = stored_form(g, band) or tracer_form(g.formula, tuple(g.coefficients), band)
        kind = "catalogue-fit"
        if err > FIT_TOLERANCE:
            import warnings

            from ..errors import PhysCamWarning

            warnings.warn(f"{g.maker} {g.name}: its {_formula_name(g.formula)} formula differs from the tracer's "
                          f"dispersion form by up to {err:.1e} between {_traced_band(g)[0]:g} and "
                          f"{_traced_band(g)[1]:g} nm (tolerance {FIT_TOLERANCE:g})", PhysCamWarning, stacklevel=3)
    offset = nd - float(evaluate(base, LINE_D_NM))
    return Dispersion(kind, nd, vd, (base[0] + offset,) + tuple(base[1:]), g.name, g.maker, matched_by, err)


def _formula_name(f) -> str:
    from ..lens.glassformulas import FORMULA_NAMES

    return FORMULA_NAMES.get(f, f"formula {f}")


@lru_cache(maxsize=4096)
def dispersion(nd: float, vd: float, glass: str | None = None, catalog: str | None = None,
               dpgf: float = 0.0) -> Dispersion:
    """The dispersion model of a medium (module notes): the catalogue formula of ``glass`` (searched
    in ``catalog`` first, then the default order), or of a unique (nd, Vd) match among the common
    glasses, else the normal-line model with P_gF moved by ``dpgf``, else (Vd = 0, no name)
    non-dispersive."""
    from ..lens.catalog import InputError, find_glass, match_glass

    nd, vd = float(nd), float(vd)
    if glass:
        try:
            g = find_glass(glass, [catalog] if catalog else None)
        except InputError:
            g = None
        if g is not None and g.formula is not None:
            return _catalogue(nd, vd if vd else g.vd, g, "name")
    if vd == 0.0:
        return normal_line(nd, 0.0)
    if dpgf == 0.0:
        g = match_glass(nd, vd, MATCH_TOL_ND, MATCH_TOL_VD)
        if g is not None:
            return _catalogue(nd, vd, g, "nd/Vd")
    return normal_line(nd, vd, float(normal_line_pgf(vd)) + dpgf if dpgf else None)


def medium_dispersion(medium) -> Dispersion:
    """:func:`dispersion` of a :class:`~physcam.lens.prescription.Medium` (all its fields)."""
    from ..errors import require_type
    from ..lens.prescription import Medium

    require_type("medium", medium, Medium, "a Medium(nd, vd, glass=...) of a prescription's surface")
    return dispersion(medium.nd, medium.vd, medium.glass, medium.catalog, medium.dpgf)


def glasses_without_dispersion(prescription) -> tuple[int, int]:
    """(glasses the prescription gives no dispersion, glasses): the media behind its surfaces that are not
    air, and of them those whose model is constant (Vd 0 and no named glass, module notes): every
    wavelength bends alike in them, so no colour aberration comes from them."""
    from ..errors import require_type
    from ..lens.prescription import Prescription

    require_type("prescription", prescription, Prescription, "physcam.lens.library.load_lens(name or file)")
    glass = [s.medium for s in prescription.surfaces if not s.medium.is_air]
    return sum(medium_dispersion(m).kind == "constant" for m in glass), len(glass)


def glass_index(name: str, wavelength_nm, catalog: str | None = None):
    """Index of the catalogue glass ``name`` at ``wavelength_nm`` from its maker's own formula
    (:class:`~physcam.lens.catalog.GlassNotFound` if unknown).

    >>> round(float(glass_index("N-BK7", 486.1327)), 5)
    1.52238
    """
    import numpy as np

    from ..lens.catalog import find_glass

    return find_glass(name, [catalog] if catalog else None).index(np.asarray(wavelength_nm, dtype=float))


def medium_index(medium, wavelength_nm):
    """Index of a :class:`~physcam.lens.prescription.Medium` at ``wavelength_nm`` (broadcasts)."""
    from ..errors import require_type
    from ..lens.prescription import Medium

    require_type("medium", medium, Medium, "a lens surface's medium, e.g. lens.surfaces[0].medium")
    return medium_dispersion(medium).index(wavelength_nm)


def refractive_index(nd, vd, wavelength_nm, glass: str | None = None):
    """Index at ``wavelength_nm`` of a glass given by ``nd`` and Abbe number ``vd`` (model of
    :func:`dispersion`; broadcasts over ``wavelength_nm``, and over nd/vd element by element).

    >>> round(float(refractive_index(1.5168, 64.17, 587.5618)), 6)
    1.5168
    """
    import numpy as np

    nd_a, vd_a = np.broadcast_arrays(np.asarray(nd, dtype=float), np.asarray(vd, dtype=float))
    if nd_a.ndim == 0:
        return dispersion(float(nd_a), float(vd_a), glass).index(wavelength_nm)
    lam = np.broadcast_to(np.asarray(wavelength_nm, dtype=float), nd_a.shape)
    out = np.empty(nd_a.shape)
    for k in np.ndindex(nd_a.shape):
        out[k] = float(dispersion(float(nd_a[k]), float(vd_a[k]), glass).index(lam[k]))
    return out


def cauchy_coefficients(nd, vd):
    """(A, B) of the two-term Cauchy fit n = A + B/lambda^2 (lambda in nm) through nd and Vd.

    physcam's model before the normal-line one (kept for comparisons: it forces
    P_gF = (1/g^2 - 1/F^2) / (1/F^2 - 1/C^2) = 0.5410 on every glass); B = 0 when Vd = 0.
    """
    import numpy as np

    nd = np.asarray(nd, dtype=float)
    vd = np.asarray(vd, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        dn = np.where(vd > 0, (nd - 1.0) / np.where(vd > 0, vd, 1.0), 0.0)  # nF - nC
    b = dn / (LINE_F_NM**-2 - LINE_C_NM**-2)
    a = nd - b / LINE_D_NM**2
    return a, b
