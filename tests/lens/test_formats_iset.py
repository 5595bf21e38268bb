import json

import pytest

from physcam.errors import LensFileError
from physcam.lens.formats import dumps_lens, loads_lens, read_lens
from physcam.lens.formats._common import extra

from lens_reference import ISET_FILES, REFERENCE

ISET = REFERENCE / "iset-json" / "dgauss.77deg.3.5201mm.json"
DGAUSS = REFERENCE / "pbrt-dat" / "dgauss.50mm.dat"

MICROLENS = {
    "name": "microlens", "dimensions": [16, 16], "offsets": [[0.0, 0.0]],
    "surfaces": [{"radius": 0.01, "thickness": 0.005, "ior": 1.5, "semi_aperture": 0.004}],
}


def test_reads_stop_semi_apertures_and_keeps_the_rest():
    p = read_lens(ISET)
    assert p.stop_index == 5 and p.surfaces[5].medium.is_air
    assert p.surfaces[0].semi_diameter == 0.88075
    assert p.name == "dgauss.22deg.3.0mm"  # the file's own name field (differs from the file name)
    assert extra(p, "iset.type") == "multi element lens"


def test_units_are_mm_a_scaled_pbrt_dgauss():
    # The ISET lens is pbrt's dgauss.50mm (mm) scaled: every radius and semi-aperture in the same ratio.
    a, b = read_lens(ISET), read_lens(DGAUSS)
    ratios = [x.radius / y.radius for x, y in zip(a.surfaces, b.surfaces) if y.radius]
    assert max(ratios) - min(ratios) < 2e-4
    assert ratios[0] == pytest.approx(3.5201 / 50.3582, rel=1e-3)  # file name 3.5201 mm over pbrt EFL


@pytest.mark.parametrize("path", ISET_FILES, ids=lambda p: p.name)
@pytest.mark.parametrize("via", ["iset", "physcam"])
def test_round_trip(path, via):
    p = read_lens(path)
    assert loads_lens(dumps_lens(p, via), via) == p


def test_microlens_block_and_unknown_surface_keys_round_trip():
    doc = json.loads(ISET.read_text())
    doc["microlens"] = MICROLENS
    doc["surfaces"][0]["vendor_note"] = "front"
    p = loads_lens(json.dumps(doc, indent=2), "iset")
    assert extra(p, "iset.microlens") == MICROLENS
    for via in ("iset", "physcam"):
        q = loads_lens(dumps_lens(p, via), via)
        assert q == p
    assert json.loads(dumps_lens(p, "iset"))["surfaces"][0]["vendor_note"] == "front"


def test_aspheric_surface():
    doc = json.loads(ISET.read_text())
    doc["surfaces"][0]["conic_constant"] = -0.5
    doc["surfaces"][0]["aspheric_coefficients"] = [1e-3, -2e-5]
    p = loads_lens(json.dumps(doc), "iset")
    s = p.surfaces[0]
    assert (s.kind, s.conic, s.aspheric) == ("aspheric", -0.5, (1e-3, -2e-5))
    assert loads_lens(dumps_lens(p, "iset"), "iset") == p


@pytest.mark.parametrize(
    "text, match",
    [
        ("{", "not valid JSON"),
        ("[]", "JSON object"),
        ('{"surfaces": [{"radius": 1}]}', "no 'thickness'"),
        ('{"surfaces": [{"radius": NaN, "thickness": 1, "ior": 0, "semi_aperture": 1}]}', "finite"),
    ],
)
def test_bad_json(text, match):
    with pytest.raises(LensFileError, match=match):
        loads_lens(text, "iset", "x.json")
