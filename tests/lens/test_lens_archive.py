"""Lens archives (issue 44): `physcam lens pack` writes one, `lens check` validates it, `lens add` installs
it into the user's lens library, where the lens then loads by name."""

from __future__ import annotations

import hashlib
import io
import json
import zipfile
from pathlib import Path

import pytest

from _documents import check_document
from physcam.cli import main
from physcam.lens.formats import read_lens
from physcam.lens.library import library_dir, list_lenses, load_lens, user_library_dir
from physcam.usd.lens_archive import MEMBERS, check_archive

#: A vendor's lens: the bundled Tessar's numbers under the vendor's own name and provenance.
VENDOR_TOML_HEAD = '''format = "physcam-lens/1"
[lens]
name = "Beloved Lens Co. 50mm T3"
maker = "Beloved Lens Co."
focal_length = 50.0
max_fstop = 2.8
t_stop = 3.0
minimum_object_distance = 450.0
[provenance]
source = "Beloved Lens Co. design BL-50, revision C (the maker's own prescription)"
licence = "CC-BY-4.0"
transcribed = "2026-11-28"
transcribed_from = "the maker's design file"
primary_source_checked = true
checks = ["EFL 50.00 mm and f/2.80 against the design file's first-order data"]
'''
RUNS_CSV = "variant,efl_mm,t_stop,bench\nrun_20260301,50.04,3.02,MTF bench 2\nrun_20260415,50.03,3.01,MTF bench 2\n"


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def _vendor_lens(folder: Path) -> Path:
    """The vendor lens file: its header and the surfaces of the bundled Tessar."""
    tessar = (library_dir() / "tessar_50mm_f2_8.toml").read_text()
    f = folder / "beloved_50.toml"
    f.write_text(VENDOR_TOML_HEAD + tessar[tessar.index("[[surface]]"):])
    return f


@pytest.fixture(scope="module")
def packed(tmp_path_factory):
    """(lens file, archive, the pack command's JSON): packed once for the module (a draft card)."""
    import contextlib

    d = tmp_path_factory.mktemp("pack")
    lens = _vendor_lens(d)
    (d / "runs.csv").write_text(RUNS_CSV)
    archive = d / "beloved_50.lens.zip"
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        rc = main(["lens", "pack", "--lens", str(lens), "--focus", "2m", "--draft", "--characterizations",
                   str(d / "runs.csv"), "-o", str(archive), "--json"])
    assert rc == 0
    return lens, archive, json.loads(out.getvalue())


@pytest.fixture
def library(tmp_path, monkeypatch):
    folder = tmp_path / "my-lenses"
    monkeypatch.setenv("PHYSCAM_LENS_LIBRARY", str(folder))
    return folder


def test_pack_writes_every_member_with_its_checksum(packed):
    _, archive, doc = packed
    assert check_document(doc) == "physcam.lens_pack"
    assert doc["slug"] == "beloved_lens_co_50mm_t3" and doc["characterizations"] == ["run_20260301", "run_20260415"]
    with zipfile.ZipFile(archive) as z:
        assert sorted(z.namelist()) == sorted(MEMBERS)
        for name, want in doc["files"].items():  # hashlib on the bytes the archive holds
            data = z.read(name)
            assert want == {"size": len(data), "sha256": hashlib.sha256(data).hexdigest()}
        assert z.read("card.pdf").startswith(b"%PDF-")
        prov = json.loads(z.read("provenance.json"))
    assert prov["source"].startswith("Beloved Lens Co. design BL-50") and prov["licence"] == "CC-BY-4.0"
    assert prov["primary_source_checked"] is True


def test_archive_round_trips_through_check_and_add(packed, library, capsys):
    lens, archive, _ = packed
    rc, out, _ = run(capsys, "lens", "check", "--lens", str(archive), "--json")
    doc = json.loads(out)
    assert rc == 0 and doc["counts"]["error"] == 0 and check_document(doc)
    rc, out, _ = run(capsys, "lens", "add", str(archive), "--json")
    doc = json.loads(out)
    assert rc == 0 and check_document(doc) == "physcam.lens_add"
    assert Path(doc["folder"]) == library / "beloved_lens_co_50mm_t3" == user_library_dir() / doc["slug"]
    installed = load_lens("beloved_lens_co_50mm_t3")
    assert installed == read_lens(lens)  # the prescription, its metadata and provenance, unchanged
    assert load_lens("Beloved Lens Co. 50mm T3") is installed
    assert installed.metadata.t_stop == 3.0 and installed.metadata.minimum_object_distance == 450.0
    rec, = list_lenses("user")
    assert (rec.slug, rec.library, rec.licence) == ("beloved_lens_co_50mm_t3", "user", "CC-BY-4.0")
    assert len(list_lenses()) == len(list_lenses("bundled")) + 1


def test_installed_usd_holds_the_prescription_pinhole_and_characterizations(packed, library, capsys):
    from physcam.usd.kit import read_characterizations
    from physcam.usd.read import composed_prescription, open_stage

    lens, archive, _ = packed
    assert run(capsys, "lens", "add", str(archive))[0] == 0
    usd = user_library_dir() / "beloved_lens_co_50mm_t3" / "lens.usda"
    stage = open_stage(usd)
    rx, toml = composed_prescription(stage, "/Lens"), read_lens(lens)
    assert [(s.radius, s.thickness, s.semi_diameter, s.medium.nd, s.medium.vd, s.medium.glass) for s in rx.surfaces] == \
        [(s.radius, s.thickness, s.semi_diameter, s.medium.nd, s.medium.vd, s.medium.glass) for s in toml.surfaces]
    lens_prim = stage.GetPrimAtPath("/Lens")
    assert set(lens_prim.GetVariantSets().GetNames()) == {"lensModel", "characterization"}
    assert stage.GetPrimAtPath("/Lens/Pinhole").IsValid()
    runs = read_characterizations(usd)
    assert runs["current_is"] == "run_20260415" and runs["selection"] == "current"
    assert runs["variants"]["run_20260301"] == {"efl_mm": [50.04], "t_stop": [3.02], "bench": "MTF bench 2"}
    assert runs["variants"]["current"] == runs["variants"]["run_20260415"]


def test_add_refuses_a_second_install_without_force(packed, library, capsys):
    _, archive, _ = packed
    assert run(capsys, "lens", "add", str(archive))[0] == 0
    rc, _, err = run(capsys, "lens", "add", str(archive))
    assert rc == 2 and "installed already" in err and "--force" in err and len(err.strip().splitlines()) == 1
    assert run(capsys, "lens", "add", str(archive), "--force")[0] == 0


def _rezipped(archive: Path, out: Path, change) -> Path:
    with zipfile.ZipFile(archive) as z:
        files = {n: z.read(n) for n in z.namelist()}
    change(files)
    with zipfile.ZipFile(out, "w") as z:
        for n, data in files.items():
            z.writestr(n, data)
    return out


def test_a_changed_member_fails_the_check_and_is_not_installed(packed, library, tmp_path, capsys):
    _, archive, _ = packed

    def edit(files):
        files["lens.toml"] = files["lens.toml"].replace(b"thickness = 5.", b"thickness = 6.", 1)

    bad = _rezipped(archive, tmp_path / "bad.lens.zip", edit)
    codes = {f.code for f in check_archive(bad) if f.severity == "error"}
    assert {"archive_checksum", "usd_prescription_differs"} <= codes
    rc, _, err = run(capsys, "lens", "add", str(bad))
    assert rc == 2 and "not installed" in err and len(err.strip().splitlines()) == 1
    assert not library.exists() or not any(library.iterdir())


def test_provenance_must_agree_and_name_source_and_licence(packed, tmp_path):
    _, archive, _ = packed

    def drop_licence(files):
        files["lens.toml"] = files["lens.toml"].replace(b'licence = "CC-BY-4.0"\n', b"")

    codes = {f.code for f in check_archive(_rezipped(archive, tmp_path / "a.lens.zip", drop_licence))}
    assert {"provenance_missing", "provenance_differs"} <= codes


def test_pack_refuses_a_lens_without_source_or_licence(tmp_path, capsys):
    f = tmp_path / "anon.toml"
    f.write_text(_vendor_lens(tmp_path).read_text().replace('licence = "CC-BY-4.0"\n', ""))
    rc, _, err = run(capsys, "lens", "pack", "--lens", str(f), "--draft", "-o", str(tmp_path / "a.lens.zip"))
    assert rc == 2 and "no licence" in err and not (tmp_path / "a.lens.zip").exists()


def test_add_refuses_the_name_of_a_bundled_lens(packed, library, tmp_path, capsys):
    _, archive, _ = packed

    def rename(files):  # a consistent archive, except that the lens takes a bundled lens's name
        toml = files["lens.toml"].replace(b"Beloved Lens Co. 50mm T3", b"Tessar 50mm f/2.8")
        files["lens.toml"] = toml
        m = json.loads(files["manifest.json"])
        m["files"]["lens.toml"] = {"size": len(toml), "sha256": hashlib.sha256(toml).hexdigest()}
        files["manifest.json"] = json.dumps(m).encode()

    rc, _, err = run(capsys, "lens", "add", str(_rezipped(archive, tmp_path / "t.lens.zip", rename)))
    assert rc == 2 and "tessar_50mm_f2_8" in err


@pytest.mark.parametrize("content, what", [
    (b"not a zip at all", "not a readable lens archive"),
    (None, "is not a member of a lens archive"),
])
def test_what_is_not_a_lens_archive_is_refused_in_one_line(tmp_path, capsys, content, what):
    f = tmp_path / "x.lens.zip"
    if content is None:
        with zipfile.ZipFile(f, "w") as z:
            z.writestr("../evil.txt", b"x")
    else:
        f.write_bytes(content)
    rc, _, err = run(capsys, "lens", "check", "--lens", str(f))
    assert rc == 2 and what in err and len(err.strip().splitlines()) == 1


def test_user_library_is_the_xdg_data_folder(monkeypatch, tmp_path):
    monkeypatch.delenv("PHYSCAM_LENS_LIBRARY")
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    assert user_library_dir() == tmp_path / "data" / "physcam" / "lenses"
    monkeypatch.delenv("XDG_DATA_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert user_library_dir() == tmp_path / "home" / ".local" / "share" / "physcam" / "lenses"


def test_characterization_rows_by_date_or_variant(tmp_path):
    from physcam.cli.lens import _read_runs
    from physcam.errors import LensFileError

    f = tmp_path / "runs.csv"
    f.write_text("date,efl_mm,note\n2026-03-01,50.04,first\n")
    assert _read_runs(f) == {"d2026_03_01": {"efl_mm": 50.04, "note": "first"}}
    f.write_text("variant,efl mm\nrun_1,50.0\n")
    with pytest.raises(LensFileError, match="letters, digits and underscores"):
        _read_runs(f)
    f.write_text("variant,efl_mm\n,50.0\n")
    with pytest.raises(LensFileError, match="without a variant"):
        _read_runs(f)
