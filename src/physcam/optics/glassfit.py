"""A catalogue formula refitted into the tracer's one dispersion form.

The tracer's kernels evaluate one form per ray (:func:`physcam.optics.glass.evaluate`):
n(l) = a0 + a1 u + a2 u^2 + sqrt(1 + sum_i B_i l^2 / (l^2 - C_i)), u = 1/l^2, l in um. A 3-term
Sellmeier catalogue formula (SCHOTT, OHARA; Zemax formula 2) is this form exactly. Any other
formula (the Schott power series of HOYA, CDGM and Sumita, HIKARI's 9-term series, an .agf
Conrady...) is fitted into it over the wavelengths the tracer uses where the catalogue gives
the formula (:data:`~physcam.optics.glass.FIT_BAND_NM` within the formula's range):

1. poles C_i by Levenberg-Marquardt (Marquardt 1963) on log C, the B_i for given poles by
   linear least squares on n^2 - 1 (variable projection, Golub & Pereyra 1973);
2. a0, a1, a2 by linear least squares on what is left in n, the C, d and F lines weighted
   100 times so that nd and nF - nC come out to the formula's to about 1e-7.

:func:`tracer_form` returns the 9 coefficients and the largest |n_fit - n_formula| over
the fitted band (the fit error a lens's report shows; :data:`FIT_TOLERANCE` in
:mod:`physcam.optics.glass`).
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

__all__ = ["tracer_form", "stored_form", "fit_table"]

#: The fits of the bundled catalogues, one file per catalogue (``scripts/glass_fits.py`` writes them with
#: :func:`fit_table`): the numbers :func:`tracer_form` computed where they were written, read instead of
#: fitted (issue 43: a lens of HOYA or CDGM glass reported without numpy, and 50 ms less per glass). Read, they
#: give every machine the same indices: a fit's Levenberg-Marquardt path follows the BLAS's rounding, and on
#: another CPU (AVX2 against AVX-512) it can end on other coefficients, each within its own stated error.
STORED_DIR = Path(__file__).parent.parent / "data" / "glass" / "fits"

_KEY_UM = (0.6562725, 0.5875618, 0.4861327)  # C, d, F


def _solve(l2, n, w, poles):
    """B (least squares on n^2 - 1) then a0 a1 a2 (weighted least squares on what is left in n)
    for the given poles; returns (a, b, residual in n)."""
    import numpy as np

    sb = np.stack([l2 / (l2 - c) for c in poles], axis=1)
    b, *_ = np.linalg.lstsq(sb / (2 * n[:, None]), (n * n - 1.0) / (2 * n), rcond=None)
    s = 1.0 + sb @ b
    if not np.all(s > 0.0):
        return None, None, np.full_like(n, 1.0)
    u = 1.0 / l2
    basis = np.stack([np.ones_like(u), u, u * u], axis=1)
    r = np.sqrt(s) - n
    a, *_ = np.linalg.lstsq(basis * w[:, None], -r * w, rcond=None)
    return a, b, r + basis @ a


def _fit_poles(l2, n, w, lo2, hi2):
    """Poles by a coarse grid, then Levenberg-Marquardt on log C (variable projection)."""
    import numpy as np

    best = None
    for c1 in np.geomspace(1e-4, 0.3 * lo2, 8):
        for c2 in np.geomspace(2.0 * c1, 0.9 * lo2, 7):
            for c3 in (2.0 * hi2 + 10.0, 40.0, 150.0):
                r = _solve(l2, n, w, (c1, c2, c3))[2]
                cost = float(r @ r)
                if best is None or cost < best[0]:
                    best = (cost, np.log([c1, c2, c3]))
    cost, logc = best
    r = _solve(l2, n, w, np.exp(logc))[2]
    lam = 1e-2
    for _ in range(40):
        jac = np.empty((n.size, 3))
        for k in range(3):
            step = np.zeros(3)
            step[k] = 1e-5
            jac[:, k] = (_solve(l2, n, w, np.exp(logc + step))[2] - r) / 1e-5
        h = jac.T @ jac
        trial = logc - np.linalg.solve(h + lam * np.diag(np.diag(h) + 1e-30), jac.T @ r)
        c = np.exp(np.clip(trial, -20.0, 20.0))
        if c[0] < 0.95 * lo2 and c[1] < 0.95 * lo2 and c[2] > 1.05 * hi2:
            rt = _solve(l2, n, w, c)[2]
            ct = float(rt @ rt)
            if ct < cost:
                small = cost - ct < 1e-6 * cost
                logc, r, cost, lam = np.log(c), rt, ct, lam / 5.0
                if small:
                    break
                continue
        lam *= 10.0
        if lam > 1e10:
            break
    return np.exp(logc)


def _model(p, l2):
    import numpy as np

    c = np.exp(p[6:])
    s = 1.0 + sum(p[3 + i] * l2 / (l2 - c[i]) for i in range(3))
    return p[0] + (p[1] + p[2] / l2) / l2 + np.sqrt(np.maximum(s, 1e-12))


def _polish(l2, n, w, p, lo2, hi2, r0):
    """Levenberg-Marquardt on all nine parameters (weighted residual) from the projected start."""
    import numpy as np

    r = (_model(p, l2) - n) * w
    cost, lam = float(r @ r), 1e-3
    for _ in range(200):
        jac = np.empty((n.size, 9))
        for k in range(9):
            step = np.zeros(9)
            step[k] = 1e-7 * max(1.0, abs(p[k]))
            jac[:, k] = ((_model(p + step, l2) - n) * w - r) / step[k]
        h = jac.T @ jac
        trial = p - np.linalg.solve(h + lam * np.diag(np.diag(h) + 1e-30), jac.T @ r)
        c = np.exp(np.clip(trial[6:], -30.0, 30.0))
        if c[0] < 0.95 * lo2 and c[1] < 0.95 * lo2 and c[2] > 1.05 * hi2:
            rt = (_model(trial, l2) - n) * w
            ct = float(rt @ rt)
            if ct < cost:
                small = cost - ct < 1e-9 * cost
                p, r, cost, lam = trial, rt, ct, lam / 5.0
                if small:
                    break
                continue
        lam *= 10.0
        if lam > 1e12:
            break
    return p[:3], p[3:6], np.exp(p[6:]), _model(p, l2) - n


def _fit_wavelengths_um(band_nm: tuple):
    """The wavelengths (um) a fit over ``band_nm`` matches the formula at (its error is the largest miss
    there): 161 across the band, then the C, d and F lines."""
    import numpy as np

    return np.concatenate([np.linspace(band_nm[0], band_nm[1], 161) / 1000.0, _KEY_UM])


@lru_cache(maxsize=2048)
def tracer_form(formula: int, coefficients: tuple, band_nm: tuple) -> tuple[tuple, float]:
    """(9 coefficients a0 a1 a2 B1 B2 B3 C1 C2 C3, max |error|) of ``formula`` fitted over ``band_nm``."""
    import numpy as np

    from ..lens.glassformulas import formula_index

    lam = _fit_wavelengths_um(band_nm)
    n = np.asarray(formula_index(formula, coefficients, lam), dtype=float)
    l2 = lam * lam
    lo2, hi2 = (band_nm[0] / 1000.0) ** 2, (band_nm[1] / 1000.0) ** 2
    w = np.ones_like(n)
    w[-3:] = 100.0
    poles = _fit_poles(l2, n, w, lo2, hi2)
    a, b, r = _solve(l2, n, w, poles)
    a, b, poles, r = _polish(l2, n, w, np.concatenate([a, b, np.log(poles)]), lo2, hi2, r)
    coefs = (float(a[0]), float(a[1]), float(a[2]), *map(float, b), *map(float, poles))
    return coefs, float(np.max(np.abs(r)))


def stored_form(glass, band_nm: tuple) -> tuple[tuple, float] | None:
    """:func:`tracer_form` of a bundled catalogue's ``glass`` (a :class:`~physcam.lens.catalog_glass.CatalogGlass`)
    over ``band_nm`` as stored in :data:`STORED_DIR`, or None when not stored for exactly this formula,
    these coefficients and this band (a user's catalogue, or data changed since the table was written)."""
    from ..errors import InputError, require_type
    from ..lens.catalog_glass import CatalogGlass

    require_type("glass", glass, CatalogGlass, "physcam.lens.catalog.find_glass(name)")
    try:
        band_nm = tuple(float(b) for b in band_nm)
    except (TypeError, ValueError):
        raise InputError(f"band_nm must be (low, high) in nm, got {band_nm!r:.40}") from None
    e = _stored(glass.maker).get(glass.name.upper())
    if (e is None or e["formula"] != glass.formula or tuple(e["coefficients"]) != tuple(glass.coefficients)
            or tuple(e["band_nm"]) != tuple(band_nm)):
        return None
    return tuple(e["form"]), e["error"]


@lru_cache(maxsize=None)
def _stored(maker: str) -> dict:
    path = STORED_DIR / f"{maker}.json"
    return json.loads(path.read_text(encoding="utf-8"))["glasses"] if path.is_file() else {}


def fit_table(glasses, band_of) -> dict:
    """The stored form of ``glasses`` (catalogue glasses whose formula is refitted): {NAME: entry},
    each entry the formula, coefficients and band fitted (the key :func:`stored_form` checks) and the fit."""
    out = {}
    for g in glasses:
        band = band_of(g)
        form, err = tracer_form(g.formula, tuple(g.coefficients), band)
        out[g.name.upper()] = {"formula": g.formula, "coefficients": list(g.coefficients), "band_nm": list(band),
                               "form": list(form), "error": err}
    return out
