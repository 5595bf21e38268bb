"""The extension zip's zoom tables (issue 45), read from the session's zip (no tables computed here):
a zoom lens's EFL table and its report rows at the tabulated positions against a hand ray-transfer-
matrix trace of the lens file (tests/_zoom_abcd.py); a prime has no zoom input. The renders are
tests/blender/test_extension_zoom.py."""

import json
import re
import tomllib
import zipfile
from importlib import resources

import pytest

from _zoom_abcd import abcd_position
from physcam.errors import InputError
from physcam.export.blender_zoom import N_ZOOM_EFL, N_ZOOM_ROWS, zoom_focus_table
from physcam.lens.library import load_lens

ZOOM = "canon_ef_70_200mm_f2_8_zoom"  # tabulated at u = 0, 0.5, 1


def _hand_efls():
    doc = tomllib.loads(resources.files("physcam.data").joinpath("lenses", f"{ZOOM}.toml").read_text(encoding="utf-8"))
    return [abcd_position(doc, k)[0] for k in range(3)]


def test_a_zoom_lens_ships_its_efl_and_rows_across_the_zoom(extension_zip):
    """EFL at infinity focus at u = 0, 0.5, 1 (the EFL table's samples 0, 32, 64; the report rows' first,
    middle and last geometry blocks at infinity) equals the hand trace's 72.118 / 134.948 / 193.910 mm."""
    with zipfile.ZipFile(extension_zip) as z:
        data = json.loads(z.read(f"lenses/{ZOOM}.json"))
        shader = z.read(f"shaders/{ZOOM}.osl").decode("utf-8")  # the four variants' one source
    zoom = data["zoom"]
    hand = _hand_efls()
    assert len(zoom["efl_mm"]) == N_ZOOM_EFL and len(zoom["rows_u"]) == N_ZOOM_ROWS
    ends = [zoom["efl_mm"][0], zoom["efl_mm"][(N_ZOOM_EFL - 1) // 2], zoom["efl_mm"][-1]]
    assert ends == pytest.approx(hand, rel=1e-9)
    assert zoom["range_mm"] == pytest.approx([hand[0], hand[2]], rel=1e-9)
    nf = zoom["n_focus"]
    rows = data["rows"]
    assert len(rows) == N_ZOOM_ROWS * nf
    at_inf = [rows[g * nf]["efl_mm"] for g in (0, (N_ZOOM_ROWS - 1) // 2, N_ZOOM_ROWS - 1)]
    assert at_inf == pytest.approx(hand, rel=1e-6)
    # the default zoom is the first position, inside the range the panel accepts (a rounded 72.118 mm fell
    # 0.3 um short of it: every new camera on the Canon was refused)
    assert zoom["default_mm"] == zoom["range_mm"][0]
    assert "float zoom_focal_length = ZOOM_DEFAULT_MM" in shader
    default = float(re.search(r"#define ZOOM_DEFAULT_MM (\S+)", shader).group(1))
    assert default == pytest.approx(hand[0], rel=1e-8)


def test_a_prime_has_no_zoom_input(extension_zip):
    with zipfile.ZipFile(extension_zip) as z:
        data = json.loads(z.read("lenses/dgauss_50mm.json"))
        shader = z.read("shaders/dgauss_50mm.osl").decode("utf-8")
    assert "zoom" not in data
    assert "zoom_focal_length" not in shader and "ZOOM_EFL" not in shader


def test_zoom_tables_of_a_prime_are_refused():
    with pytest.raises(InputError, match="not a zoom lens"):
        zoom_focus_table(load_lens("dgauss_50mm"))
