"""Everyday use (issue 15) through the real CLI: sensors filtered, the one default sensor said, the user
config, values read back as written, renamed options, clamped analyses, lenses compared."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import pytest

from physcam.cli import main

pytestmark = pytest.mark.slow
DATA = Path(__file__).resolve().parents[2] / "src" / "physcam" / "data" / "sensors.csv"


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def one_line_error(rc, err):
    assert rc == 2 and "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("physcam: error:"), err
    return lines[0]


# ---- sensors -----------------------------------------------------------------------------------
def test_sensors_filter_by_maker_format_and_width(capsys):
    table = list(csv.DictReader(DATA.read_text().splitlines()))
    table += [{**r, "name": f"{r['maker']} {r['camera']} {r['format']}", "kind": "digital"}  # the camera table
              for r in csv.DictReader(DATA.with_name("cameras.csv").read_text().splitlines())]
    arri = {r["key"] for r in table if r["name"].startswith("ARRI ")}
    rc, out, _ = run(capsys, "sensors", "ARRI", "--json")
    assert rc == 0 and {s["key"] for s in json.loads(out)["sensors"]} == arri
    rc, out, _ = run(capsys, "sensors", "--maker", "film", "--min-width", "30", "--json")
    got = json.loads(out)["sensors"]
    assert got and all(s["kind"] == "film" and s["width_mm"] >= 30 for s in got)
    assert {s["key"] for s in got} == {r["key"] for r in table if r["kind"] == "film" and float(r["width_mm"]) >= 30}
    rc, out, _ = run(capsys, "sensors", "ALEXA", "--format", "16:9", "--json")
    assert {s["key"] for s in json.loads(out)["sensors"]} == {r["key"] for r in table if "ALEXA" in r["name"]
                                                              and "16:9" in r["name"]}
    rc, out, _ = run(capsys, "sensors", "Mini LF", "--json")  # an alias: that one sensor
    assert [s["key"] for s in json.loads(out)["sensors"]] == ["alexa-lf-og"]
    rc, _, err = run(capsys, "sensors", "--maker", "Nikon")
    assert "no sensor matches" in one_line_error(rc, err)


# ---- one default sensor ------------------------------------------------------------------------
def test_the_default_sensor_is_super_35_and_said(capsys):
    rc, out, err = run(capsys, "illumination", "dgauss_50mm", "--grid", "16", "--json")
    assert rc == 0 and json.loads(out)["sensor"].startswith("Super 35")
    assert "physcam: note: no --sensor given: Super 35" in err
    rc, out, _ = run(capsys, "report", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--json")
    d = json.loads(out)
    assert d["sensor"]["key"] == "s35-4perf" and any("no --sensor given" in n for n in d["notes"])
    rc, out, _ = run(capsys, "lens", "breathing", "dgauss_50mm", "--focus", "inf", "--json")
    assert json.loads(out)["sensor_width_mm"] == pytest.approx(24.89)
    # a refusal stays one line: no note before it
    rc, _, err = run(capsys, "illumination", "no_such_lens")
    one_line_error(rc, err)


def test_the_exports_say_the_default_sensor_too(capsys, tmp_path):
    # found by a review: export rib and mitsuba used Super 35 without a word (the report kept the note)
    for args in (("rib", "-o", str(tmp_path / "cam.rib")), ("mitsuba", "-o", str(tmp_path / "mts"))):
        rc, _, err = run(capsys, "export", *args, "--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "4")
        assert rc == 0 and "physcam: note: no --sensor given: Super 35" in err, args
        rc, _, err = run(capsys, "export", *args, "--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "4",
                         "--sensor", "ALEXA 35", "--force")
        assert rc == 0 and "no --sensor given" not in err, args


# ---- the user config ---------------------------------------------------------------------------
def test_user_config_sets_sensor_units_coc_and_output_folder(capsys, tmp_path, monkeypatch):
    out_dir = tmp_path / "shots"
    out_dir.mkdir()
    cfg = tmp_path / "config.toml"
    cfg.write_text(f'sensor = "ALEXA 35"\nunits = "ft"\ncoc = "cine"\noutput_dir = "{out_dir}"\n')
    monkeypatch.setenv("PHYSCAM_CONFIG", str(cfg))
    monkeypatch.chdir(tmp_path)
    rc, out, _ = run(capsys, "report", "--focal", "50", "--fstop", "2.8", "--focus", "10ft", "--json")
    d = json.loads(out)
    assert d["sensor"]["key"] == "alexa35-og" and d["coc_convention"] == "cine"
    rc, out, _ = run(capsys, "report", "--focal", "50", "--fstop", "2.8", "--focus", "10ft", "--plot", "dof.png")
    assert rc == 0 and (out_dir / "dof.png").is_file() and not (tmp_path / "dof.png").exists()
    assert "9' " in out  # near limit in feet and inches
    rc, out, _ = run(capsys, "report", "--focal", "50", "--fstop", "2.8", "--focus", "10ft", "--units", "m",
                     "--sensor", "S35")  # the command line wins
    assert "Super 35" in out and " m " in out
    rc, out, _ = run(capsys, "config", "show", "--json")
    s = json.loads(out)["settings"]
    assert s["sensor"] == {"value": "ALEXA 35", "source": str(cfg)} and s["units"]["value"] == "ft"
    cfg.write_text('sensr = "ALEXA 35"\n')
    rc, _, err = run(capsys, "report", "--focal", "50", "--fstop", "2.8", "--focus", "3m")
    assert "unknown key(s) sensr" in one_line_error(rc, err)
    cfg.write_text('units = "yards"\n')
    rc, _, err = run(capsys, "config", "show")
    assert "units must be one of m, ft" in one_line_error(rc, err)


def test_a_config_that_is_not_there_or_not_a_file_is_refused(capsys, tmp_path, monkeypatch):
    """PHYSCAM_CONFIG naming a file that is not there (a typo, another machine's path) or a folder was
    passed over for physcam's defaults without a word (a review found `config show` saying "not there"
    of an existing folder); each is now one line naming it. Unset or empty still means defaults."""
    monkeypatch.setenv("PHYSCAM_CONFIG", str(tmp_path / "typo.toml"))
    rc, _, err = run(capsys, "report", "--focal", "50", "--fstop", "2.8", "--focus", "3m")
    assert f"PHYSCAM_CONFIG names {tmp_path / 'typo.toml'}, which is not there" in one_line_error(rc, err)
    monkeypatch.setenv("PHYSCAM_CONFIG", str(tmp_path))
    rc, _, err = run(capsys, "config", "show")
    assert f"the physcam config {tmp_path} is a folder" in one_line_error(rc, err)
    monkeypatch.setenv("PHYSCAM_CONFIG", "")
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "nothing-here"))
    rc, out, _ = run(capsys, "config", "show", "--json")
    assert rc == 0 and all(v["source"] == "default" for v in json.loads(out)["settings"].values())
    monkeypatch.delenv("PHYSCAM_CONFIG")
    rc, out, _ = run(capsys, "config", "show", "--json")  # the default place, not there: the defaults
    assert rc == 0 and json.loads(out)["path"] == str(tmp_path / "nothing-here" / "physcam" / "config.toml")
    (tmp_path / "nothing-here" / "physcam" / "config.toml").mkdir(parents=True)
    rc, _, err = run(capsys, "config", "show")
    assert "config.toml is a folder" in one_line_error(rc, err)


def test_tests_read_no_user_config(capsys):
    rc, out, _ = run(capsys, "config", "show", "--json")
    d = json.loads(out)
    assert all(v["source"] == "default" for v in d["settings"].values())


# ---- USD values as written ---------------------------------------------------------------------
def test_usd_read_prints_values_as_written(capsys, tmp_path):
    f = tmp_path / "shot.usda"
    assert main(["usd", "write", str(f), "--focal", "35", "--fstop", "2.8", "--focus", "10ft", "--sensor",
                 "ALEXA 35"]) == 0
    capsys.readouterr()
    rc, out, _ = run(capsys, "usd", "read", str(f), "--json")
    cam = json.loads(out)["usd"]["camera"]
    assert (cam["fstop"], cam["focal_length_mm"], cam["focus_mm"]) == (2.8, 35.0, 3048.0)
    assert (cam["sensor_width_mm"], cam["sensor_height_mm"]) == (27.99, 19.22)
    report = json.loads(out)["report"]
    assert report["coc_convention"] == "d/1500" and report["fstop"] == 2.8
    f2 = tmp_path / "cine.usda"
    assert main(["usd", "write", str(f2), "--focal", "35", "--fstop", "2.8", "--focus", "3m", "--coc", "cine"]) == 0
    capsys.readouterr()
    rc, out, _ = run(capsys, "usd", "read", str(f2), "--json")
    d = json.loads(out)
    assert d["usd"]["camera"]["coc_mm"] == 0.025 and d["report"]["coc_convention"] == "cine"


def test_usd_refuses_a_focus_at_infinity_with_the_way_forward(capsys, tmp_path):
    rc, _, err = run(capsys, "usd", "write", str(tmp_path / "a.usda"), "--focal", "35", "--fstop", "2.8", "--focus",
                     "infinity")
    assert "focus distance is finite" in one_line_error(rc, err)
    rc, _, _ = run(capsys, "usd", "write", str(tmp_path / "b.usda"), "--focal", "35", "--fstop", "2.8", "--focus",
                   "hyperfocal")
    assert rc == 0


# ---- renamed options keep working, unlisted ----------------------------------------------------
@pytest.mark.parametrize("new, old", [
    (["breathing-real", "dgauss_50mm", "--focus", "2m", "--focus-method", "unit"],
     ["breathing-real", "dgauss_50mm", "--focus", "2m", "--method", "unit"]),
    (["bokeh", "dgauss_50mm", "--light", "1.5m", "--rays", "3000", "--pixels", "16"],
     ["bokeh", "dgauss_50mm", "--depth", "1.5m", "--rays", "3000", "--pixels", "16"]),
    (["lens", "breathing", "dgauss_50mm", "--focus", "1m", "3m"], ["lens", "breathing", "dgauss_50mm", "--at", "1m", "3m"]),
])
def test_old_spellings_are_hidden_aliases(capsys, new, old):
    rc, a, _ = run(capsys, *new, "--json")
    rc2, b, _ = run(capsys, *old, "--json")
    assert rc == rc2 == 0 and json.loads(a) == json.loads(b)
    rc, helptext, _ = run(capsys, *new[:2] if new[0] == "lens" else new[:1], "--help")
    hidden = next(o for o in old if o.startswith("--") and o not in new)
    assert hidden not in helptext


# ---- analyses clamp with a note ----------------------------------------------------------------
@pytest.mark.parametrize("argv, says", [
    (["illumination", "navarro_anamorphic_2x", "--grid", "32"], "fields clamped to"),
    (["colour", "dgauss_77deg_3_5201mm"], "fields clamped to"),
    (["ghosts", "navarro_anamorphic_2x", "--top", "2"], "the widest field the lens lets through"),
])
def test_analyses_clamp_their_default_range_with_a_note(capsys, argv, says):
    rc, out, _ = run(capsys, *argv, "--sensor", "FF", "--json")
    assert rc == 0
    d = json.loads(out)
    assert any(says in n for n in d["notes"]), d["notes"]
    fields = [p["field_deg"] for p in d.get("points", d.get("lateral", []))] or [d["field_deg"]]
    import re

    limit = float(re.search(r"(?:clamped to|light is at) ([\d.]+) deg", " ".join(d["notes"])).group(1))
    assert max(fields) == pytest.approx(limit, abs=0.006)


def test_explicit_fields_beyond_the_lens_are_still_refused(capsys):
    rc, _, err = run(capsys, "illumination", "dgauss_77deg_3_5201mm", "--field", "0", "--field", "40", "--sensor", "FF")
    assert "choose a smaller field" in one_line_error(rc, err)


# ---- compare -----------------------------------------------------------------------------------
def test_compare_lenses_side_by_side(capsys, tmp_path):
    rc, out, _ = run(capsys, "compare", "dgauss_50mm", "tessar_50mm_f2_8", "--focus", "2m", "--fstop", "4",
                     "--rays", "20000", "--json")
    assert rc == 0
    a, b = json.loads(out)["lenses"]
    # the depth of field and fields of view are the lens report's
    r = json.loads(run(capsys, "report", "--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "4", "--json")[1])
    assert a["near_from_film_mm"] == r["dof"]["near_from_film_mm"] and a["hfov_deg"] == r["fov_deg"]["focus"]["horizontal"]
    assert a["fstop"] == b["fstop"] == 4.0
    # the bokeh of a far light shrinks with the aperture diameter (blur ~ f^2 / N): f/8 gives half f/4's
    rc, out8, _ = run(capsys, "compare", "dgauss_50mm", "--focus", "2m", "--fstop", "8", "--rays", "20000", "--json")
    c = json.loads(out8)["lenses"][0]
    assert c["bokeh_diameter_mm"] / a["bokeh_diameter_mm"] == pytest.approx(0.5, rel=0.08)
    # a lens slower than asked is compared wide open, with a note
    rc, out, _ = run(capsys, "compare", "tessar_50mm_f2_8", "--fstop", "1.4", "--rays", "2000", "--json")
    t = json.loads(out)["lenses"][0]
    assert t["fstop"] == pytest.approx(2.8, rel=0.01) and any("compared wide open" in n for n in t["notes"])
    fig = tmp_path / "cmp.png"
    rc, out, _ = run(capsys, "compare", "dgauss_50mm", "tessar_50mm_f2_8", "--rays", "2000", "-o", str(fig),
                     "--units", "ft")
    assert rc == 0 and fig.read_bytes()[:4] == b"\x89PNG" and "6' 6 3/4\"" in out  # 2 m in feet


def test_compare_blender_is_still_its_own_command(capsys):
    rc, out, _ = run(capsys, "compare", "blender", "--help")
    assert rc == 0 and "--light" in out and "--samples" in out
    rc, _, err = run(capsys, "compare", "blender", "dgauss_50mm")
    assert rc == 2 and "required" in err


def test_focus_hyperfocal_on_lens_commands(capsys):
    """`lens show --focus hyperfocal --fstop 8` focuses where `report --lens ... --focus hyperfocal` says."""
    r = json.loads(run(capsys, "report", "--lens", "dgauss_50mm", "--fstop", "8", "--focus", "hyperfocal", "--json")[1])
    rc, out, err = run(capsys, "lens", "show", "dgauss_50mm", "--focus", "hyperfocal", "--fstop", "8", "--json")
    assert rc == 0 and "hyperfocal focus" in err
    assert json.loads(out)["focus"]["focus_from_film_mm"] == pytest.approx(r["focus_from_film_mm"], rel=1e-12)
    assert math.isfinite(r["focus_from_film_mm"])


# ---- review findings (2026-11-23): options that did nothing, lists with holes, messages -------------
@pytest.mark.parametrize("argv, says", [
    (["dof-table", "--focal", "50", "--fstops", "2,,4"], "'2,,4' has an empty item"),
    (["dof-table", "--focal", "50", "--fstops", "2", "--focus", "1m,,2m"], "'1m,,2m' has an empty item"),
    (["report", "--focal", "50", "--fstop", "2", "--focus", "2m", "--pupil-fraction", "5"],
     "--pupil-fraction places the tape-measure pupil estimate"),
    (["bokeh", "dgauss_50mm", "--rays", "0"], "bokeh rays must lie between 1 and 1e11, got 0"),
    (["bokeh", "dgauss_50mm", "--pixels", "4"], "bokeh pixels must lie between 8 and 4096, got 4"),
    (["bokeh", "dgauss_50mm", "--light", "0"], "light distance"),
    (["distortion", "dgauss_50mm", "--fit", "brown"], "--fit needs --resolution"),
])
def test_refusals_name_what_is_wrong(capsys, argv, says):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("physcam: error:") and says in err[0], err


def test_the_dof_card_carries_the_dof_chart(tmp_path, capsys):
    """Issue 32: the dof-table card draws the DOF chart of the set's apps under its table (the chart of
    `report --plot`), a band per stop of the table; tests/test_figures_style.py checks its text fits."""
    card = tmp_path / "card.svg"
    assert main(["dof-table", "--focal", "35", "--fstops", "2.8,5.6", "--focus", "2m", "--sensor", "ALEXA 35",
                 "-o", str(card)]) == 0
    capsys.readouterr()
    text = card.read_text(encoding="utf-8")
    assert "focus mark from the film plane" in text and "near and far limits" in text
    assert "H f/2.8" in text and "H f/5.6" in text  # each stop's hyperfocal marked on the chart


def test_colour_film_is_the_reference_lines_focus_for_a_lens_designed_elsewhere(capsys, tmp_path):
    # found in review: through a camera state the film went to the design wavelength's focus (546 nm
    # here), 7.8 um from the d line's, and every lateral colour figure moved with it
    from physcam.lens.library import load_lens
    from physcam.optics.paraxial import gaussian

    src = Path(__file__).resolve().parents[2] / "src/physcam/data/lenses/cooke_triplet_50mm_f4_5.toml"
    text = src.read_text().replace("coating = \"none\"\n", "coating = \"none\"\nwavelength_nm = 546.074\n", 1)
    path = tmp_path / "cooke546.toml"
    path.write_text(text)
    rc, out, _ = run(capsys, "colour", "--lens", str(path), "--json")
    d_focus = gaussian(load_lens(str(path)), wavelength_nm=587.5618).z_rear_focal_point
    assert rc == 0 and json.loads(out)["film_z_mm"] == pytest.approx(d_focus, abs=1e-6)
