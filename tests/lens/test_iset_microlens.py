"""Issue 13.4: ISET lens JSON with a microlens block, as lenstool's ``insertmicrolens`` writes it
(seed 004; isetlens/pbrt-v4 ``lenstool.cpp``): ``"microlens": {"dimensions": [xdim, ydim],
"surfaces": [the microlens file's rows], "offsets": xdim * ydim pairs of zeros}``, the lens renamed
"<lens> w/ microlens <microlens>"."""

from __future__ import annotations

import json
import math

import pytest

from physcam.errors import ExportError, InputError, LensFileError
from physcam.lens.formats import dumps_lens, loads_lens
from physcam.lens.formats.iset import dumps, loads, microlens_of, with_microlens
from physcam.lens.library import load_lens
from physcam.optics.paraxial import gaussian

from lens_reference import REFERENCE

ISET = REFERENCE / "iset-json" / "dgauss.77deg.3.5201mm.json"


def test_block_has_lenstools_layout_and_round_trips():
    main = loads(ISET.read_text())
    lenslet = loads(ISET.read_text(), name="tiny dgauss")  # any prescription serves as a lenslet
    p = with_microlens(main, lenslet, count_x=3, count_y=2, film_width_mm=0.6, film_height_mm=0.4,
                       film_to_lens_mm=4.0, sensor_offset_mm=0.05)
    doc = json.loads(dumps(p))
    assert doc["name"] == "dgauss.22deg.3.0mm w/ microlens tiny dgauss"
    m = doc["microlens"]
    assert m["dimensions"] == [3, 2]
    assert m["offsets"] == [[0.0, 0.0]] * 6
    assert m["surfaces"] == json.loads(ISET.read_text())["surfaces"]  # the lenslet's rows as in its file
    assert doc["surfaces"] == json.loads(ISET.read_text())["surfaces"]  # the main lens untouched
    back = microlens_of(loads_lens(dumps(p), "iset"))
    assert back["count_x"] == 3 and back["count_y"] == 2 and back["thin_focal_length_mm"] is None
    assert back["lenslet"].surfaces == lenslet.surfaces
    assert (back["film_width_mm"], back["film_height_mm"], back["film_to_lens_mm"], back["sensor_offset_mm"]) == \
        (0.6, 0.4, 4.0, 0.05)
    assert loads_lens(dumps_lens(p, "physcam"), "physcam") == p  # physcam's TOML carries the block too


def test_thin_lenslet_is_written_as_an_equivalent_glass_lenslet():
    """ISET needs surfaces: a thin lenslet of focal length f is written as a plano-convex lenslet of
    index 1.5, R = (n - 1) f (its power is the curved face's), filling its cell; physcam reads the
    ideal lenslet back."""
    p = with_microlens(load_lens("dgauss_50mm"), thin_focal_length_mm=0.2, count_x=10, count_y=10,
                       film_width_mm=0.4, film_height_mm=0.4)
    rows = json.loads(dumps(p))["microlens"]["surfaces"]
    assert rows[0]["radius"] == pytest.approx(0.1) and rows[0]["ior"] == 1.5
    assert rows[0]["semi_aperture"] == pytest.approx(0.02 * math.sqrt(2.0))  # the cell's half diagonal
    assert rows[-1]["ior"] == 0.0  # the stop on the flat face
    glass = loads(json.dumps({"name": "pc", "surfaces": rows}))
    assert gaussian(glass).efl == pytest.approx(0.2, rel=1e-12)
    back = microlens_of(p)
    assert back["thin_focal_length_mm"] == 0.2 and back["lenslet"] is None and back["sensor_offset_mm"] is None


def test_what_cannot_be_written_is_refused():
    main = load_lens("dgauss_50mm")
    with pytest.raises(ExportError, match="cylinders|anamorphic"):
        with_microlens(load_lens("navarro_anamorphic_2x"), thin_focal_length_mm=5.0)
    with pytest.raises(InputError):
        with_microlens(main)  # no lenslet
    with pytest.raises(InputError):
        with_microlens(main, main, thin_focal_length_mm=5.0)  # two lenslets
    once = with_microlens(main, thin_focal_length_mm=5.0)
    with pytest.raises(InputError, match="already"):
        with_microlens(once, thin_focal_length_mm=5.0)
    with pytest.raises(InputError, match="of its own"):
        with_microlens(main, once)
    with pytest.raises(InputError):
        with_microlens(main, thin_focal_length_mm=5.0, count_x=0)
    with pytest.raises(InputError):
        with_microlens(main, thin_focal_length_mm=5.0, offsets_mm=[[0.0, 0.0]])
    with pytest.raises(ExportError, match="too strong"):
        with_microlens(main, thin_focal_length_mm=0.01)  # f/0.008 over a 1.25 mm cell: no glass lenslet


@pytest.mark.parametrize("block, why", [
    ({"dimensions": [0, 2], "surfaces": []}, "dimensions"),
    ({"dimensions": [2, 2], "surfaces": [], "offsets": [[0, 0]]}, "offsets"),
    ({"dimensions": [1, 1], "surfaces": [], "offsets": [[0, "x"]]}, "number"),
    ({"dimensions": [1, 1], "surfaces": "no"}, "surfaces"),
])
def test_malformed_blocks_are_lens_file_errors(block, why):
    doc = json.loads(ISET.read_text())
    doc["microlens"] = block
    with pytest.raises(LensFileError, match=why):
        microlens_of(loads(json.dumps(doc)))
