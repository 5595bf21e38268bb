"""The (nd, Vd) dispersion model against a published catalogue glass."""

import pytest
from hypothesis import given
from hypothesis import strategies as st

from physcam.optics.glass import LINE_C_NM, LINE_D_NM, LINE_F_NM, refractive_index


def test_nbk7_against_the_schott_catalogue():
    # SCHOTT N-BK7 data sheet: nd 1.51680, Vd 64.17, nF 1.52238, nC 1.51432. A two-term fit from
    # (nd, Vd) reproduces nF and nC to about 1e-4 (it cannot know their split exactly).
    n = refractive_index(1.5168, 64.17, [LINE_F_NM, LINE_D_NM, LINE_C_NM])
    assert n[1] == pytest.approx(1.51680, abs=1e-12)
    assert n[0] == pytest.approx(1.52238, abs=1e-4)
    assert n[2] == pytest.approx(1.51432, abs=1e-4)


@given(st.floats(1.4, 2.0), st.floats(18.0, 95.0))
def test_abbe_number_is_reproduced_exactly(nd, vd):
    nF, nD, nC = refractive_index(nd, vd, [LINE_F_NM, LINE_D_NM, LINE_C_NM])
    assert nD == pytest.approx(nd, rel=1e-13)
    assert (nD - 1) / (nF - nC) == pytest.approx(vd, rel=1e-9)
    assert nF > nD > nC  # normal dispersion


def test_zero_abbe_means_no_dispersion():
    n = refractive_index(1.6, 0.0, [400.0, 587.5618, 700.0])
    assert list(n) == [1.6, 1.6, 1.6]
