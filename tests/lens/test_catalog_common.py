"""The common glasses' nd and Vd that physcam.lens.catalog keeps beside the catalogues (so that a medium
far from all of them is told so without reading SCHOTT's and OHARA's files, issue 43) are the
catalogues' own, and match_glass answers as it does from the catalogues themselves."""

from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.lens import catalog


def _from_the_catalogues(nd, vd, tol_nd, tol_vd):
    """match_glass's rule applied to the catalogues' own glasses (the oracle: no stored table)."""
    hits = [g for g in catalog.GLASSES.values()
            if g.formula is not None and abs(g.nd - nd) <= tol_nd and abs(g.vd - vd) <= tol_vd]
    return hits[0] if len(hits) == 1 else None


def test_the_stored_common_glasses_are_the_catalogues():
    assert catalog._COMMON_ND_VD == tuple((key, g.nd, g.vd) for key, g in catalog.GLASSES.items()
                                          if g.formula is not None)


@settings(max_examples=150, deadline=None)
@given(which=st.sampled_from(catalog._COMMON_ND_VD + (("far", 1.9, 20.0),)),
       dnd=st.floats(-2e-3, 2e-3) | st.floats(-1e-4, 1e-4), dvd=st.floats(-0.6, 0.6) | st.floats(-0.1, 0.1),
       tol_nd=st.sampled_from([0.0, 5e-5, 1e-3, 0.01]), tol_vd=st.sampled_from([0.0, 0.05, 0.5, 2.0]))
def test_match_glass_is_the_catalogues_answer(which, dnd, dvd, tol_nd, tol_vd):
    nd, vd = which[1] + dnd, which[2] + dvd
    expected = _from_the_catalogues(nd, vd, tol_nd, tol_vd)
    kept, catalog._Common._table = catalog._Common._table, None  # as in a fresh process: the stored table first
    try:
        assert catalog.match_glass(nd, vd, tol_nd, tol_vd) == expected
    finally:
        catalog._Common._table = kept


def test_a_medium_far_from_every_common_glass_reads_no_catalogue():
    import subprocess
    import sys

    code = ("from physcam.lens import catalog\n"
            "assert catalog.match_glass(1.834, 37.19, 5e-4, 0.5) is None\n"  # zuiko_18mm's first glass
            "print(sorted(catalog._BUILTIN))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "['MISC']"
