"""The rules every command keeps (issue 15), checked by walking the parser, so a new command is held
to them the day it arrives (docs/cli.md, "Writing a command"):

- every ``--json`` prints a versioned document (schema, version, units) that validates against the
  JSON Schema shipped for it in physcam/cli/schemas; every command with ``--json`` has a run here;
- every ``--csv`` prints the rows of that document, cell for cell (CSV round-trips to the JSON);
- every focus option reads distances, ``hyperfocal`` and ``infinity``, and a command taking a
  focus prints distances in ``--units m|ft``;
- every command taking a sensor takes the shared sensor options and says its default;
- tables piped or redirected are plain and complete (no box, no ellipsis);
- one grammar (issue 26): a lens is always ``--lens NAME_OR_FILE`` (the old positional spelling is
  hidden and says it is deprecated), and every single-value option given twice is an error naming it;
- hostile numbers (issue 24 item 12): no option reads its value with bare ``int`` or ``float`` (a
  400-digit count or 1e-320 reached the handlers and overflowed there): integers are
  ``_common.whole`` (bounded), real numbers ``_common.number`` (finite, no subnormals).
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import os
import shutil
from pathlib import Path

import pytest

from _documents import check_document
from physcam.cli import build_parser, main
from physcam.cli._common import HYPERFOCAL
from physcam.cli._output import SCHEMA_DIR

pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]
LIVE_SAMPLE = REPO / "tests" / "live" / "data" / "recommended_static_example.json"


def leaves(parser=None, prefix=()):
    """(path, parser) of every runnable subcommand."""
    parser = parser or build_parser()
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not subs:
        yield prefix, parser
        return
    seen = set()
    for name, p in subs[0].choices.items():
        if id(p) not in seen:
            seen.add(id(p))
            yield from leaves(p, prefix + (name,))


def options(parser) -> set[str]:
    return {o for a in parser._actions for o in a.option_strings}


LEAVES = dict(leaves())

#: One quick run of every command that has --json (run in a folder the `workdir` fixture prepares).
JSON_RUNS = {
    ("defocus-kernels",): ["defocus-kernels", "--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8",
                           "--resolution", "64x36", "--field-grid", "2x1", "--depths", "1m", "-o", "kernels"],
    ("report",): ["report", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--cameras"],
    ("dof-table",): ["dof-table", "--focal", "35", "--fstops", "2,4", "--focus", "1m,hyperfocal,inf"],
    ("sensors",): ["sensors", "ARRI"],
    ("exposure",): ["exposure", "--fps", "24", "--to-fps", "48"],
    ("diopter",): ["diopter", "--focal", "50", "--fstop", "2.8", "--focus", "inf", "--sensor", "S35"],
    ("hyperfocal",): ["hyperfocal", "--focal", "25,50", "--fstops", "2.8,8", "--sensor", "S35"],
    ("lenses",): ["lenses"],
    ("lens", "show"): ["lens", "show", "dgauss_50mm", "--focus", "2m"],
    ("lens", "breathing"): ["lens", "breathing", "dgauss_50mm", "--focus", "1m", "2m", "inf"],
    ("lens", "zoom"): ["lens", "zoom", "--lens", "laikin_zoom_15_150mm", "--steps", "3"],
    ("lens", "check"): ["lens", "check", "dgauss_50mm"],
    ("lens", "card"): ["lens", "card", "--lens", "dgauss_50mm", "--draft", "--dpi", "30", "-o", "card.png"],
    ("lens", "fix"): ["lens", "fix", "dgauss_50mm.toml", "-o", "fixed.toml"],
    ("spot",): ["spot", "dgauss_50mm", "--rings", "8"],
    ("bokeh",): ["bokeh", "dgauss_50mm", "--rays", "2000", "--pixels", "32", "--focus", "2m", "--light", "1m"],
    ("illumination",): ["illumination", "dgauss_50mm", "--grid", "16"],
    ("colour",): ["colour", "dgauss_50mm", "--field", "0", "--field", "5"],
    ("breathing-real",): ["breathing-real", "dgauss_50mm", "--focus", "inf", "--focus", "2m"],
    ("ghosts",): ["ghosts", "dgauss_50mm", "--top", "3"],
    ("distortion",): ["distortion", "dgauss_50mm"],
    ("compare", "lenses"): ["compare", "dgauss_50mm", "tessar_50mm_f2_8", "--rays", "2000"],
    ("usd", "write"): ["usd", "write", "w.usda", "--focal", "35", "--fstop", "2.8", "--focus", "3m"],
    ("usd", "read"): ["usd", "read", "shot.usda"],
    ("usd", "kit"): ["usd", "kit", "vendor", "v2.usda", "--lens", "dgauss_50mm", "--focus", "1.5m"],
    ("usd", "animate"): ["usd", "animate", "pull.usda", "--lens", "dgauss_50mm", "--marks", "pull.csv"],
    ("usd", "check"): ["usd", "check", "shot2.usda"],
    ("usd", "refresh"): ["usd", "refresh", "shot2.usda"],
    ("config", "show"): ["config", "show"],
    ("export", "unreal"): ["export", "unreal", "dgauss_50mm", "-o", "d.ulens", "--width-px", "1024", "--height-px", "683",
                           "--focus", "inf", "--focus", "2m"],
    ("export", "opencv"): ["export", "opencv", "dgauss_50mm", "--width-px", "1024", "--height-px", "683"],
    ("export", "blender"): ["export", "blender", "dgauss_50mm", "--focus", "2m", "-o", "cams"],
    ("export", "blender-extension"): ["export", "blender-extension", "-o", "ext", "--lens", "dgauss_50mm"],
    ("export", "rib"): ["export", "rib", "-o", "c.rib", "--focal", "40", "--fstop", "2.8", "--focus", "2.5m"],
    ("export", "pbrt"): ["export", "pbrt", "-o", "pbrt", "--lens", "dgauss_50mm", "--fstop", "2.8", "--focus", "2m"],
    ("live", "validate"): ["live", "validate", str(LIVE_SAMPLE)],
    ("live", "frustum"): ["live", "frustum", "shot.usda", "frustum.usda", "--wall", "wall.usda"],
    ("mtf",): ["mtf", "dgauss_50mm", "--fstop", "4", "--fields", "3", "--pupil-samples", "32", "--frequency", "20"],
    ("psf",): ["psf", "dgauss_50mm", "--fstop", "8", "--field", "5", "--method", "huygens", "--samples", "33"],
    ("microlens", "insert"): ["microlens", "insert", "dgauss_50mm", "--microlens-focal", "0.5", "--xdim", "21", "--ydim",
                              "21", "--film-width", "4.2", "--film-height", "4.2", "--focus", "1m", "-o", "lf.json"],
    ("microlens", "render"): ["microlens", "render", "lf0.json", "--fstop", "5.6", "--point", "1m", "--rays", "2000",
                              "--pixels-per-lenslet", "3"],
    ("characterize",): ["characterize", "dgauss_50mm", "--focus", "1m,inf", "--fstop", "2.8", "-o", "lib", "--dry-run"],
    ("metadata", "show"): ["metadata", "show", str(REPO / "tests/data/camera-metadata/red/A001_C066_0303LZ_001.frames.csv"),
                           str(REPO / "tests/data/camera-metadata/red/A001_C066_0303LZ_001.static.csv")],
    ("metadata", "report"): ["metadata", "report", str(REPO / "tests/data/camera-metadata/red/A001_C066_0303LZ_001.frames.csv"),
                             str(REPO / "tests/data/camera-metadata/red/A001_C066_0303LZ_001.static.csv")],
    ("metadata", "usd"): ["metadata", "usd", str(REPO / "tests/data/camera-metadata/bmd/metadata.txt"), "-o", "clip.usda",
                          "--plate", "plate.mov", "--plate-frames", "1-1"],
    ("export", "mitsuba"): ["export", "mitsuba", "-o", "mit", "--focal", "50", "--fstop", "2.8", "--focus", "3m",
                            "--width-px", "64"],
}
#: Further runs of documents a command prints in other modes.
EXTRA_JSON_RUNS = {
    "lens show --zoom": ["lens", "show", "nikon_af_s_70_200mm_f2_8e_zoom", "--zoom", "135mm"],
    "lens breathing --zoom": ["lens", "breathing", "laikin_zoom_15_150mm", "--zoom", "0.5", "--focus", "2m"],
    "psf_fft": ["psf", "dgauss_50mm", "--fstop", "8"],
    "mtf_chart_best_focus": ["mtf", "dgauss_50mm", "--fstop", "4", "--fields", "3", "--pupil-samples", "32",
                             "--frequency", "20", "--best-focus", "20"],
    # f/2.8: its document has the keys and value types of f/5.6's (the former run here), in 2/3 of the CPU
    "report_dof_real": ["report", "--lens", "dgauss_50mm", "--fstop", "2.8", "--focus", "3m", "--dof", "real"],
    "distortion_field": ["distortion", "dgauss_50mm", "--resolution", "256x171", "--focus", "2m", "--fit", "brown"],
    "distortion_across_focus": ["distortion", "dgauss_50mm", "--resolution", "256x171", "--across-focus", "1m,inf"],
    "report_at_infinity": ["report", "--lens", "dgauss_50mm", "--fstop", "2.8", "--focus", "inf", "--cameras"],
    "mtf_field": ["mtf", "dgauss_50mm", "--fstop", "8", "--field", "10", "--pupil-samples", "32"],
}
#: Commands with --json this test does not run, and why (each is covered where named).
JSON_NOT_RUN = {
    ("defocus",): "needs an EXR render with depth (tests/analysis/defocus/test_defocus.py runs it and validates the document)",
    ("compare", "blender"): "needs Blender's bpy (tests/blender/test_compare.py validates its document)",
    ("live", "record"): "needs a UDP stream (tests/live/test_cli_live.py records one and validates the document)",
    ("live", "recover"): "needs a recording's journal (tests/live/test_takes.py recovers one and validates the document)",
    ("calibrate",): "needs chart photographs (tests/analysis/calibration/test_calibrate.py renders them and validates its document)",
    ("demo",): "writes the whole demo (tests/onset_cli/test_report_cli.py::test_demo_writes_outputs validates it)",
    ("lens", "pack"): "packs a lens card and a USD file (tests/lens/test_lens_archive.py round-trips an archive through "
                      "pack, check and add and validates both documents)",
    ("lens", "add"): "needs an archive from `lens pack` (tests/lens/test_lens_archive.py validates its document)",
    ("farm",): "its --json goes before the `--` of the command line it wraps, where this test appends it "
               "(tests/farm/test_farm_jobs.py validates its document)",
    ("farm-task",): "runs a task of a farm job (tests/farm/test_farm_run.py runs them; test_farm_task_json_document "
                    "validates its document)",
}
#: Where the rows of each --csv command's document are.
CSV_ROWS = {
    ("dof-table",): "rows", ("sensors",): "sensors", ("lenses",): "lenses", ("lens", "breathing"): "rows",
    ("lens", "zoom"): "rows",
    ("spot",): "fields", ("illumination",): "points", ("colour",): "lateral",
    ("breathing-real",): "rows", ("ghosts",): "paths", ("distortion",): "points", ("compare", "lenses"): "lenses",
    ("export", "unreal"): "lens_file.physcam.marks", ("mtf",): "points", ("lens", "show"): "points",
    ("config", "show"): "rows",
    ("metadata", "show"): "frames", ("metadata", "report"): "frames",
}
#: Commands that take a focus but print no distance (so no --units), and why.
NO_UNITS = {
    ("defocus",): "prints the file written; depths are read in --depth-unit",
    ("defocus-kernels",): "prints the files written; the index holds millimetres",
    ("psf",): "prints a Strehl ratio and micrometres on the film (the focus mark is an input only)",
    ("usd", "write"): "prints the file written; the file holds millimetres and scene units",
    ("usd", "kit"): "prints the file written",
    ("live", "record"): "prints frame counts and timecodes",
    ("live", "recover"): "prints frame counts and timecodes (as live record)",
    ("live", "send"): "prints the samples sent (OpenTrackIO's own units)",
}
#: Focus options with a grammar of their own (not _common.focus), and why.
OWN_FOCUS_GRAMMAR = {
    ("characterize",): "a grid of marks shared by several lenses and f-stops (NEAR:FAR:N or a list; inf reads as "
                       "infinity); the hyperfocal mark differs per lens and f-stop, so it has no place in the grid",
}
#: Commands whose --sensor has another default than the one default sensor, and why.
OTHER_SENSOR_DEFAULT = {
    ("live", "record"): "the stream's sensor, when it carries one",
    ("live", "recover"): "the recording's own options (its stream's sensor, when it carries one)",
    ("live", "play"): "the recording's sensor",
    ("lens", "check"): "optional: with a sensor the check adds a corner probe",
    ("metadata", "report"): "the clip's recorded sensor area when the file gives it",
    ("metadata", "usd"): "the clip's recorded sensor area when the file gives it",
}


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    """A folder with what the runs read: a camera, a shot with body and lens, a focus pull, a wall."""
    from physcam.lens.library import library_dir

    d = tmp_path_factory.mktemp("contract")
    old = os.getcwd()
    os.chdir(d)
    try:
        shutil.copy(library_dir() / "dgauss_50mm.toml", d / "dgauss_50mm.toml")
        (d / "pull.csv").write_text("frame,focus\n1,2m\n24,3m\n")
        for argv in (["usd", "write", "shot.usda", "--focal", "35", "--fstop", "2.8", "--focus", "3m", "--sensor",
                      "ALEXA 35"],
                     ["usd", "kit", "body", "body.usda", "--sensor", "ALEXA 35"],
                     ["usd", "kit", "vendor", "v.usda", "--lens", "dgauss_50mm", "--focus", "1.5m"],
                     ["usd", "kit", "shot", "shot2.usda", "--body", "body.usda", "--lens", "v.usda", "--focus", "2m"],
                     ["live", "wall", "wall.usda"],
                     ["microlens", "insert", "dgauss_50mm", "--microlens-focal", "0.5", "--xdim", "21", "--ydim", "21",
                      "--film-width", "4.2", "--film-height", "4.2", "--focus", "1m", "-o", "lf0.json"]):
            assert main(argv) == 0, argv
    finally:
        os.chdir(old)
    return d


def run_json(capsys, workdir, argv):
    old = os.getcwd()
    os.chdir(workdir)
    try:
        capsys.readouterr()
        rc = main([*argv, "--json", *_force(argv)])
        out, err = capsys.readouterr()
    finally:
        os.chdir(old)
    assert rc == 0, f"physcam {' '.join(argv)} --json: exit {rc}\n{err}"
    return json.loads(out)


def _force(argv):
    """--force where the run writes a file (the module's folder is shared, runs repeat)."""
    writes = any(a in ("-o", "--plot") or a.endswith((".usda", ".ulens", ".rib")) for a in argv) and "--dry-run" not in argv
    return ["--force"] if writes and "--force" in _opts_of(argv) else []


def _opts_of(argv):
    for n in (2, 1):
        if tuple(argv[:n]) in LEAVES:
            return options(LEAVES[tuple(argv[:n])])
    if argv[:1] == ["compare"]:
        return options(LEAVES[("compare", "lenses")])
    return set()


def test_every_json_command_is_run_here():
    with_json = {path for path, p in LEAVES.items() if "--json" in options(p)}
    missing = with_json - set(JSON_RUNS) - set(JSON_NOT_RUN)
    assert not missing, f"commands with --json but no run in JSON_RUNS (add one): {sorted(missing)}"
    assert not (set(JSON_RUNS) | set(JSON_NOT_RUN)) - with_json, "JSON_RUNS names a command without --json"


@pytest.mark.parametrize("path", sorted(JSON_RUNS), ids=" ".join)
def test_json_validates_against_its_shipped_schema(capsys, workdir, path):
    doc = run_json(capsys, workdir, JSON_RUNS[path])
    check_document(doc)


@pytest.mark.parametrize("name", sorted(EXTRA_JSON_RUNS))
def test_other_documents_validate(capsys, workdir, name):
    check_document(run_json(capsys, workdir, EXTRA_JSON_RUNS[name]))


def test_every_schema_file_is_a_schema_named_for_its_document():
    import jsonschema

    files = sorted(SCHEMA_DIR.glob("*.schema.json"))
    assert len(files) >= 30
    for f in files:
        s = json.loads(f.read_text())
        jsonschema.Draft202012Validator.check_schema(s)
        name = f.name.removesuffix(".schema.json")
        assert s["properties"]["schema"]["const"] == f"physcam.{name}", f.name
        assert {"schema", "version", "units"} <= set(s["required"]) or name == "lens_report", f.name


def _rows(doc, key):
    for part in key.split("."):
        doc = doc[part]
    return doc


def _same(cell: str, value) -> bool:
    """A CSV cell against the JSON value it came from (numbers exactly: CSV carries repr)."""
    if value is None:
        return cell == ""
    if isinstance(value, bool):
        return cell == ("true" if value else "false")
    if isinstance(value, (int, float)):
        return cell != "" and float(cell) == float(value)
    if isinstance(value, list):
        return cell == ";".join("" if v is None else str(v) for v in value)
    return cell == str(value)


@pytest.mark.parametrize("path", sorted(CSV_ROWS), ids=" ".join)
def test_csv_round_trips_to_the_json_rows(capsys, workdir, path):
    assert "--csv" in options(LEAVES[path])
    argv = JSON_RUNS[path]
    rows = _rows(run_json(capsys, workdir, argv), CSV_ROWS[path])
    old = os.getcwd()
    os.chdir(workdir)
    try:
        rc = main([*argv, "--csv", *_force(argv)])
        out, err = capsys.readouterr()
    finally:
        os.chdir(old)
    assert rc == 0, err
    table = list(csv.DictReader(io.StringIO(out)))
    assert len(table) == len(rows) > 0
    assert table and set(table[0]) <= set(rows[0]), f"CSV columns that are not JSON keys: {set(table[0]) - set(rows[0])}"
    for got, want in zip(table, rows):
        for k, cell in got.items():
            assert _same(cell, want[k]), f"{' '.join(path)} row {want}: {k} CSV {cell!r} != JSON {want[k]!r}"


def test_every_csv_command_has_its_rows_named():
    with_csv = {path for path, p in LEAVES.items() if "--csv" in options(p)}
    assert with_csv == set(CSV_ROWS), f"add their rows to CSV_ROWS: {sorted(with_csv ^ set(CSV_ROWS))}"


def _focus_actions(p):
    return [a for a in p._actions if getattr(a.type, "physcam_focus", None)]


def test_every_focus_option_reads_hyperfocal_and_infinity():
    """Every option that takes a focus mark is built with physcam.cli._common.focus (or focus_list)."""
    named = []
    for path, p in LEAVES.items():
        for a in p._actions:
            if a.option_strings and a.dest in ("focus", "focus_to", "at", "across_focus") \
                    and path not in OWN_FOCUS_GRAMMAR:
                named.append((path, a))
    assert len(named) >= 15
    for path, a in named:
        spec = getattr(a.type, "physcam_focus", None)
        assert spec is not None, f"{' '.join(path)} {a.option_strings}: build its type with _common.focus()"
        got = a.type("hyperfocal")
        assert got == HYPERFOCAL or got == [HYPERFOCAL], (path, a.option_strings)
        if spec["infinity"]:
            got = a.type("infinity")
            assert got == math.inf or got == [math.inf], (path, a.option_strings)
        else:
            with pytest.raises(argparse.ArgumentTypeError, match="finite"):
                a.type("infinity")


def test_commands_taking_a_focus_print_distances_in_units():
    for path, p in LEAVES.items():
        if _focus_actions(p) and path not in NO_UNITS:
            assert "--units" in options(p), f"{' '.join(path)} takes a focus: add add_units_option (or NO_UNITS)"


def test_commands_taking_a_sensor_share_the_options_and_the_default():
    for path, p in LEAVES.items():
        if "--sensor" not in options(p) or path in OTHER_SENSOR_DEFAULT:
            continue
        assert {"--sensor-width", "--sensor-height"} <= options(p), path
        helps = {a.option_strings[0]: a.help for a in p._actions if a.option_strings}
        assert "default Super 35" in helps["--sensor"], f"{' '.join(path)}: use _common.add_sensor_options"


@pytest.mark.parametrize("argv, whole", [
    (["lenses"], "Double Gauss 50mm f/2 (pbrt dgauss.50mm)"),
    (["sensors", "ARRI"], "ARRI ALEXA Mini LF / LF 4.5K LF Open Gate 3:2"),
    (["report", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--lens-length", "12cm", "--sensor-front", "30cm"],
     "estimate: 0.4 of the lens length behind its front"),
    (["lens", "show", "dgauss_50mm"], "front focal length (F to first vertex)"),
    (["dof-table", "--focal", "35", "--fstops", "2,2.8,4,5.6,8,11,16", "--focus", "1m,2m"], "f/16 near - far"),
])
def test_piped_tables_are_plain_and_complete(capsys, argv, whole):
    assert main(argv) == 0  # captured: not a terminal
    out = capsys.readouterr().out
    assert whole in out
    assert not set("┃│━┏┡└…") & set(out), "a piped table keeps no box drawing and no ellipsis"


# ---- one grammar (issue 26) ------------------------------------------------------------------------
LENS_DESTS = ("lens", "lenses")


def test_every_command_takes_its_lens_as_an_option():
    with_lens = 0
    for path, p in LEAVES.items():
        for a in p._actions:
            if a.dest in LENS_DESTS:
                with_lens += 1
                assert a.option_strings == ["--lens"], f"{' '.join(path)}: the lens is --lens NAME_OR_FILE"
            if not a.option_strings and a.dest not in ("help", "_lens_positional"):
                assert "lens" not in a.dest, f"{' '.join(path)}: a positional lens ({a.dest}); use add_lens_argument"
            if a.dest == "_lens_positional":
                assert a.help == argparse.SUPPRESS, f"{' '.join(path)}: the deprecated positional lens is hidden"
    assert with_lens >= 25


def _value_that_parses(path, parser, action):
    """A value argparse accepts for ``action`` (its choices, its default, or a common shape), else None."""
    candidates = list(action.choices or []) + [action.default, "1", "0.5", "2m", "1,2", "64x48", "a", "S35"]
    for v in candidates:
        if v is None or isinstance(v, bool) or v == argparse.SUPPRESS:
            continue
        v = v if isinstance(v, str) else (",".join(map(str, v)) if isinstance(v, (tuple, list)) else str(v))
        try:
            action(parser, argparse.Namespace(), action.type(v) if callable(action.type) else v, action.option_strings[0])
            return v
        except (argparse.ArgumentTypeError, argparse.ArgumentError, ValueError, TypeError, SystemExit):
            continue
    return None


def test_every_single_value_option_given_twice_is_an_error(capsys):
    from physcam.cli import _StoreOnce

    checked = 0
    for path, p in LEAVES.items():
        for a in p._actions:
            if not a.option_strings or a.nargs not in (None, "?"):
                continue
            if type(a) is argparse._StoreAction:
                pytest.fail(f"{' '.join(path)} {a.option_strings[0]}: a single-value option that may be repeated")
            if not isinstance(a, _StoreOnce):
                continue
            v = _value_that_parses(path, p, a)
            if v is None:
                continue
            opt = a.option_strings[0]
            assert main([*path, opt, v, opt, v]) == 2, f"{' '.join(path)} {opt} twice"
            err = capsys.readouterr().err
            assert f"{opt} was given twice" in err, (path, opt, err)
            checked += 1
    assert checked > 100


# ---- hostile numbers (issue 24 item 12) -------------------------------------------------------------
def test_no_option_reads_a_bare_int_or_float():
    """Every integer option is bounded (``_common.whole``); no option is ``type=int`` or ``type=float``."""
    bare, wholes = [], 0
    for path, p in LEAVES.items():
        for a in p._actions:
            if a.type in (int, float):
                bare.append(f"{' '.join(path)} {a.option_strings[0] if a.option_strings else a.dest}")
            wholes += getattr(a.type, "physcam_whole", None) is not None
    assert not bare, f"use _common.whole (integers) or _common.number (reals): {bare}"
    assert wholes >= 25


def test_whole_options_refuse_a_400_digit_number():
    """A 400-digit count is refused by every integer option's type (bounds at most 2**53: a float holds it)."""
    huge = "9" * 400
    for path, p in LEAVES.items():
        for a in p._actions:
            bounds = getattr(a.type, "physcam_whole", None)
            if bounds is None:
                continue
            assert -(2**53) <= bounds[0] <= bounds[1] <= 2**53, (path, a.option_strings)
            with pytest.raises(argparse.ArgumentTypeError, match="whole number from"):
                a.type(huge)


def test_the_command_table_names_every_command_and_its_module():
    """physcam.cli.COMMAND_MODULES lets a run build only its own command's parser (start-up): it must
    name exactly the commands the modules register, each with the module that registers it."""
    import importlib
    import pkgutil

    import physcam.cli as cli

    found = {}
    for m in pkgutil.iter_modules(cli.__path__):
        if m.name.startswith("_"):
            continue
        module = importlib.import_module(f"physcam.cli.{m.name}")
        if getattr(module, "register", None) is None:
            continue
        parser = cli._Parser(prog="physcam")
        sub = parser.add_subparsers(dest="command", parser_class=cli._Parser)
        module.register(sub)
        found.update({name: m.name for name in sub.choices})
    assert found == cli.COMMAND_MODULES
    # a lone command's parser answers as the full one does
    assert cli.build_parser(["report"]).parse_args(["report", "--focal", "50", "--fstop", "2"]).focal == 50.0
