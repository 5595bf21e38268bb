from contextlib import nullcontext

import pytest

from physcam.errors import ExportError, LensFileError, PhysCamWarning
from physcam.lens.catalog import find_glass
from physcam.lens.formats import dumps_lens, loads_lens
from physcam.lens.library import load_lens

SINGLET = """VERS 190513 80 123457
MODE SUDA
NAME test singlet
UNIT MM X W X CM MR CPMM
SURF 0
  TYPE STANDARD
  CURV 0.0
  DISZ INFINITY
SURF 1
  STOP
  TYPE STANDARD
  CURV 0.0
  DISZ 2.0
  DIAM 4.0 1 0 0 1 ""
SURF 2
  TYPE STANDARD
  CURV 0.01 0 0 0 0 ""
  DISZ 5.0
  GLAS N-BK7 0 0 1.5168 64.17 0 0 0 0 0 0
  DIAM 10.0 1 0 0 1 ""
SURF 3
  TYPE EVENASPH
  CURV -0.02
  CONI -1.5
  PARM 1 0
  PARM 2 1e-6
  PARM 3 -2e-9
  DISZ 90.0
  DIAM 10.0 1 0 0 1 ""
SURF 4
  TYPE STANDARD
  CURV 0.0
  DISZ 0.0
"""


def test_reads_standard_and_even_asphere():
    p = loads_lens(SINGLET, "zemax", "s.zmx")
    assert p.name == "test singlet" and p.stop_index == 0
    a, b = p.surfaces[1], p.surfaces[2]
    assert a.radius == 100.0 and a.semi_diameter == 10.0  # CURV 0.01 -> R 100; DIAM is the semi-diameter
    g = find_glass("N-BK7")
    assert (a.medium.nd, a.medium.vd, a.medium.glass) == (1.5168, 64.17, "N-BK7") == (g.nd, g.vd, g.name)
    assert (b.kind, b.radius, b.conic, b.aspheric) == ("aspheric", -50.0, -1.5, (1e-6, -2e-9))
    assert b.thickness == 90.0 and b.medium.is_air
    assert loads_lens(dumps_lens(p, "zemax"), "zemax") .surfaces == p.surfaces


def test_model_glass():
    text = SINGLET.replace("GLAS N-BK7 0 0 1.5168 64.17", "GLAS ___BLANK 1 0 1.7 30.5")
    s = loads_lens(text, "zemax").surfaces[1]
    assert (s.medium.nd, s.medium.vd, s.medium.glass) == (1.7, 30.5, None)


@pytest.mark.parametrize(
    "old, new, line, match",
    [
        ("TYPE EVENASPH", "TYPE TOROIDAL", 22, "TOROIDAL is not supported"),
        ("GLAS N-BK7 0 0 1.5168 64.17", "GLAS UNOBTAINIUM 0 0 0 0", 19, "unknown glass 'UNOBTAINIUM'"),
        ("GLAS N-BK7", "GLAS MIRROR", 19, "MIRROR"),
        ("UNIT MM", "UNIT IN", 4, "UNIT MM"),
        ("PARM 1 0", "PARM 1 0.5", 25, "PARM 1"),
        ("CURV 0.01", "CURV zz", 17, "CURV must be a number"),
        ("  STOP\n", "", None, "no aperture stop"),
    ],
)
def test_refuses_clearly(old, new, line, match):
    with pytest.raises(LensFileError, match=match) as exc:
        loads_lens(SINGLET.replace(old, new, 1), "zemax", "s.zmx")
    assert exc.value.line == line and exc.value.path == "s.zmx"


def test_stop_on_a_lens_face_becomes_a_flat_stop_at_its_vertex():
    # issue 25: most real files put STOP on a lens face; it was refused
    text = SINGLET.replace("  STOP\n", "").replace("SURF 2\n", "SURF 2\n  STOP\n")
    p = loads_lens(text, "zemax")
    stop, face = p.surfaces[1], p.surfaces[2]
    assert (stop.kind, stop.radius, stop.thickness, stop.semi_diameter) == ("stop", 0.0, 0.0, 10.0)
    assert stop.medium.is_air and face.radius == 100.0 and p.stop_index == 1
    assert p.surfaces[0].kind == "flat"


@pytest.mark.parametrize("name", ["canon_rf_85mm_f1_2", "dgauss_50mm", "zeiss_planar_80mm_f2_8"])
def test_bundled_lenses_round_trip_through_zemax(name):
    p = load_lens(name)
    with pytest.warns(Warning) if p.focus else _nullcontext():
        text = dumps_lens(p, "zemax")
    q = loads_lens(text, "zemax")
    shape = lambda s: (s.kind, s.radius, s.thickness, s.semi_diameter, s.conic, s.aspheric)  # noqa: E731
    assert [shape(s) for s in q.surfaces] == [shape(s) for s in p.surfaces]
    for a, b in zip(q.surfaces, p.surfaces):
        # the writer keeps the file's nd and Vd: a glass whose numbers are its catalogue's is written by name
        # (GLAS N-BK7), else as a model glass of the file's numbers (the name is dropped), e.g. the patent's
        # rounded 1.618 / 63.4 for N-PSK53A's 1.61800 / 63.39
        assert (a.medium.nd, a.medium.vd) == (b.medium.nd, b.medium.vd)
        g = find_glass(b.medium.glass, [b.medium.catalog]) if b.medium.glass else None
        named = g is not None and (g.nd, g.vd) == (b.medium.nd, b.medium.vd)
        assert a.medium.glass == (b.medium.glass if named else None)


def test_anamorphic_refused():
    with pytest.raises(ExportError, match="cylindrical"):
        dumps_lens(load_lens("navarro_anamorphic_2x"), "zemax")


class _nullcontext:
    def __enter__(self):
        return self

    def __exit__(self, *a):
        return False


def test_catalogue_glass_numbers_on_the_line_are_placeholders():
    # issue 25 item 2: OpticStudio ignores nd/Vd on a catalogue glass's GLAS line; N-BK7 is
    # nd 1.51680, Vd 64.17 (SCHOTT data sheet), whatever the line says
    text = SINGLET.replace("GLAS N-BK7 0 0 1.5168 64.17", "GLAS N-BK7 0 0 1.5 40")
    m = loads_lens(text, "zemax", path="bk7.zmx").surfaces[1].medium  # surface 0 is the stop
    assert (m.nd, m.vd, m.glass, m.catalog) == (1.5168, 64.17, "N-BK7", "SCHOTT")


def test_windows_code_page_file_is_read(tmp_path):
    # OpticStudio's "ANSI" files are cp1252: a degree sign in a NOTE must not refuse the file
    f = tmp_path / "ansi.zmx"
    f.write_bytes(SINGLET.replace("UNIT MM", "NOTE 0 field 20\xb0 edge\nUNIT MM").encode("cp1252"))
    from physcam.lens.formats import read_lens

    assert read_lens(f).surfaces[1].medium.nd == 1.5168


def test_writer_says_sequential_mode():
    assert "MODE SEQ" in dumps_lens(loads_lens(SINGLET, "zemax", path="s.zmx"), "zemax").splitlines()[:3]


@pytest.mark.parametrize("slug", ["dgauss_50mm", "zeiss_distagon_35mm_f4", "canon_rf_85mm_f1_2"])
def test_a_truncated_file_is_an_error_never_another_lens(slug):
    """Issue 8.8: a .zmx cut anywhere (mid-surface, or before the image surface) loaded as a
    different lens (EFL -53 mm). Cut a real lens's file after every line: each cut either
    raises LensFileError or, when only lines after the image surface's data were lost, reads
    back the very same surfaces."""
    lens = load_lens(slug)
    moving = slug == "canon_rf_85mm_f1_2"  # a .zmx holds one focus: the writer says it drops the groups
    with pytest.warns(PhysCamWarning, match="drops the focus groups") if moving else nullcontext():
        text = dumps_lens(lens, "zemax")
    whole = loads_lens(text, "zemax").surfaces
    lines = text.splitlines(keepends=True)
    first_surf = next(i for i, ln in enumerate(lines) if ln.startswith("SURF"))
    for cut in range(first_surf + 1, len(lines)):
        part = "".join(lines[:cut])
        try:
            got = loads_lens(part, "zemax", "cut.zmx").surfaces
        except LensFileError:
            continue
        assert got == whole, f"cut after line {cut} ({lines[cut - 1].strip()!r}) loads as another lens"


def test_a_hand_written_block_without_curv_is_not_called_truncated():
    """A lens vendor's hand-written .zmx with the stop's CURV left out was told "the file seems cut short
    (truncated)" although three surfaces followed it (round 8); it is told what the block lacks."""
    text = ("SURF 0\n  CURV 0\n  DISZ INFINITY\nSURF 1\n  STOP\n  DIAM 5\n  DISZ 10\n"
            "SURF 2\n  CURV 0.02\n  DISZ 5\n  GLAS N-BK7\n  DIAM 10\nSURF 3\n  CURV -0.02\n  DISZ 45\n  DIAM 10\n"
            "SURF 4\n  CURV 0\n  DISZ 0\n")
    with pytest.raises(LensFileError, match=r"SURF 1 has no CURV line: every SURF block needs both") as err:
        loads_lens(text, "zemax", path="hand.zmx")
    assert "truncated" not in str(err.value) and err.value.line == 4
    assert loads_lens(text.replace("  STOP\n", "  STOP\n  CURV 0\n"), "zemax").stop_index == 0  # SURF 1, the first surface after the object
