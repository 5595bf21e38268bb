import dataclasses

import pytest

from physcam.errors import ExportError, LensFileError
from physcam.lens.formats import dumps_lens, loads_lens, read_lens, write_lens
from physcam.lens.prescription import Prescription

from lens_reference import PBRT_FILES, REFERENCE

DGAUSS = REFERENCE / "pbrt-dat" / "dgauss.50mm.dat"


def test_dgauss_values_from_the_file():
    p = read_lens(DGAUSS)
    assert len(p.surfaces) == 11 and p.stop_index == 5
    s0 = p.surfaces[0]
    # Row 1 of the file: 29.475 3.76 1.67 25.2 (aperture is a diameter)
    assert (s0.radius, s0.thickness, s0.medium.nd, s0.semi_diameter) == (29.475, 3.76, 1.67, 12.6)
    assert p.surfaces[5].medium.is_air and p.surfaces[5].semi_diameter == 17.1 / 2
    assert all(s.medium.vd == 0.0 for s in p.surfaces)  # pbrt has no dispersion
    assert p.surfaces[-1].thickness == 0.0  # film distance not given
    assert p.name == "dgauss.50mm"
    assert "2,673,491" in p.metadata.notes


def test_fourth_column_is_a_diameter_by_the_files_own_geometry():
    # Read as semi-diameters, dgauss's surface 4 (radius 12.75, aperture 18) would not fit its sphere.
    p = read_lens(DGAUSS)
    doubled = p.with_surfaces(dataclasses.replace(s, semi_diameter=2 * s.semi_diameter) for s in p.surfaces)
    with pytest.raises(LensFileError, match="exceeds the radius"):
        doubled.validate()


@pytest.mark.parametrize("path", PBRT_FILES, ids=lambda p: p.name)
@pytest.mark.parametrize("via", ["pbrt", "physcam", "zemax"])
def test_round_trip(path, via):
    p = read_lens(path)
    q = loads_lens(dumps_lens(p, via), via, str(path))
    if via == "zemax":
        assert q.surfaces == p.surfaces
    else:
        assert q == p


def test_write_read_files(tmp_path):
    p = read_lens(DGAUSS)
    out = write_lens(p, tmp_path / "dgauss.50mm.dat")
    assert read_lens(out) == p
    with pytest.raises(ExportError, match="exists"):
        write_lens(p, out)
    write_lens(p, out, force=True)


def test_flat_surface_cannot_be_written():
    p = read_lens(DGAUSS)
    s = list(p.surfaces)
    s[-1] = dataclasses.replace(s[-1], radius=0.0, kind="flat")
    with pytest.raises(ExportError, match="pbrt"):
        dumps_lens(Prescription(tuple(s)), "pbrt")


@pytest.mark.parametrize(
    "text, line, match",
    [
        ("# c\n29.475 3.76 1.67\n", 2, "expected 4 numbers"),
        ("10 1 1.5 5\n0 1 0 4\n-10 x 1 5\n", 3, "thickness must be a number"),
        ("10 1 1.5 5\n0 1 0 4\n-10 nan 1 5\n", 3, "finite"),
        ("10 1 1.5 5\n-10 1 1 5\n", None, "no aperture stop"),
        ("", None, "no surfaces"),
    ],
)
def test_bad_files_name_the_line(text, line, match):
    with pytest.raises(LensFileError, match=match) as exc:
        loads_lens(text, "pbrt", "bad.dat")
    assert exc.value.path == "bad.dat" and exc.value.line == line
