"""Glass dispersion for one wavelength in Python floats (issue 43's report without numpy), against numpy:
the normal-line model's 2x2 solve against numpy.linalg.solve, the 9-coefficient formula against its
array form, and the stored catalogue fits (src/physcam/data/glass/fits) against fitting anew."""

import json
import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.lens.catalog import BUILTIN_CATALOGS, catalog
from physcam.optics import glass
from physcam.optics.glassfit import STORED_DIR, stored_form


@settings(max_examples=200, deadline=None)
@given(nd=st.floats(1.3, 2.1), vd=st.floats(15.0, 100.0))
def test_normal_line_solve_is_numpys(nd, vd):
    uf, uc, ug = (glass._u(w) for w in (glass.LINE_F_NM, glass.LINE_C_NM, glass.LINE_G_NM))
    pgf = glass.normal_line_pgf(vd)
    dn = (nd - 1.0) / vd
    a = np.array([[uf - uc, uf * uf - uc * uc], [ug - uf, ug * ug - uf * uf]])
    b, c = np.linalg.solve(a, np.array([dn, pgf * dn]))
    _, b1, c1 = glass._cauchy3(nd, vd, pgf)
    # two solvers of one system each err by up to about cond(A) x eps in norm (Higham 2002, ch. 7): 4 of those
    # apart, in |x| (a small c, 1e-6 beside b's 1e-2, may differ by more than that fraction of itself)
    tol = 4.0 * np.linalg.cond(a) * np.finfo(float).eps  # cond 44: 3.9e-14 (an AVX2 machine's LAPACK: 1.5e-14 apart)
    size = math.hypot(b, c)
    assert math.isclose(b1, b, rel_tol=tol, abs_tol=tol * size) and math.isclose(c1, c, rel_tol=tol, abs_tol=tol * size)


@settings(max_examples=100, deadline=None)
@given(nd=st.floats(1.4, 2.0), vd=st.floats(18.0, 90.0), wl=st.floats(300.0, 2500.0))
def test_one_wavelength_is_the_array_formula(nd, vd, wl):
    model = glass.dispersion(nd, vd)
    assert model.index(wl) == float(model.index(np.array([wl]))[0])  # the same operations, bit for bit
    assert math.isclose(model.index(glass.LINE_D_NM), nd, rel_tol=1e-12)  # the model goes through nd


def _stored():
    return {p.stem: json.loads(p.read_text())["glasses"] for p in sorted(STORED_DIR.glob("*.json"))}


def test_every_refitted_catalogue_glass_is_stored_with_its_current_data():
    for name in BUILTIN_CATALOGS:
        for g in catalog(name).values():
            if g.formula is not None and g.sellmeier is None:
                assert stored_form(g, glass._traced_band(g)) is not None, f"{name} {g.name}: not stored"


def test_stored_fits_meet_their_formula_within_their_stored_error():
    """Every stored fit evaluated as the tracer does (:func:`glass.evaluate`) against its catalogue formula at
    the wavelengths the fit used: the largest difference is the error stored beside it. Not "a fit anew gives
    the same coefficients": the Levenberg-Marquardt path depends on the BLAS's rounding (on an AVX2 machine
    a fit anew lands on other coefficients, 0.08-20x the stored error), which is why physcam reads the stored
    fits everywhere: the same glass indices on every machine."""
    import numpy as np

    from physcam.lens.glassformulas import formula_index
    from physcam.optics.glassfit import _fit_wavelengths_um

    for name, table in _stored().items():
        for key, e in table.items():
            lam_um = _fit_wavelengths_um(tuple(e["band_nm"]))
            want = np.asarray(formula_index(e["formula"], tuple(e["coefficients"]), lam_um), dtype=float)
            got = glass.evaluate(tuple(e["form"]), lam_um * 1000.0)
            assert math.isclose(float(np.max(np.abs(got - want))), e["error"], rel_tol=1e-6, abs_tol=1e-12), \
                (name, key)