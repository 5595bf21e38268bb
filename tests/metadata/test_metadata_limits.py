"""Values no camera records are refused before they reach "validated" OpenTrackIO, USD or ``metadata
show``; a concatenated recording is refused naming where each take starts; a large CSV is read with
memory well under its size (issue 40 item 9)."""

from __future__ import annotations

import json
import tracemalloc
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.cli import main
from physcam.errors import MetadataError
from physcam.metadata import load

from test_metadata_readers import ARRI, MOSYS, RED


def _arri_with(tmp_path, name="edit.csv", **cells):
    """The real AME sample with the named columns of its first row replaced."""
    lines = ARRI.read_text(encoding="utf-8").splitlines()
    header = lines[0].split("\t")
    first = lines[1].split("\t")
    for col, v in cells.items():
        first[header.index(col.replace("_", " "))] = v
    p = tmp_path / name
    p.write_text("\n".join([lines[0], "\t".join(first), *lines[2:]]) + "\n", encoding="utf-8")
    return p


def _refused(capsys, argv, words):
    assert main(argv) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("physcam: error: ") and all(w in err for w in words), err
    return captured.out


def test_a_red_fstop_of_1e308_never_reaches_opentrackio(tmp_path, capsys):
    pytest.importorskip("jsonschema")
    text = RED[0].read_text(encoding="utf-8").splitlines()
    header = text[0].split(",")
    row = text[1].split(",")
    row[header.index("Aperture")] = "1e308"
    p = tmp_path / "red.frames.csv"
    p.write_text("\n".join([text[0], ",".join(row), *text[2:]]) + "\n")
    out = _refused(capsys, ["metadata", "opentrackio", str(p), str(RED[1]), "-o", str(tmp_path / "t.jsonl")],
                   ["red.frames.csv:2: ", "f-stop 1e+308 is outside from 0.5 to 1000"])
    assert out == "" and not (tmp_path / "t.jsonl").exists()


@pytest.mark.parametrize("cells, words", [
    ({"Lens_Focus_Distance": "-5"}, ["edit.csv:2: ", "focus distance -5000 mm is outside more than 0 mm"]),
    ({"Project_FPS": "-5"}, ["the clip's frame rate -5 is outside more than 0 fps"]),
    ({"Lens_Linear_Iris": "-3000"}, ["T-stop 0.25 is outside from 0.5 to 1000"]),
    ({"Shutter_Angle": "720"}, ["shutter angle 720 is outside more than 0 degrees and at most 360 degrees"]),
])
def test_metadata_show_refuses_what_no_camera_records(tmp_path, capsys, cells, words):
    p = _arri_with(tmp_path, **cells)
    for argv in (["metadata", "show", str(p)], ["metadata", "show", str(p), "--json"]):
        assert _refused(capsys, argv, words) == ""


def test_show_json_is_whole_or_nothing(tmp_path, capsys):
    """A focus of 1e308 m is a finite number in the file and infinite in mm: refused before printing, so
    stdout holds no half document (it held 3 kB of JSON, then a traceback)."""
    p = _arri_with(tmp_path, Lens_Focus_Distance="1e308")
    assert _refused(capsys, ["metadata", "show", str(p), "--json"], ["edit.csv:2: ", "focus distance inf mm"]) == ""
    assert main(["metadata", "show", str(ARRI), "--json"]) == 0
    json.loads(capsys.readouterr().out)  # the real clip: one whole document


@settings(max_examples=40, deadline=None)
@given(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e4, max_value=1e4))
def test_a_stop_is_kept_exactly_when_it_is_in_range(tmp_path_factory, stop):
    """Any Canon ApertureNumber is kept as the f-stop when 0.5 <= N <= 1000 and refused otherwise."""
    from test_metadata_readers import CANON

    from physcam.metadata.limits import FRAME_RANGES

    lines = CANON[0].read_text(encoding="utf-8").splitlines()
    header = lines[0].split(",")
    row = lines[1].split(",")
    row[header.index("ApertureNumber")] = repr(stop)
    row[header.index("ApertureMode")] = "1"
    p = tmp_path_factory.mktemp("stop") / "frames.csv"
    p.write_text("\n".join([lines[0], ",".join(row)]) + "\n")
    lo, hi = FRAME_RANGES["fstop"][:2]
    if lo <= stop <= hi:
        assert load(p).frames[0].fstop == stop
    else:
        with pytest.raises(MetadataError, match="f-stop .* is outside from 0.5 to 1000"):
            load(p)


def test_a_mosys_recording_concatenated_20_times_is_refused(tmp_path, capsys):
    """20 copies of the real F4 recording (1497 packets, timecode 15:03:47:02 on): the timecode runs back
    19 times, at packets 1497, 2994 ... (k x 1497), each from its last timecode to its first."""
    data = MOSYS.read_bytes()
    p = tmp_path / "twenty.f4"
    p.write_bytes(data * 20)
    rec = load(MOSYS)
    first, last = rec.frames[0].timecode, rec.frames[-1].timecode
    _refused(capsys, ["metadata", "show", str(p)],
             ["the timecode runs back 19 times", "20 takes one after another",
              f"packet 1497 ({last} -> {first})", "packet 2994", "and 14 more", "split the file"])


def test_a_timecode_through_midnight_is_one_take(tmp_path):
    lines = ARRI.read_text(encoding="utf-8").splitlines()
    header = lines[0].split("\t")
    idx = [i for i, h in enumerate(header) if h == "Master TC"]
    out = [lines[0]]
    for k, tc in enumerate(("23:59:59:22", "23:59:59:23", "00:00:00:00", "00:00:00:01")):
        cells = lines[1 + k].split("\t")
        for i in idx:
            cells[i] = tc
        out.append("\t".join(cells))
    p = tmp_path / "midnight.csv"
    p.write_text("\n".join(out) + "\n")
    assert [f.timecode for f in load(p).frames][1:3] == ["23:59:59:23", "00:00:00:00"]


def _big_ame(path: Path, rows: int) -> int:
    """An AME CSV of ``rows`` real rows (the sample's, repeated) with a Master TC counting on from the
    sample's first: tens of MB of a file whose every row is a real camera's."""
    src = ARRI.read_text(encoding="utf-8").splitlines()
    header = src[0].split("\t")
    idx = [i for i, h in enumerate(header) if h == "Master TC"]
    with path.open("w", encoding="utf-8") as fh:
        fh.write(src[0] + "\n")
        for k in range(rows):
            cells = src[1 + k % 500].split("\t")
            s, f = divmod(1176223 + k, 24)
            tc = f"{s // 3600:02d}:{s // 60 % 60:02d}:{s % 60:02d}:{f:02d}"
            for i in idx:
                cells[i] = tc
            fh.write("\t".join(cells) + "\n")
    return path.stat().st_size


def test_a_large_csv_is_read_in_less_memory_than_its_size(tmp_path):
    """4,000 rows (4.6 MB): the most Python allocates while reading (tracemalloc's peak) stays under
    half the file's size (the frames kept are ~0.26 of it); reading the whole text, its lines and a dict
    of every row's 183 cells took about 16 times the size (308 MB for 17,000 rows).

    17,000 rows (19.6 MB) until round 14, 10 s under tracemalloc on a loaded machine; the bound is a
    ratio to the size, which a reader that holds the text breaks at any size (16 times), and a
    smaller file only makes it stricter for the reader's fixed buffers (0.27 of the size at 17,000
    rows, 0.26 at 4,000)."""
    p = tmp_path / "big.csv"
    size = _big_ame(p, 4_000)
    assert size > 4e6
    tracemalloc.start()
    try:
        rec = load(p)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert len(rec.frames) == 4_000 and rec.frames[-1].focus_mm == pytest.approx(load(ARRI).frames[499].focus_mm)
    assert peak < 0.5 * size, f"peak {peak / 1e6:.1f} MB for a {size / 1e6:.1f} MB file"


def _ame_rows(tmp_path, name, timecodes, fps=None):
    """The real AME sample's first rows with these Master TCs (and Project FPS), nothing after them."""
    lines = ARRI.read_text(encoding="utf-8").splitlines()
    header = lines[0].split("\t")
    out = [lines[0]]
    for k, tc in enumerate(timecodes):
        cells = lines[1 + k].split("\t")
        for i, h in enumerate(header):
            if h == "Master TC":
                cells[i] = tc
            elif h == "Project FPS" and fps is not None:
                cells[i] = fps
        out.append("\t".join(cells))
    p = tmp_path / name
    p.write_text("\n".join(out) + "\n", encoding="utf-8")
    return p


def test_a_deleted_row_is_refused_where_the_timecode_skips(tmp_path, capsys):
    """The real ARRI take with its 200th frame row (file line 201) deleted: every later frame would land one
    plate frame early, so the reader refuses at the row after the gap, naming the timecodes either side."""
    lines = ARRI.read_text(encoding="utf-8").splitlines()
    tc = lambda line: lines[line - 1].split("\t")[1]  # noqa: E731  (Master TC is the 2nd column)
    before, gone = tc(200), tc(201)
    p = tmp_path / "gap.csv"
    p.write_text("\n".join(lines[:200] + lines[201:]) + "\n", encoding="utf-8")
    _refused(capsys, ["metadata", "show", str(p)],
             ["gap.csv:201: ", f"skips 1 frame from {before} to {tc(202)} at the clip's 24 fps"])
    assert gone not in capsys.readouterr().err


def test_a_frame_rate_the_timecode_was_not_counted_at_is_refused(tmp_path, capsys):
    """The real take (timecode counted at 24 fps) with Project FPS changed to 25: at 25 fps, :23 to :00 of the
    next second skips frame :24, at the first second boundary of the file."""
    p = _arri_with(tmp_path, name="fps25.csv", Project_FPS="25.000")
    lines = p.read_text(encoding="utf-8").splitlines()
    line = next(n for n in range(2, len(lines) + 1) if lines[n - 1].split("\t")[1].endswith(":00"))
    _refused(capsys, ["metadata", "show", str(p)], [f"fps25.csv:{line}: ", "skips 1 frame", "at the clip's 25 fps"])


def test_a_timecode_frame_past_the_frame_rate_is_refused_at_its_line(tmp_path, capsys):
    """Frame 24 does not exist at 24 fps (frames run 00 to 23): refused at its line, not taken for a new take."""
    p = _ame_rows(tmp_path, "tc.csv", ["13:36:49:22", "13:36:49:23", "13:36:49:24", "13:36:50:00"])
    _refused(capsys, ["metadata", "show", str(p)], ["tc.csv:4: ", "timecode 13:36:49:24 is not a time", "00 to 23"])


def test_drop_frame_timecode_at_29_97_counts_on_through_the_dropped_numbers(tmp_path):
    """SMPTE ST 12-1 drop frame: numbers ;00 and ;01 are skipped at each minute but every tenth, so
    00:00:59;29 -> 00:01:00;02 and 00:09:59;29 -> 00:10:00;00 are one frame each, and
    00:00:59;29 -> 00:01:00;03 loses the frame numbered ;02: refused."""
    ok = _ame_rows(tmp_path, "df.csv", ["00:00:59;28", "00:00:59;29", "00:01:00;02", "00:01:00;03"], fps="29.970")
    assert [f.timecode for f in load(ok).frames][2] == "00:01:00;02"
    ok10 = _ame_rows(tmp_path, "df10.csv", ["00:09:59;29", "00:10:00;00", "00:10:00;01"], fps="29.970")
    assert len(load(ok10).frames) == 3
    skip = _ame_rows(tmp_path, "df1.csv", ["00:00:59;29", "00:01:00;03"], fps="29.970")
    with pytest.raises(MetadataError, match=r"df1.csv:3: the timecode skips 1 frame"):
        load(skip)


def test_a_take_in_feet_is_converted_and_said_in_feet(tmp_path):
    """Lens Distance Unit "Feet": the first row's 4.812 is 4.812 x 304.8 mm = 1466.7 mm (1 ft = 304.8 mm)."""
    lines = ARRI.read_text(encoding="utf-8").splitlines()
    header = lines[0].split("\t")
    u, d = header.index("Lens Distance Unit"), header.index("Lens Focus Distance")
    rows = [r.split("\t") for r in lines[1:3]]
    for r in rows:
        r[u] = "Feet"
    p = tmp_path / "feet.csv"
    p.write_text("\n".join([lines[0], *("\t".join(r) for r in rows)]) + "\n", encoding="utf-8")
    rec = load(p)
    assert rec.frames[0].focus_mm == pytest.approx(float(rows[0][d]) * 304.8, rel=1e-12)
    assert "focus distances recorded in feet, converted to mm" in rec.notes


def test_a_corrupt_lens_iris_cell_is_refused_even_beside_the_linear_iris(tmp_path, capsys):
    """The linear iris is the one read (finer), but a Lens Iris cell that is no stop is a corrupt row."""
    p = _arri_with(tmp_path, name="iris.csv", Lens_Iris="banana")
    _refused(capsys, ["metadata", "show", str(p)], ["iris.csv:2: ", "Lens Iris 'banana' is not a stop"])


def test_fps_that_contradicts_the_files_rate_is_refused_not_ignored(tmp_path, capsys):
    """--fps stands in for a rate the file lacks; the ARRI take records Project FPS 24, so --fps 25 (which was
    silently ignored: the USD came out at 24) is refused, and nothing is written; --fps 24 agrees."""
    out = tmp_path / "take.usda"
    _refused(capsys, ["metadata", "usd", str(ARRI), "-o", str(out), "--fps", "25"],
             ["records 24 fps, not --fps 25"])
    assert not out.exists()
    assert main(["metadata", "opentrackio", str(ARRI), "--fps", "24", "-o", str(tmp_path / "t.jsonl")]) == 0
