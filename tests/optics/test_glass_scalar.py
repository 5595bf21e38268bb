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
from physcam.optics.glassfit import STORED_DIR, stored_form, tracer_form


@settings(max_examples=200, deadline=None)
@given(nd=st.floats(1.3, 2.1), vd=st.floats(15.0, 100.0))
def test_normal_line_solve_is_numpys(nd, vd):
    uf, uc, ug = (glass._u(w) for w in (glass.LINE_F_NM, glass.LINE_C_NM, glass.LINE_G_NM))
    pgf = glass.normal_line_pgf(vd)
    dn = (nd - 1.0) / vd
    b, c = np.linalg.solve(np.array([[uf - uc, uf * uf - uc * uc], [ug - uf, ug * ug - uf * uf]]),
                           np.array([dn, pgf * dn]))
    _, b1, c1 = glass._cauchy3(nd, vd, pgf)
    assert math.isclose(b1, b, rel_tol=1e-14) and math.isclose(c1, c, rel_tol=1e-14)


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


def test_stored_fits_are_what_fitting_gives():
    """The middle glass of each catalogue fitted anew: the stored form to 1e-12
    (a BLAS of another machine may round the least squares differently in the last bits)."""
    for name, table in _stored().items():
        keys = sorted(table)
        for key in (keys[len(keys) // 2],):
            e = table[key]
            form, err = tracer_form(e["formula"], tuple(e["coefficients"]), tuple(e["band_nm"]))
            assert all(math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-18) for a, b in zip(form, e["form"])), key
            assert math.isclose(err, e["error"], rel_tol=1e-6, abs_tol=1e-12)
