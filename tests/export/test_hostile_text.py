"""Issue 40, item 11: a text from a lens file or a user (a lens name, notes, a maker, a sensor or
variant name, a path) never becomes code in a file physcam writes.

Every exporter is fed the same hostile corpus. Each output is read back by a reader written here
from the language's own rules, independent of physcam's escaping (``physcam.export._codetext``):

- OSL: the C preprocessor's first translation phases (ISO C 5.1.1.2: trigraphs, backslash-newline
  splices, comments replaced by a space), then the code with comments removed must be the very
  code written for a harmless name: the hostile text stayed inside its comment.
- Python: ``ast.parse`` of the script (and ``compile``), whose tree, string values blanked, must be
  the harmless name's tree; the strings read back hold the text; no PEP 263 encoding declaration
  on the first two lines.
- RIB and pbrt: a tokenizer (``#`` to the line end; quoted strings with backslash escapes) whose
  tokens must be the harmless name's.
- Nuke: the ``.nk`` tokenized as Tcl words (quotes, backslash escapes, braces): the same nodes and
  knobs as for a harmless path, no ``[`` or ``$`` in a quoted word, braces balanced.
- 3DE4: the same number of lines, the name on its one line, the rest unchanged.
- XML (Mitsuba): ``xml.etree`` parses it and the element tree is the harmless name's.
- USD: usd-core opens the file and the text reads back exactly; a text USD cannot carry (NUL, an
  undecodable byte) is refused in one line (``ExportError``).
- JSON (Unreal, OpenCV/Omniverse): ``json.loads`` (strict) reads the name back exactly.
"""

from __future__ import annotations

import ast
import dataclasses
import io
import json
import os
import re
import tokenize
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import ExportError, PhysCamError
from physcam.lens.library import load_lens

#: The corpus: line breaks of every kind, quotes, backslashes, comment closers, NUL, undecodable
#: bytes (surrogates), a Python encoding declaration, Tcl and XML syntax, bidi overrides, 5000 characters.
HOSTILE = [
    "evil\n#define N_SURF 1\nshader x(){}\n",
    "cr\rimport os\r\nos.system('id')",
    'quote " and """ triple """',
    "backslash at the end \\",
    "backslash \\\nspliced #define HALF_W 0.0",
    "trigraph ??/\n#define HALF_H 0.0",
    "*/ closes /* opens",
    "# hash // slashes",
    "nul\x00byte",
    "surrogates \udc80\udcff of undecodable bytes",
    "# -*- coding: utf-7 -*-",
    "\u2028line separator\u2029paragraph\x85nel\x0bvt\x0cff\x1cfs\x1dgs\x1ers",
    "xml --> <!-- & <tag a=\"1\"> -",
    "tcl [exec rm -rf ~] $HOME {brace} }",
    "\u202eright-to-left override\u202c",
    "tab\tseparated\twords",
    "tab\tand escape \x1b[31m red",
    "\\N{BULLET} \\x41 \\u0041 escapes",
    "x" * 5000 + "\n#define N_SURF 1",
]
HARMLESS = "harmless lens"
IDS = [f"h{i}" for i in range(len(HOSTILE))]


def _named(lens, name: str, **more):
    return dataclasses.replace(lens, metadata=dataclasses.replace(lens.metadata, name=name, **more))


@pytest.fixture(scope="module")
def triplet():
    return load_lens("cooke_triplet_50mm_f4_5")


# ------------------------------------------------------------------ OSL (a C preprocessor's view)
_C_TOKEN = re.compile(r'//[^\r\n]*|/\*.*?\*/|"(?:\\.|[^"\\\r\n])*"|/\*|"', re.S)


def c_code(text: str) -> str:
    """``text`` after ISO C translation phases 1-3 (5.1.1.2): trigraph ``??/`` made ``\\``, every
    backslash-newline spliced away, each comment replaced by one space (strings kept whole)."""

    def token(m: re.Match) -> str:
        t = m.group()
        if t == "/*":
            raise AssertionError("an unterminated /* comment")
        if t == '"':
            raise AssertionError("a line break inside a string (or an unterminated one)")
        return t if t[0] == '"' else " "

    text = text.replace("??/", "\\")
    text = re.sub(r"\\\r?\n", "", text)
    return _C_TOKEN.sub(token, text)


def _writable(text: str) -> None:
    text.encode("utf-8")  # a lone surrogate would raise here, at the write
    assert "\x00" not in text


@pytest.fixture(scope="module")
def baked(triplet):
    from physcam.export.blender import bake_camera
    from physcam.optics.state import camera_state

    return bake_camera(camera_state(triplet, focus_mm=2000.0, sensor_mm=(24.0, 18.0)))


@pytest.mark.parametrize("name", HOSTILE, ids=IDS)
def test_osl_shader_keeps_the_name_in_its_comment(baked, name):
    from physcam.export.blender import _emit

    def shader(n):
        return _emit(dataclasses.replace(baked, lens=_named(baked.lens, n)), dispersion=False, fresnel=False)

    text = shader(name)
    _writable(text)
    assert c_code(text) == c_code(shader(HARMLESS))


@pytest.fixture(scope="module")
def focus_table_of_triplet(triplet):
    from physcam.export.blender_focus import focus_table

    # 4 focus states, not the builder's 32: the name reaches the shader's comment by the same code whatever
    # the number of states (the tables are numbers), and the table costs 1.9 s of CPU instead of about 5
    return focus_table(triplet, n_focus=4)


def test_extension_shaders_keep_the_name_in_their_comment(focus_table_of_triplet):
    """The Blender extension's focus-table shaders (``blender_focus.focus_table_shader``)."""
    from physcam.export.blender_focus import focus_table_shader

    ft = focus_table_of_triplet
    base = c_code(focus_table_shader(dataclasses.replace(ft, lens=_named(ft.lens, HARMLESS))))
    for name in HOSTILE:
        text = focus_table_shader(dataclasses.replace(ft, lens=_named(ft.lens, name)))
        _writable(text)
        assert c_code(text) == base, repr(name[:40])


def test_osl_comment_splices_nothing_for_any_text():
    """A property over every text (hypothesis): ``// <osl_comment(t)>`` then a line of code: the
    preprocessor sees the code line whole, whatever ``t`` holds."""
    from physcam.export._codetext import osl_comment

    @settings(max_examples=300, deadline=None)
    @given(st.text())
    def check(t):
        assert c_code(f"// {osl_comment(t)}\n#define X 1\n") == " \n#define X 1\n"

    check()


# ------------------------------------------------------------------ Python
_CODING = re.compile(rb"^[ \t\f]*#.*?coding[:=][ \t]*([-\w.]+)")  # PEP 263's own expression


def _blank_strings(tree):
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            node.value = ""
    return ast.dump(tree)


def _python(text: str):
    _writable(text)
    data = text.encode("utf-8")
    for line in data.splitlines()[:2]:
        assert not _CODING.match(line), line
    compile(data, "<generated>", "exec")
    tokenize.tokenize(io.BytesIO(data).readline)
    return ast.parse(data)


@pytest.mark.parametrize("name", HOSTILE, ids=IDS)
def test_builtin_camera_script_keeps_comments_in_its_docstring(name):
    from physcam.export.blender_camera import blender_camera_script

    values = {"camera": {"lens": 50.0}, "render": {}, "entrance_pupil_from_film_mm": 80.0, "notes": [name]}
    tree = _python(blender_camera_script(values, comments=[name, "second"]))
    doc = ast.get_docstring(tree, clean=False)
    assert doc.endswith("second\n")
    values_node = next(n for n in tree.body if isinstance(n, ast.Assign) and n.targets[0].id == "VALUES")
    assert json.loads(values_node.value.args[0].value)["notes"] == [name]  # data kept exactly
    base = ast.parse(blender_camera_script(values, comments=[HARMLESS, "second"]))
    assert _blank_strings(tree) == _blank_strings(base)
    if name.isprintable() and "coding" not in name:
        assert name in doc  # a printable line reads back as written


@pytest.mark.parametrize("name", HOSTILE, ids=IDS)
def test_setup_script_holds_the_shader_and_path_as_strings(baked, name):
    from physcam.export.blender import _emit, blender_setup_script

    src = _emit(dataclasses.replace(baked, lens=_named(baked.lens, name)), dispersion=False, fresnel=False)
    tree = _python(blender_setup_script(src, sensor_width_mm=24.0, sensor_height_mm=18.0, text_name=name))
    consts = {n.targets[0].id: n.value.value for n in tree.body if isinstance(n, ast.Assign)
              and isinstance(n.value, ast.Constant)}
    base = ast.parse(blender_setup_script(src, sensor_width_mm=24.0, sensor_height_mm=18.0, text_name=HARMLESS))
    assert _blank_strings(tree) == _blank_strings(base)
    assert consts["SHADER_SOURCE"] == src and consts["TEXT_NAME"] == name
    path = Path(name.replace("\n", "_").replace("\r", "_") + ".osl")
    if "\x00" not in str(path):
        tree = _python(blender_setup_script(path, sensor_width_mm=24.0, sensor_height_mm=18.0))
        base = ast.parse(blender_setup_script(Path("lens.osl"), sensor_width_mm=24.0, sensor_height_mm=18.0))
        assert _blank_strings(tree) == _blank_strings(base)


def test_python_docstring_reads_back_any_printable_line():
    from physcam.export._codetext import python_docstring

    @settings(max_examples=300, deadline=None)
    @given(st.text(st.characters(blacklist_categories=("Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp")), max_size=300))
    def check(t):
        if re.search(r"(?i)coding[:=]", t):
            return
        assert ast.literal_eval(f'"""{python_docstring(t)} """') == t + " "

    check()


# ------------------------------------------------------------------ RIB and pbrt
_HASH_TOKEN = re.compile(r'(?P<c>#[^\r\n]*)|(?P<s>"(?:[^"\\\r\n]|\\.)*")|(?P<sp>\s+)|(?P<w>[^\s"#\[\]]+)|(?P<b>[\[\]])'
                         r'|(?P<bad>.)', re.S)


def hash_tokens(text: str) -> list[str]:
    """Tokens of a RIB or pbrt file: ``#`` comments to the line end (LF or CR) dropped, quoted
    strings (backslash escapes) whole, brackets, bare words and numbers."""
    out = []
    for m in _HASH_TOKEN.finditer(text):
        assert m.lastgroup != "bad", f"unexpected {m.group()!r}"
        if m.lastgroup in ("s", "w", "b"):
            out.append(m.group())
    return out


@pytest.fixture(scope="module")
def report(triplet):
    from physcam.onset.report import solve_report
    from physcam.onset.request import report_camera
    from physcam.optics.sensors import custom_sensor

    return solve_report(report_camera(focal_length_mm=None, sensor=custom_sensor(24.0, 18.0), fstop=5.6,
                                      focus_mm=2000.0, lens=triplet))


@pytest.mark.parametrize("legacy", [False, True])
def test_rib_comments_hold_any_text(report, legacy):
    from physcam.export.renderman import rib_camera_block, rib_camera_values

    values = rib_camera_values(report, 1.0)
    base = hash_tokens(rib_camera_block(values, legacy=legacy, comments=[HARMLESS]))
    for name in HOSTILE:
        text = rib_camera_block(values, legacy=legacy, comments=[name])
        _writable(text)
        assert hash_tokens(text) == base, repr(name[:40])


def test_pbrt_scene_and_lens_comments_hold_any_text(report, triplet):
    from physcam.export.pbrt import pbrt_camera_values, pbrt_lens_text, pbrt_scene_snippet

    values = pbrt_camera_values(report, triplet)
    for camera in ("realistic", "perspective"):
        base = hash_tokens(pbrt_scene_snippet(values, camera, comments=[HARMLESS]))
        for name in HOSTILE:
            text = pbrt_scene_snippet(values, camera, comments=[name])
            _writable(text)
            assert hash_tokens(text) == base, repr(name[:40])
    base = hash_tokens(pbrt_lens_text(triplet, comments=[HARMLESS])[0])
    for name in HOSTILE:  # the lens's own notes go into the .dat too (physcam.lens.formats.pbrt)
        text, _ = pbrt_lens_text(_named(triplet, name, notes=name), comments=[name])
        _writable(text)
        assert hash_tokens(text) == base, repr(name[:40])


def _pbrt_unquote(token: str) -> str:
    return re.sub(r"\\(.)", r"\1", token[1:-1])


@pytest.mark.parametrize("name", ['a "quoted" name.dat', "C:\\lenses\\x.dat", "line\nbreak.dat", "nul\x00.dat"])
def test_pbrt_lens_file_name_is_one_string_or_refused(report, triplet, name):
    from physcam.export.pbrt import pbrt_camera_values, pbrt_scene_snippet

    values = pbrt_camera_values(report, triplet, lensfile=name)
    if "\n" in name or "\x00" in name:
        with pytest.raises(ExportError, match="line break or control character"):
            pbrt_scene_snippet(values, "realistic")
        return
    toks = hash_tokens(pbrt_scene_snippet(values, "realistic"))
    i = toks.index('"string lensfile"')
    assert toks[i + 1] == "[" and toks[i + 3] == "]"
    assert _pbrt_unquote(toks[i + 2]) == name.replace("\\", "/")


# ------------------------------------------------------------------ Nuke
_TCL = re.compile(r'(?P<c>^[ \t]*#[^\n]*)|(?P<q>"(?:[^"\\]|\\.)*")|(?P<o>\{)|(?P<e>\})|(?P<sp>\s+)|(?P<w>[^\s"{}]+)',
                  re.M | re.S)


def nk_nodes(text: str):
    """(node kind, [(knob, value)]) of a ``.nk`` script read as Tcl words; checks that braces balance
    and that no quoted word holds ``[`` or ``$`` (Tcl command and variable substitution)."""
    nodes, depth, words, current = [], 0, [], None
    for m in _TCL.finditer(text):
        kind, v = m.lastgroup, m.group()
        if kind in ("c", "sp"):
            continue
        if kind == "q":
            inner = v[1:-1]
            assert not re.search(r"(?<!\\)[\[$]", inner), f"substitution in {v!r}"
            words.append(re.sub(r"\\(.)", r"\1", inner))
        elif kind == "o":
            assert depth == 0
            depth, current, words = 1, (words[-1], []), []
        elif kind == "e":
            assert depth == 1, "unbalanced }"
            current[1].extend(zip(words[0::2], words[1::2]))
            nodes.append(current)
            depth, words = 0, []
        else:
            words.append(v)
    assert depth == 0, "unbalanced {"
    return nodes


@pytest.mark.parametrize("name", HOSTILE + ["plain/folder/plate.####.exr", "C:\\plates\\p.exr"], ids=IDS + ["ok", "win"])
def test_nuke_script_quotes_paths_or_refuses_them(name):
    from physcam.export.nuke import nuke_stmap_script

    base = nk_nodes(nuke_stmap_script("u.exr", "d.exr", plate="p.exr", version="1.0"))
    text = nuke_stmap_script("u.exr", "d.exr", plate="p.exr", version=name)  # the version goes in a comment
    _writable(text)
    assert nk_nodes(text) == base
    try:
        text = nuke_stmap_script(name, "d.exr", plate=name, render=name)
    except ExportError as exc:
        assert len(str(exc).splitlines()) == 1
        assert any(c in name for c in '{}"[]$') or not name.isprintable()
        return
    nodes = nk_nodes(text)
    assert [(k, [kn for kn, _ in knobs]) for k, knobs in nodes] == [(k, [kn for kn, _ in knobs]) for k, knobs in base]
    files = [dict(knobs)["file"] for k, knobs in nodes if k == "Read"]
    assert files == [name.replace("\\", "/"), name.replace("\\", "/"), "d.exr", name.replace("\\", "/")]


# ------------------------------------------------------------------ 3DEqualizer
@pytest.fixture(scope="module")
def tde4_fit(triplet):
    from physcam.analysis.distortion.models import fit_tde4_radial, samples_from_field
    from physcam.analysis.distortion.stmap import distortion_field
    from physcam.optics.state import camera_state

    res = distortion_field(camera_state(triplet, focus_mm=2000.0, sensor_mm=(24.0, 18.0)), width_px=96,
                           height_px=72, maps=False)
    return fit_tde4_radial(samples_from_field(res))


@pytest.mark.parametrize("name", HOSTILE, ids=IDS)
def test_tde4_lens_name_stays_on_its_line(tde4_fit, name):
    from physcam.export.tde4 import tde4_lens_text

    base = tde4_lens_text(tde4_fit, HARMLESS).split("\n")
    text = tde4_lens_text(tde4_fit, name)
    _writable(text)
    lines = text.split("\n")
    assert len(text.splitlines()) == len(lines) - 1 == len(base) - 1  # no other line break of any kind
    assert lines[1:] == base[1:]
    assert lines[0].endswith("(physcam fit at focus 2 m)")


# ------------------------------------------------------------------ XML (Mitsuba)
def _tree(text: str):
    root = ET.fromstring(text.encode("utf-8"))
    return [(e.tag, sorted(e.attrib.items())) for e in root.iter()]


@pytest.mark.parametrize("name", HOSTILE, ids=IDS)
def test_mitsuba_xml_comment_holds_any_name(report, name):
    from physcam.export.mitsuba import mitsuba_camera_values, mitsuba_scene_xml

    values = mitsuba_camera_values(report)
    base = _tree(mitsuba_scene_xml(values))
    values["physcam"]["lens"] = name
    text = mitsuba_scene_xml(values)
    _writable(text)
    assert _tree(text) == base
    body = text.split("<!--", 1)[1].split("-->", 1)[0]
    assert "--" not in body and not body.endswith("-")  # XML 1.0, 2.5


# ------------------------------------------------------------------ JSON (Unreal, OpenCV/Omniverse)
@pytest.mark.parametrize("name", HOSTILE, ids=IDS)
def test_json_exports_carry_the_name_exactly(triplet, name):
    from physcam.export.opencv_distortion import fit_opencv_pinhole
    from physcam.export.unreal import unreal_lens_file
    from physcam.optics.state import camera_state

    lens = _named(triplet, name)
    data = unreal_lens_file(lens, 24.0, 18.0, image_width_px=320, image_height_px=240, focus_marks_mm=[2000.0])
    back = json.loads(json.dumps(data, indent=2, allow_nan=False))
    assert back["metadata"]["lensInfo"]["modelName"] == back["metadata"]["name"] == back["physcam"]["lens"] == name
    cam = fit_opencv_pinhole(camera_state(lens, focus_mm=2000.0, sensor_mm=(24.0, 18.0)), image_width_px=320,
                             image_height_px=240)
    assert json.loads(json.dumps(cam.to_dict(), allow_nan=False))["lens_name"] == name


# ------------------------------------------------------------------ USD
def _usd_refused(name: str) -> bool:
    return "\x00" in name or any(0xD800 <= ord(c) <= 0xDFFF for c in name)


@pytest.mark.parametrize("name", HOSTILE, ids=IDS)
def test_usd_camera_reads_the_names_back_or_refuses_them(tmp_path, report, name):
    pytest.importorskip("pxr")
    from pxr import Usd

    from physcam.usd.author import author_camera, new_stage, save_stage
    from physcam.usd.spec import spec_from_report

    spec = spec_from_report(report).replaced(lens_name=name, sensor_name=name)
    stage = new_stage()
    if _usd_refused(name):
        with pytest.raises(ExportError, match="cannot carry"):
            author_camera(stage, "/Cameras/Camera", spec)
        return
    author_camera(stage, "/Cameras/Camera", spec)
    path = save_stage(stage, tmp_path / "cam.usda")
    back = Usd.Stage.Open(str(path))
    assert [str(p.GetPath()) for p in back.Traverse()] == ["/Cameras", "/Cameras/Camera", "/Cameras/Camera/Pinhole",
                                                          "/Cameras/Camera/Camera"]
    cam = back.GetPrimAtPath("/Cameras/Camera")
    assert cam.GetCustomDataByKey("physcam:sensorName") == name
    assert back.GetPrimAtPath("/Cameras/Camera/Pinhole").GetCustomDataByKey("physcam:lensName") == name


@pytest.mark.parametrize("name", HOSTILE, ids=IDS)
def test_usd_vendor_lens_reads_name_maker_and_source_back(tmp_path, triplet, name):
    pytest.importorskip("pxr")
    from pxr import Usd

    from physcam.usd.kit import write_vendor_lens

    lens = _named(triplet, name, maker=name, source=name)
    if _usd_refused(name):
        with pytest.raises(ExportError, match="cannot carry"):
            write_vendor_lens(tmp_path / "v.usda", lens, focus_mm=2000.0)
        return
    path = write_vendor_lens(tmp_path / "v.usda", lens, focus_mm=2000.0)
    stage = Usd.Stage.Open(str(path))
    rx = stage.GetPrimAtPath("/Lens/Prescription")
    assert [rx.GetAttribute(a).Get() for a in ("lensName", "maker", "source")] == [name, name, name]


@pytest.mark.parametrize("dates", [["2026-03-01", "2026_03_01"], ["2026-03-0\u00b2"], ["d\n#x", "2026-01-01"]])
def test_usd_characterization_dates_make_valid_variant_names(tmp_path, report, dates):
    """Dates become ASCII variant names; two dates that would make one name are refused (a silent
    overwrite of a measuring day before); a Unicode digit such as a superscript two was an error of
    Sdf's own (a traceback)."""
    pytest.importorskip("pxr")
    from pxr import Usd

    from physcam.usd.kit import write_lens_file
    from physcam.usd.spec import spec_from_report

    spec = spec_from_report(report)
    chars = {d: spec for d in dates}
    if dates[0] == "2026-03-01":
        with pytest.raises(PhysCamError, match="one variant name"):
            write_lens_file(tmp_path / "l.usda", chars)
        return
    path = write_lens_file(tmp_path / "l.usda", chars)
    stage = Usd.Stage.Open(str(path))
    names = stage.GetPrimAtPath("/Lens").GetVariantSets().GetVariantSet("characterization").GetVariantNames()
    assert len(names) == len(dates) + 1 and all(re.fullmatch(r"[A-Za-z0-9_]+", n) for n in names)


# ------------------------------------------------------------------ end to end: a lens file on the command line
def test_cli_export_blender_of_a_hostile_lens_file(tmp_path, capsys):
    """The issue's case: a lens file whose name holds line breaks and OSL code; the shader written by
    ``physcam export blender`` has the harmless file's code, and the setup script parses."""
    from physcam.cli import main

    toml = (Path(__file__).resolve().parents[2] / "src/physcam/data/lenses/cooke_triplet_50mm_f4_5.toml").read_text()
    outs = {}
    for label, name in (("evil", HOSTILE[0] + '"""\\'), ("plain", HARMLESS)):
        lens = tmp_path / f"{label}.toml"
        lens.write_text(re.sub(r'(?m)^name = ".*"$', lambda m: "name = " + json.dumps(name), toml, count=1))
        out = tmp_path / label
        assert main(["export", "blender", "--lens", str(lens), "--focus", "2m", "--sensor-width", "24",
                     "--sensor-height", "18", "-o", str(out), "--builtin"]) == 0
        outs[label] = out
    capsys.readouterr()
    assert c_code((outs["evil"] / "evil.osl").read_text()) == c_code((outs["plain"] / "plain.osl").read_text())
    for script in ("setup_evil.py", "builtin_evil.py"):
        _python((outs["evil"] / script).read_text())


def test_cli_metadata_usd_of_a_clip_with_an_undecodable_file_name(tmp_path, capsys):
    """The clip's file name goes into the camera's ``physcam:source`` description: a name with a byte
    that is not UTF-8 (a surrogate in Python) was a traceback at the write; it is shown as U+FFFD."""
    pytest.importorskip("pxr")
    from pxr import Usd

    from physcam.cli import main

    clip = tmp_path / os.fsdecode(b"clip\xff.csv")
    clip.write_bytes((Path(__file__).resolve().parents[2] / "src/physcam/data/samples/"
                      "arri_alexa_lf_B001C001_first48.csv").read_bytes())
    assert main(["metadata", "usd", str(clip), "-o", str(tmp_path / "cam.usda")]) == 0
    capsys.readouterr()
    stage = Usd.Stage.Open(str(tmp_path / "cam.usda"))
    sources = [p.GetCustomDataByKey("physcam:source") for p in stage.Traverse() if p.GetTypeName() == "PhysicalCamera"]
    assert sources == ["arri camera metadata read by physcam metadata usd (clip\ufffd.csv)"]


def test_a_tab_in_a_lens_note_is_a_space_in_the_exported_comment():
    """pbrt's own dgauss.50mm.dat separates its header's words with tabs; exported, the note read
    "D-GAUSS\ufffdF/2\ufffd22deg\ufffdHFOV" (a tab was a control character to printable_line)."""
    from physcam.export._codetext import printable_line
    from physcam.export.pbrt import pbrt_lens_text

    assert printable_line("a\tb\nc") == "a b\ufffdc"
    text, _ = pbrt_lens_text(load_lens("dgauss_50mm"))
    assert "# D-GAUSS F/2 22deg HFOV" in text.splitlines()


def test_cli_commands_to_paste_keep_a_folder_with_spaces_one_word(tmp_path, capsys):
    """`export blender` prints the Blender command lines to paste; with ``-o "blender cams"`` they read
    ``--python blender cams/setup_....py``, two words to a shell. Quoted (shlex), a shell reads the paths back."""
    import shlex

    from physcam.cli import main

    out = tmp_path / "blender cams ' $HOME"
    assert main(["export", "blender", "--lens", "cooke_triplet_50mm_f4_5", "--focus", "2m", "--sensor", "S35",
                 "-o", str(out), "--builtin"]) == 0
    lines = [ln for ln in capsys.readouterr().out.splitlines() if "blender your.blend --python" in ln]
    assert len(lines) == 2
    for ln, name in zip(lines, ("setup_cooke_triplet_50mm_f4_5.py", "builtin_cooke_triplet_50mm_f4_5.py")):
        words = shlex.split(ln.split(": ", 1)[1].split("  (")[0])
        assert words[:3] == ["blender", "your.blend", "--python"] and words[3] == str(out / name)
        assert Path(words[3]).is_file()
