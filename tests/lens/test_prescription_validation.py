"""Prescription.validate: each broken lens gets a precise message naming the surface."""

import pytest

from physcam import LensFileError
from physcam.lens.prescription import Focus, LensMetadata, Medium, Prescription, Surface, VariableGap

GLASS = Medium(1.5168, 64.17)


def lens(*surfaces, focus=None):
    return Prescription(tuple(surfaces), LensMetadata(name="test"), focus=focus)


def good():
    return [Surface(50.0, 5.0, GLASS, 10.0), Surface(-50.0, 2.0, semi_diameter=10.0),
            Surface(0.0, 40.0, semi_diameter=5.0, kind="stop")]


def test_good_lens_passes():
    assert lens(*good()).validate().stop_index == 2


@pytest.mark.parametrize("mutate, message", [
    (lambda s: s.__setitem__(2, Surface(0.0, 40.0, semi_diameter=5.0, kind="flat")), "no aperture stop"),
    (lambda s: s.__setitem__(0, Surface(0.0, 5.0, GLASS, 10.0, kind="stop")), "2 aperture stops"),
    (lambda s: s.__setitem__(0, Surface(8.0, 5.0, GLASS, 10.0)), "exceeds the radius 8 mm"),
    (lambda s: s.__setitem__(0, Surface(50.0, -1.0, GLASS, 10.0)), "negative axial gap"),
    (lambda s: s.__setitem__(0, Surface(50.0, 0.5, GLASS, 10.0)), "crosses surface 1"),
    (lambda s: s.__setitem__(0, Surface(50.0, 5.0, GLASS, 0.0)), "semi-diameter must be > 0"),
    (lambda s: s.__setitem__(0, Surface(50.0, 5.0, Medium(0.9, 0.0), 10.0)), "index after the surface"),
    (lambda s: s.__setitem__(0, Surface(float("nan"), 5.0, GLASS, 10.0)), "NaN"),
    (lambda s: s.__setitem__(0, Surface(50.0, 5.0, GLASS, 10.0, conic=-1.0)), "not marked aspheric"),
    (lambda s: s.__setitem__(0, Surface(0.0, 5.0, GLASS, 10.0, kind="cylindrical_x")), "needs a non-zero radius"),
    # issue 8: physical bounds, so no huge number reaches the optics (index 1e20 in a pbrt file,
    # 1e308 on a stop row printed nan and EFL 0)
    (lambda s: s.__setitem__(0, Surface(50.0, 5.0, Medium(1e20, 0.0), 10.0)), "between 1 and 5"),
    (lambda s: s.__setitem__(2, Surface(0.0, 40.0, Medium(1e308, 0.0), 5.0, kind="stop")), "between 1 and 5"),
    (lambda s: s.__setitem__(0, Surface(50.0, 5.0, Medium(1.5, 1.0), 10.0)), "Abbe number"),
    (lambda s: s.__setitem__(0, Surface(50.0, 1e6, GLASS, 10.0)), "beyond any camera lens"),
    (lambda s: s.__setitem__(0, Surface(50.0, 5.0, GLASS, 10.0, "aspheric", conic=1e9)), "conic constant"),
    (lambda s: s.__setitem__(0, Surface(50.0, 5.0, GLASS, 10.0, "aspheric", aspheric=(1e300,))), "sag at the rim"),
])
def test_broken_lens_message(mutate, message):
    s = good()
    mutate(s)
    with pytest.raises(LensFileError, match=message):
        lens(*s).validate("lens.toml", lines=[3, 9, 15])


def test_error_names_file_and_line():
    s = good()
    s[1] = Surface(-50.0, -2.0, semi_diameter=10.0)
    with pytest.raises(LensFileError) as e:
        lens(*s).validate("lens.toml", lines=[3, 9, 15])
    assert e.value.path == "lens.toml" and e.value.line == 9
    assert str(e.value).startswith("lens.toml:9: ")


def test_focus_gap_must_be_air():
    f = Focus(1000.0, (VariableGap(0, 5.0, 6.0),))
    with pytest.raises(LensFileError, match="air gap"):
        lens(*good(), focus=f).validate()
    ok = Focus(1000.0, (VariableGap(1, 2.0, 3.0),))
    lens(*good(), focus=ok).validate()
