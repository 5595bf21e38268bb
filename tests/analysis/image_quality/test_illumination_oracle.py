"""Relative illumination against the independent optics oracle of issue 8 (item 4), its
convergence with the grid, a monotonic property, and bounded sizes.

Oracle figures (independent tracer, object at infinity, d line, wide open, paraxial film plane):
Zeiss Distagon 35 mm f/4 at 31.54 deg: 0.4599; ISET double Gauss 3.52 mm at 28.96 deg: 0.0110.
Both beams pass a strongly curved front element obliquely, which a sampling window of the front
semi-diameter on the vertex plane cut short (0.4455 and 0.0086 before).
"""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.analysis.image_quality.illumination import MAX_GRID, relative_illumination
from physcam.cli import main
from physcam.errors import InputError
from physcam.lens.library import load_lens


@pytest.mark.parametrize("name, field, oracle", [
    ("zeiss_distagon_35mm_f4", 31.54, 0.4599),
    ("dgauss_77deg_3_5201mm", 28.96, 0.0110),
])
def test_matches_the_oracle(name, field, oracle):
    r = relative_illumination(load_lens(name), [0.0, field])  # default grid 200
    assert r.points[1].relative_illumination == pytest.approx(oracle, rel=0.01)


def test_converges_with_the_grid():
    lens = load_lens("zeiss_distagon_35mm_f4")
    ri = {g: relative_illumination(lens, [0.0, 31.54], grid=g).points[1].relative_illumination for g in (200, 1200)}
    assert ri[200] == pytest.approx(ri[1200], rel=2e-3)


@settings(max_examples=6, deadline=None)
@given(st.floats(2.0, 24.0), st.floats(1.0, 8.0))
def test_double_gauss_darkens_outward(a, gap):
    # wide open the pbrt double Gauss vignettes more and more off axis (from about 1 deg on; below
    # that its barrel distortion holds RI at 1.0000): RI falls with field
    lens = load_lens("dgauss_50mm")
    r = relative_illumination(lens, [0.0, a, a + gap], grid=100)
    ri = [p.relative_illumination for p in r.points]
    assert ri[0] == 1.0 > ri[1] > ri[2] > 0


def test_sizes_are_bounded_before_allocation(capsys):
    lens = load_lens("dgauss_50mm")
    for bad in (100_000, MAX_GRID + 1, 15, True, 2.5):
        with pytest.raises(InputError, match=f"from 16 to {MAX_GRID}"):
            relative_illumination(lens, [0.0], grid=bad)
    with pytest.raises(InputError, match="from 2 to 200"):
        relative_illumination(lens, n_fields=10**9)
    assert main(["illumination", "dgauss_50mm", "--grid", "100000"]) == 2
    err = capsys.readouterr().err
    assert "grid" in err and str(MAX_GRID) in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert math.isfinite(relative_illumination(lens, [0.0, 5.0], grid=16).points[1].relative_illumination)


def test_field_counts_are_bounded_before_allocation():
    from physcam.analysis.distortion.field import real_distortion

    lens = load_lens("dgauss_50mm")
    for bad in (10**9, 201, 2):
        with pytest.raises(InputError, match="from 3 to 200"):
            real_distortion(lens, n_fields=bad)
    with pytest.raises(InputError, match="from 2 to 200"):
        relative_illumination(lens, n_fields=1)
