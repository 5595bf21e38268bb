"""Unreal's lens file of a zoom lens as a focus x zoom grid (issue 45 phase 2).

The zoom keys and the focal lengths at infinity are checked against a paraxial ABCD trace written
here from the bundled TOML file itself (read with tomllib, not through physcam): the Canon 70-200's
glasses are non-dispersive (one index each), so the trace needs no dispersion model. The focused rows
are checked against physcam's optics layer (`technical_planes` at that zoom position and mark).
"""

from __future__ import annotations

import math
import tomllib
from importlib import resources

import pytest
from _zoom_abcd import abcd_position

from physcam.errors import InputError
from physcam.export.unreal import INFINITY_FOCUS_CM, unreal_lens_file
from physcam.lens.library import load_lens
from physcam.lens.zoom import prescription_at
from physcam.optics.focusing import technical_planes
from physcam.optics.zoom import encoder_for_focal_length

CANON = "canon_ef_70_200mm_f2_8_zoom"
W_MM, H_MM, W_PX, H_PX = 24.89, 18.66, 1920, 1440


def _doc():
    text = resources.files("physcam.data").joinpath("lenses", f"{CANON}.toml").read_text(encoding="utf-8")
    return tomllib.loads(text)


def _rows(data, name):
    table = next(t for t in data["cameraParameterTables"] if t["parameterName"] == name)
    return [[float(v) for v in r.split(",")] for r in table["data"].split(";")]


def test_a_zoom_lens_file_is_a_focus_by_zoom_grid_against_a_hand_abcd_trace():
    lens = load_lens(CANON)
    doc = _doc()
    efls = [abcd_position(doc, k)[0] for k in range(3)]
    assert efls == pytest.approx([72.118, 134.948, 193.910], abs=5e-4)  # docs/zoom.md's table, optiland's
    data = unreal_lens_file(lens, W_MM, H_MM, image_width_px=W_PX, image_height_px=H_PX,
                            focus_marks_mm=[math.inf, 3000.0])
    fl = _rows(data, "FocalLengthTable")
    assert len(fl) == 6  # 3 tabulated positions x 2 marks
    assert sorted({r[1] for r in fl}) == pytest.approx(efls, rel=1e-9)  # ZoomEncoder: the EFL at infinity, mm
    for k, efl in enumerate(efls):
        inf = next(r for r in fl if r[0] == INFINITY_FOCUS_CM and r[1] == pytest.approx(efl, rel=1e-9))
        assert inf[2] * W_MM == pytest.approx(efl, rel=1e-6)  # the pinhole at infinity is the EFL
        assert inf[3] * H_MM == pytest.approx(efl, rel=1e-6)
        near = next(r for r in fl if r[0] == 300.0 and r[1] == pytest.approx(efl, rel=1e-9))
        tp = technical_planes(prescription_at(lens, lens.zoom.encoder[k]), 3000.0)
        assert near[3] * H_MM == pytest.approx(tp.pinhole_focal_length_mm, rel=1e-6)
        nodal = next(r for r in _rows(data, "NodalOffsetTable") if r[0] == 300.0 and r[1] == pytest.approx(efl))
        assert nodal[-1] * 10.0 == pytest.approx(tp.entrance_pupil_from_film_mm, rel=1e-9)
    marks = data["physcam"]["marks"]
    assert [m["zoom_encoder"] for m in marks] == [0.0, 0.0, 0.5, 0.5, 1.0, 1.0]
    assert data["physcam"]["zoom_focal_lengths_mm"] == pytest.approx(efls, rel=1e-9)


def test_zoom_positions_between_the_tabulated_ones():
    lens = load_lens(CANON)
    data = unreal_lens_file(lens, W_MM, H_MM, image_width_px=W_PX, image_height_px=H_PX,
                            focus_marks_mm=[math.inf], zoom_positions=["100mm", 0.75])
    fl = _rows(data, "FocalLengthTable")
    assert [r[1] for r in fl][0] == pytest.approx(100.0, rel=1e-9)  # keyed by the EFL asked for
    assert fl[0][2] * W_MM == pytest.approx(100.0, rel=1e-6)
    assert [m["zoom_encoder"] for m in data["physcam"]["marks"]] == pytest.approx(
        [encoder_for_focal_length(lens, 100.0), 0.75], abs=1e-12)
    assert 134.948 < fl[1][1] < 193.910  # encoder 0.75 lies between the middle and long positions


def test_zoom_positions_on_a_prime_are_refused():
    with pytest.raises(InputError, match="no zoom table"):
        unreal_lens_file(load_lens("dgauss_50mm"), W_MM, H_MM, image_width_px=W_PX, image_height_px=H_PX,
                         focus_marks_mm=[math.inf], zoom_positions=["50mm"])
