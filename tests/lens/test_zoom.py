"""Zoom lenses in the lens layer: the cam curves, the prescription at a zoom position, the physcam TOML
zoom table, Zemax multi-configuration files and single-position files joined (issue 45)."""

from __future__ import annotations

import math
import warnings
from dataclasses import replace
from pathlib import Path

import pytest
from hypothesis import given, settings, strategies as st

from physcam.errors import InputError, LensFileError, PhysCamWarning
from physcam.lens.formats import physcam_toml, read_lens, zemax
from physcam.lens.library import load_lens
from physcam.lens.prescription import Zoom, ZoomGap
from physcam.lens.zoom import ZOOM_ENCODER_KEY, join_positions, pchip, prescription_at, varying_gaps

DATA = Path(__file__).resolve().parents[1] / "data"
APPLESEED = DATA / "zoom_appleseed"
ZOOMS = ("canon_ef_70_200mm_f2_8_zoom", "laikin_zoom_15_150mm", "nikon_af_s_70_200mm_f2_8e_zoom",
         "nikon_zoom_80_200mm_f2_8")

# ---- the cam curves -------------------------------------------------------------------------------

knots = st.lists(st.floats(0.05, 10.0), min_size=2, max_size=6).map(
    lambda hs: [sum(hs[:k]) for k in range(len(hs) + 1)])


@settings(max_examples=60, deadline=None)
@given(knots, st.data())
def test_pchip_passes_through_every_knot_exactly(x, data):
    y = data.draw(st.lists(st.floats(-100, 100), min_size=len(x), max_size=len(x)))
    assert [pchip(x, y, xk) for xk in x] == y


@settings(max_examples=60, deadline=None)
@given(knots, st.data(), st.booleans())
def test_pchip_is_monotone_where_the_table_is_and_never_overshoots(x, data, rising):
    y = sorted(data.draw(st.lists(st.floats(-100, 100), min_size=len(x), max_size=len(x))), reverse=not rising)
    xs = [min(x[0] + (x[-1] - x[0]) * k / 400, x[-1]) for k in range(401)]
    v = [pchip(x, y, t) for t in xs]
    steps = [b - a for a, b in zip(v, v[1:])]
    assert all(s >= -1e-9 for s in steps) if rising else all(s <= 1e-9 for s in steps)
    assert min(y) - 1e-9 <= min(v) and max(v) <= max(y) + 1e-9


def test_pchip_reproduces_a_straight_line():
    # a linear table has equal secants: the harmonic mean and the end formula give that slope, so the
    # Hermite cubic is the line itself (Fritsch and Carlson 1980)
    x, y = [0.0, 0.3, 1.0], [2.0, 2.9, 5.0]
    for t in (0.1, 0.5, 0.77):
        assert pchip(x, y, t) == pytest.approx(2.0 + 3.0 * t, abs=1e-12)


def test_pchip_refuses_a_point_outside_the_table():
    with pytest.raises(InputError, match="outside"):
        pchip([0, 1], [0, 1], 1.5)


# ---- the bundled zooms at their tabulated positions --------------------------------------------------

@pytest.mark.parametrize("name", ZOOMS)
def test_tabulated_positions_come_back_exactly(name):
    p = load_lens(name)
    z = p.zoom
    for k, u in enumerate(z.encoder):
        q = prescription_at(p, u)
        assert q.zoom is None and dict(q.extras)[ZOOM_ENCODER_KEY] == repr(u)
        for g in z.gaps:
            assert q.surfaces[g.surface].thickness == g.thickness[k]
        if z.stop_semi_diameter is not None:
            assert q.surfaces[q.stop_index].semi_diameter == z.stop_semi_diameter[k]


@pytest.mark.parametrize("name", ZOOMS)
def test_zoom_toml_round_trips(name):
    p = load_lens(name)
    assert physcam_toml.loads(physcam_toml.dumps(p)) == p


def test_the_nikon_e_grid_holds_the_transcribed_close_focus_columns():
    # WO 2019/097669 ex. 1 as transcribed: d25 / d30 at close focus 14.966 / 3.858, 7.506 / 11.318, 2.928 / 15.890 mm,
    # object 753.20 / 750.55 / 753.40 mm from the first vertex
    p = load_lens("nikon_af_s_70_200mm_f2_8e_zoom")
    expect = {0.0: (753.20, 14.966, 3.858), 0.5: (750.55, 7.506, 11.318), 1.0: (753.40, 2.928, 15.890)}
    for u, (d0, d25, d30) in expect.items():
        f = prescription_at(p, u).focus
        assert f.close_distance == d0
        assert {g.surface: g.thickness_close for g in f.gaps} == {24: d25, 29: d30}


def test_between_positions_every_gap_stays_between_its_neighbours():
    p = load_lens("canon_ef_70_200mm_f2_8_zoom")
    for g in p.zoom.gaps:
        lo, hi = sorted(g.thickness[:2])
        for u in (0.1, 0.25, 0.4):
            assert lo <= prescription_at(p, u).surfaces[g.surface].thickness <= hi


@pytest.mark.parametrize("bad", [-0.01, 1.5, math.nan, "0.5", True])
def test_an_encoder_outside_0_to_1_is_refused(bad):
    with pytest.raises(InputError):
        prescription_at(load_lens("laikin_zoom_15_150mm"), bad)


def test_a_prime_is_no_zoom():
    with pytest.raises(InputError, match="not a zoom lens"):
        prescription_at(load_lens("dgauss_50mm"), 0.5)


# ---- validation of the zoom table --------------------------------------------------------------------

def _zoomed(p, **kw):
    return replace(p, zoom=replace(p.zoom, **kw))


def test_a_zoom_table_that_does_not_fit_the_lens_is_refused():
    p = load_lens("laikin_zoom_15_150mm")
    with pytest.raises(LensFileError, match="rise from 0 to 1"):
        _zoomed(p, encoder=(0.0, 0.6, 0.5, 1.0)).validate()
    with pytest.raises(LensFileError, match="air gap"):
        _zoomed(p, gaps=(ZoomGap(0, (p.surfaces[0].thickness, 1.0, 1.0, 1.0)),)).validate()
    with pytest.raises(LensFileError, match="first position"):
        _zoomed(p, gaps=(ZoomGap(4, (1.0, 2.0, 3.0, 4.0)),)).validate()
    with pytest.raises(LensFileError, match="4 finite values"):
        _zoomed(p, gaps=(ZoomGap(4, (p.surfaces[4].thickness, 2.0)),)).validate()


def test_surfaces_that_cross_at_a_later_position_are_refused():
    p = load_lens("laikin_zoom_15_150mm")
    g = p.zoom.gaps[0]
    crossing = ZoomGap(g.surface, g.thickness[:3] + (0.0,))  # no air left between two curved surfaces
    with pytest.raises(LensFileError, match="at zoom position 4"):
        _zoomed(p, gaps=(crossing,) + p.zoom.gaps[1:]).validate()


def test_toml_zoom_table_errors_name_the_file():
    text = (DATA.parent.parent / "src/physcam/data/lenses/laikin_zoom_15_150mm.toml").read_text()
    with pytest.raises(LensFileError, match="unknown key 'gaps'"):
        physcam_toml.loads(text.replace("[[zoom.gap]]", "[[zoom.gaps]]", 1), "x.toml")
    head, zoom = text.split("[zoom]", 1)
    with pytest.raises(LensFileError, match="list of numbers"):
        physcam_toml.loads(head + "[zoom]" + zoom.replace("thickness = [", 'thickness = "x" #[', 1), "x.toml")
    with pytest.raises(LensFileError, match="leave out \\[focus\\]"):
        nikon = (DATA.parent.parent / "src/physcam/data/lenses/nikon_af_s_70_200mm_f2_8e_zoom.toml").read_text()
        physcam_toml.loads(nikon.replace("[zoom]", "[focus]\nclose_distance = 753.2\n\n[zoom]"), "x.toml")


# ---- Zemax multi-configuration --------------------------------------------------------------------

HAND_ZMX = """VERS 190513 80 123457
MODE SEQ
NAME hand-written zoom
UNIT MM X W X CM MR CPMM
ENPD 10
WAVL 0.5875618
SURF 0
  TYPE STANDARD
  CURV 0.0
  DISZ INFINITY
SURF 1
  TYPE STANDARD
  CURV 0.02
  DISZ 5.0
  GLAS ___BLANK 1 0 1.5168 64.17 0 0 0 0 0 0
  DIAM 12 1 0 0 1 ""
SURF 2
  TYPE STANDARD
  CURV 0.0
  DISZ 10.0
  DIAM 12 1 0 0 1 ""
SURF 3
  TYPE STANDARD
  CURV -0.04
  DISZ 2.0
  GLAS ___BLANK 1 0 1.5168 64.17 0 0 0 0 0 0
  DIAM 8 1 0 0 1 ""
SURF 4
  TYPE STANDARD
  CURV 0.0
  DISZ 3.0
  DIAM 8 1 0 0 1 ""
SURF 5
  STOP
  TYPE STANDARD
  CURV 0.0
  DISZ 40.0
  TCOM 2 50.0
  DIAM 5 1 0 0 1 ""
SURF 6
  TYPE STANDARD
  CURV 0.0
  DISZ 0
MNUM 3 1
MOFF 0 1 "" 0 0 0 1 1 0 0.0 "" 0
THIC 2 1 10.0 0 0 0 1 1 1 0 0 "" 0
THIC 2 2 15.0 0 0 0 1 1 1 0 0 "" 0
THIC 2 3 20.0 0 0 0 1 1 1 0 0 "" 0
APER 0 1 10.0 0 0 0 1 1 1 0 0 "" 0
APER 0 2 9.0 0 0 0 1 1 1 0 0 "" 0
APER 0 3 8.0 0 0 0 1 1 1 0 0 "" 0
FVCY 1 1 0 0 0 0 1 1 1 0 0 "" 0
FVCY 1 2 0 0 0 0 1 1 1 0 0 "" 0
FVCY 1 3 0 0 0 0 1 1 1 0 0 "" 0
"""


def test_a_hand_written_multi_configuration_zmx_loads_with_its_configurations():
    from physcam.optics import paraxial

    p = zemax.loads(HAND_ZMX, "hand.zmx")
    z = p.zoom
    assert z.positions == 3 and z.encoder == (0.0, 0.5, 1.0)
    # THIC 2 (Zemax) is the gap after physcam surface 1: 10, 15, 20 mm as written; TCOM 2 50 on surface 5 keeps
    # t2 + t5 = 50 in every configuration: 40, 35, 30 mm
    assert {g.surface: g.thickness for g in z.gaps} == {1: (10.0, 15.0, 20.0), 4: (40.0, 35.0, 30.0)}
    # APER under ENPD: the entrance pupil is 10, 9, 8 mm across in configurations 1, 2, 3
    for u, epd in zip(z.encoder, (10.0, 9.0, 8.0)):
        assert paraxial.gaussian(prescription_at(p, u)).entrance_pupil_diameter == pytest.approx(epd, rel=1e-9)


def test_a_zoom_zmx_round_trips_through_the_writer():
    p = zemax.loads(HAND_ZMX)
    assert zemax.loads(zemax.dumps(p)) == p


@pytest.mark.parametrize("change, message", [
    (("THIC 2 3 20.0", "THIC 2 4 20.0"), "not 1..3"),
    (("THIC 2 3 20.0 0 0 0 1 1 1 0 0 \"\" 0\n", ""), "no value for configuration 3"),
    (("FVCY 1 1 0", "CRVT 1 1 0"), "CRVT changes the lens"),
    (("MOFF 0 1", "THIC 0 1 100 0 0 0 1 1 1 0 0 \"\" 0\nTHIC 0 2 100 0 0 0 1 1 1 0 0 \"\" 0\n"
                  "THIC 0 3 200 0 0 0 1 1 1 0 0 \"\" 0\nMOFF 0 1"), "object distance"),
    (("TCOM 2 50.0", "TCOM 2 12.0"), "negative thickness"),
])
def test_a_bad_multi_configuration_file_is_refused_with_its_line(change, message):
    with pytest.raises(LensFileError, match=message) as err:
        zemax.loads(HAND_ZMX.replace(*change), "bad.zmx")
    assert err.value.path == "bad.zmx"


def test_a_position_solve_keeps_the_sum_of_its_gaps():
    # TOLE 2 55 on surface 5: t2 + t3 + t4 + t5 = 55 with t3 = 2, t4 = 3, so t5 = 40, 35, 30 for t2 = 10, 15, 20
    p = zemax.loads(HAND_ZMX.replace("TCOM 2 50.0", "TOLE 2 55.0"))
    assert {g.surface: g.thickness for g in p.zoom.gaps} == {1: (10.0, 15.0, 20.0), 4: (40.0, 35.0, 30.0)}


def test_tcom_with_words_is_a_comment():
    p = zemax.loads(HAND_ZMX.replace("TCOM 2 50.0", "TCOM keeps the track"))
    assert {g.surface: g.thickness for g in p.zoom.gaps} == {1: (10.0, 15.0, 20.0)}


def test_a_single_configuration_file_is_no_zoom():
    p = zemax.loads(HAND_ZMX.replace("MNUM 3 1", "MNUM 1 1").split("MOFF")[0])
    assert p.zoom is None


# ---- single-position files of one design, joined ---------------------------------------------------

def _appleseed(path):
    from physcam.lens.prescription import AIR, LensMetadata, Medium, Prescription, Surface

    rows = [ln.split() for ln in path.read_text().splitlines() if ln.strip() and ln.lstrip()[0] not in "/#"]
    surfaces = tuple(Surface(float(r), float(t), AIR if float(n) in (0, 1) else Medium(float(n)), float(a),
                             "stop" if float(r) == 0 and float(n) == 0 else "spherical") for r, t, n, a in rows)
    return Prescription(surfaces, LensMetadata(name=path.stem))


def test_joined_appleseed_files_find_the_moving_gaps_the_sources_name():
    # SOURCES.md: the Canon 70-200's gaps vary after rows 6, 10, 17 and 22 (1-based), i.e. surfaces 5, 9, 16, 21
    ps = [_appleseed(APPLESEED / f"canon-zoom-{f}.txt") for f in (70, 135, 200)]
    assert varying_gaps(ps) == [5, 9, 16, 21]
    # the shipped lens was joined from the same files (its apertures clipped where two surfaces cross)
    assert [g.surface for g in load_lens("canon_ef_70_200mm_f2_8_zoom").zoom.gaps] == [5, 9, 16, 21]


def test_joining_nikon_files_gives_the_books_three_gaps():
    # Modern Lens Design fig. 20.3: 1.86/25.27/48.678, 36.928/19.23/1.536, 16.55/10.84/5.133 mm
    p = load_lens("nikon_zoom_80_200mm_f2_8")
    assert {g.surface: g.thickness for g in p.zoom.gaps} == {
        4: (1.86, 25.27, 48.678), 9: (36.928, 19.23, 1.536), 12: (16.55, 10.84, 5.133)}


def test_files_of_different_designs_are_not_joined():
    a = load_lens("laikin_zoom_15_150mm")
    base = replace(a, zoom=None)
    b = base.with_thicknesses({4: 10.0})
    other = base.with_surfaces([replace(base.surfaces[0], radius=300.0)] + list(base.surfaces[1:]))
    with pytest.raises(LensFileError, match="surface 0 differs"):
        join_positions([base, other], names=["w.toml", "t.toml"])
    thick_glass = base.with_thicknesses({0: 40.0})
    with pytest.raises(LensFileError, match="glass thickness"):
        join_positions([base, thick_glass])
    with pytest.raises(LensFileError, match="same lens"):
        join_positions([base, base])
    joined = join_positions([base, b], stated_focal_length=[15, 20])
    assert joined.zoom == Zoom((ZoomGap(4, (base.surfaces[4].thickness, 10.0)),), (0.0, 1.0), None, None, (15.0, 20.0))


def test_a_zoom_read_and_written_keeps_zemax_s_warnings_quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("error", PhysCamWarning)
        zemax.dumps(zemax.loads(HAND_ZMX))
    with pytest.warns(PhysCamWarning, match="zoom x focus grid"):
        zemax.dumps(replace(load_lens("nikon_af_s_70_200mm_f2_8e_zoom"), focus=None))


def test_read_lens_takes_a_zoom_file(tmp_path):
    f = tmp_path / "z.zmx"
    f.write_text(HAND_ZMX)
    assert read_lens(f).zoom.positions == 3


@pytest.mark.parametrize("fmt", ["pbrt", "iset", "seed-toml"])
def test_a_format_without_zoom_positions_says_it_writes_one(fmt):
    from physcam.lens.formats import dumps_lens

    # and, as for any lens, what else the format cannot hold (Abbe numbers, glass names)
    with pytest.warns(PhysCamWarning, match="first zoom position"), pytest.warns(PhysCamWarning, match="drops"):
        dumps_lens(load_lens("laikin_zoom_15_150mm"), fmt)
