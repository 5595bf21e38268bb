import json
from pathlib import Path

import pytest

from physcam.errors import InputError, LensFileError
from physcam.lens.formats import dumps_lens, loads_lens, read_lens
from physcam.lens.formats._common import extra
from physcam.lens.library import find_lens, list_lenses, load_lens
from physcam.lens.provenance import provenance_of

from lens_reference import ISET_FILES, PBRT_FILES, REFERENCE, SEED_FILES, SEED_INVALID
from patent_stated import PATENT_STATED
from primary_stated import PRIMARY

ALL_REFERENCE = PBRT_FILES + ISET_FILES + SEED_FILES


#: The Blender extension's copy of the pbrt double Gauss (the same prescription with Abbe numbers of its
#: own): dropped from the library in issue 44, its name an alias of dgauss_50mm.
DUPLICATE = "double_gauss_50mm_f2.toml"

#: The bundled zooms (issue 45, docs/zoom.md): built by scripts/build_zoom_lenses.py from their sources' tables.
ZOOMS = {"canon_ef_70_200mm_f2_8_zoom", "laikin_zoom_15_150mm", "nikon_af_s_70_200mm_f2_8e_zoom",
         "nikon_zoom_80_200mm_f2_8"}
#: Lenses entered from another project's transcription whose primary source was out of reach (issue 49:
#: the third anamorphic, a rear one; its checks are in tests/lens/test_anamorphic_library.py).
SECOND_HAND = ("panavision_rear_anamorphic_1_3x",)


def test_every_reference_file_is_bundled_once():
    recs = list_lenses()
    originals = sorted(r.original_file for r in recs if r.original_file)
    assert originals == sorted(f"{f.parent.name}/{f.name}" for f in ALL_REFERENCE if f.name != DUPLICATE)
    assert len({r.slug for r in recs}) == len(recs) == 18 + len(PATENT_STATED) + len(SECOND_HAND) + len(ZOOMS) + len(PRIMARY)
    assert find_lens(DUPLICATE).slug == find_lens("double_gauss_50mm_f2").slug == "dgauss_50mm"


@pytest.mark.parametrize("rec", list_lenses(), ids=lambda r: r.slug)
def test_bundled_lens_is_valid_and_round_trips(rec):
    p = load_lens(rec.slug)
    p.validate()
    assert loads_lens(dumps_lens(p, "physcam"), "physcam") == p
    assert rec.source and (rec.original_format in ("pbrt", "iset", "seed-toml") or rec.slug in PATENT_STATED
                           or rec.slug in SECOND_HAND or rec.slug in PRIMARY or (rec.slug in ZOOMS and p.zoom is not None))


def _numbers(p):
    """Each surface's geometry, nd and Vd: what a transcription is (a glass name added later is not)."""
    return [(s.kind, s.radius, s.thickness, s.semi_diameter, s.conic, s.aspheric, s.medium.nd, s.medium.vd)
            for s in p.surfaces]


@pytest.mark.parametrize("path", [f for f in ALL_REFERENCE if f.name not in SEED_INVALID], ids=lambda p: p.name)
def test_uncorrected_lenses_equal_their_original(path):
    rec = find_lens(path.name)
    assert not rec.corrected or path.suffix == ".json"  # the ISET copy corrects only its name
    bundled, original = _numbers(load_lens(rec.slug)), _numbers(read_lens(path))
    if path.name == DUPLICATE:  # the same radii, gaps, nd and apertures; the Abbe numbers are the copy's own
        bundled, original = [b[:-1] for b in bundled], [o[:-1] for o in original]
    assert bundled == original


@pytest.mark.parametrize("name", sorted(SEED_INVALID))
def test_corrected_lenses_say_what_and_why(name):
    rec = find_lens(name)
    assert rec.corrected
    notes = extra(load_lens(rec.slug), "provenance.corrections")
    assert notes and all(len(n) > 60 for n in notes)


def test_halved_apertures_match_the_published_surfaces():
    original = (REFERENCE / "physical-camera-toml" / "canon_rf_85mm_f1_2.toml").read_text()
    assert "aperture = 140.4" in original
    assert load_lens("canon_rf_85mm_f1_2").surfaces[0].semi_diameter == 140.4 / 4


def test_names_aliases_and_paths():
    assert find_lens("dgauss.50mm").slug == "dgauss_50mm"
    assert find_lens("Tessar 50mm f/2.8").slug == "tessar_50mm_f2_8"
    assert find_lens("dgauss.22deg.3.0mm").slug == "dgauss_77deg_3_5201mm"  # the ISET file's own name
    p = load_lens(REFERENCE / "pbrt-dat" / "telephoto.250mm.dat")
    assert p == read_lens(REFERENCE / "pbrt-dat" / "telephoto.250mm.dat")
    assert load_lens("navarro anamorphic 2x").is_anamorphic


def test_unknown_name_suggests_the_closest():
    with pytest.raises(InputError, match="did you mean .*tessar_50mm_f2_8"):
        load_lens("tesar 50")
    with pytest.raises(InputError, match="no such lens file"):
        load_lens("missing/lens.dat")


def test_a_slug_loads_the_lens_the_index_finds():
    # load_lens reads a bare slug's file directly (fast path): that must be the very lens the name
    # lookup gives, so no slug may also be another lens's name or alias
    from physcam.lens.library import _key

    recs = list_lenses()
    for rec in recs:
        assert find_lens(rec.slug).slug == rec.slug
        assert load_lens(rec.slug) is load_lens(rec.name)
        for other in recs:
            if other.slug != rec.slug:
                assert _key(rec.slug) not in {_key(other.name), *map(_key, other.aliases)}


# ---- provenance (issue 44) -------------------------------------------------------------------
ORACLE = json.loads((Path(__file__).resolve().parents[1] / "data" / "optiland_library.json").read_text())["lenses"]
OTHER_PROJECTS = ("Blender", "pbrt-v4-scenes", "isetlens", "Physical Camera")


@pytest.mark.parametrize("rec", list_lenses(), ids=lambda r: r.slug)
def test_every_bundled_lens_carries_a_provenance_record(rec):
    prov = provenance_of(load_lens(rec.slug))
    assert prov.source and not any(name in prov.source for name in OTHER_PROJECTS)  # the primary source
    assert prov.licence and rec.licence == prov.licence
    assert prov.transcribed and prov.checked and prov.transcribed_by and prov.checked_by
    assert isinstance(prov.primary_source_checked, bool) and prov.checks and prov.assumptions
    if not prov.primary_source_checked:  # where the numbers came from instead, and said to be unchecked
        assert prov.transcribed_from and "not" in prov.transcribed_from
        assert any(c.startswith("primary source: not reached") for c in prov.checks)
        assert prov.licence == "NOASSERTION"
    kinds = {a.split(":")[0] for a in prov.assumptions}
    assert {"stop", "semi-diameters"} <= kinds and any(k == "glass" for k in kinds)


@pytest.mark.parametrize("rec", list_lenses(), ids=lambda r: r.slug)
def test_bundled_efl_and_f_number_match_optiland(rec):
    from physcam.optics.paraxial import gaussian

    p = load_lens(rec.slug)
    for axis, want in ORACLE[rec.slug].items():  # optiland 0.6.3: scripts/optiland_library_oracle.py
        g = gaussian(p, axis=axis)
        assert g.efl == pytest.approx(want["efl_mm"], rel=1e-3)
        assert g.f_number == pytest.approx(want["f_number"], rel=1e-3)


def test_named_glasses_are_the_files_numbers_to_their_printed_digits():
    # a catalogue glass is named only where the file's nd and Vd, as printed, are that glass's
    from physcam.lens.catalog import find_glass

    named = 0
    for rec in list_lenses():
        for s in load_lens(rec.slug).surfaces:
            m = s.medium
            if m.glass:
                g = find_glass(m.glass, [m.catalog])
                assert abs(g.nd - m.nd) <= 5e-4 + 1e-9 and abs(g.vd - m.vd) <= 0.05 + 1e-9, (rec.slug, m)
                named += 1
    assert named >= 60


def test_lenses_and_lens_show_print_source_and_licence(capsys):
    from physcam.cli import main

    assert main(["lenses"]) == 0
    out = capsys.readouterr().out
    header = next(line for line in out.splitlines() if line.startswith("name"))
    assert "source" in header and "licence" in header
    row = next(line for line in out.splitlines() if line.startswith("tessar_50mm_f2_8 "))
    assert "US 4,213,674 (Olympus, 1980), embodiment 1" in row and "NOASSERTION" in row
    assert main(["lens", "show", "--lens", "tessar_50mm_f2_8"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("Tessar 50mm f/2.8  (wavelength 587.562 nm")
    assert lines[1] == "source: US 4,213,674 (Olympus, 1980), embodiment 1; numbers not checked against it"
    assert lines[2] == "licence: NOASSERTION"
    assert main(["lens", "show", "--lens", "tessar_50mm_f2_8", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["provenance"]["source"] == "US 4,213,674 (Olympus, 1980), embodiment 1"
    assert doc["provenance"]["primary_source_checked"] is False


def test_lens_check_says_what_the_provenance_record_says():
    from physcam.lens.check import check

    notes = {f.code: f for f in check("tessar_50mm_f2_8") if f.severity == "note"}
    assert "US 4,213,674" in notes["provenance_unchecked"].message
    assert "Blender" in notes["provenance_unchecked"].implication
    assert "NOASSERTION" in notes["licence_unresolved"].message
    assert not {"provenance_unchecked", "licence_unresolved"} & {f.code for f in check(REFERENCE / "pbrt-dat" / "dgauss.50mm.dat")}


def test_a_file_named_as_no_lens_of_the_library_is_read(tmp_path, monkeypatch):
    """A lens file in the current folder, named without ./ and without a lens-file extension (a vendor's
    ``lens file.txt``), was refused with "no bundled lens called 'lens file.txt'" though the file was right there.
    Where no lens of the library has the name, the file of that name is read; a library name still wins."""
    from physcam.lens.library import library_dir

    monkeypatch.chdir(tmp_path)
    (tmp_path / "lens file.txt").write_bytes((library_dir() / "tessar_50mm_f2_8.toml").read_bytes())
    assert load_lens("lens file.txt").surfaces == load_lens("tessar_50mm_f2_8").surfaces
    (tmp_path / "Tessar 50mm f-2.8").write_text("not a lens")  # a lens's name as a file here: the library's lens
    assert find_lens("Tessar 50mm f-2.8").slug == "tessar_50mm_f2_8"
    assert load_lens("Tessar 50mm f-2.8").surfaces == load_lens("tessar_50mm_f2_8").surfaces
    with pytest.raises(InputError, match="no bundled lens called 'no_such'"):
        load_lens("no_such")


def test_a_lens_archive_given_as_a_lens_file_says_how_to_install_it(tmp_path):
    import zipfile

    archive = tmp_path / "my lens.lens.zip"
    with zipfile.ZipFile(archive, "w") as z:
        z.writestr("lens.toml", "x")
    with pytest.raises(LensFileError, match=r"a zip archive, not a lens file: .*`physcam lens add '.*my lens\.lens\.zip'`"):
        load_lens(archive)
