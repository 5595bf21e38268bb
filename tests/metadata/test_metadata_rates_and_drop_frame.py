"""NTSC frame rates, drop-frame timecode and the damaged copies of a user review (round 22): a 23.976 clip
is 24000/1001 (not 2997/125) in every reader and output; a drop-frame clip keeps its flag from the file to
OpenTrackIO, counts on through minutes and midnight (a drop-frame day is 2,589,408 frames, SMPTE ST
12-1); a missing focus column, a Latin-1 or BOM-less UTF-16 copy and a negative ART start frame are said
as what they are.

The clips in tests/data/camera-metadata/arri-edited/ are the reviewer's edits of the real ALEXA LF take
(README.txt there says how); the other damaged copies are made here from the real samples.
"""

from __future__ import annotations

import csv
import json
import re
from fractions import Fraction
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from physcam.cli import main
from physcam.errors import MetadataError
from physcam.metadata import detect_file, load

from test_metadata_readers import ARRI, RED

D = Path(__file__).resolve().parents[1] / "data" / "camera-metadata"
EDITED = D / "arri-edited"
ARRI_JSON = D / "arri-json" / "B003C003_180327_R1ZA.json"
NTSC = {"23.976": Fraction(24000, 1001), "29.970": Fraction(30000, 1001), "59.940": Fraction(60000, 1001),
        "24.000": Fraction(24), "25.000": Fraction(25)}


def _column(path, name):
    """The column ``name`` of a tab-separated AME file, read with the csv module (not physcam's reader)."""
    return [r[name].strip() for r in csv.DictReader(path.open(encoding="utf-8"), delimiter="\t")]


def _samples(tmp_path, *argv):
    out = tmp_path / "t.jsonl"
    assert main(["metadata", "opentrackio", *map(str, argv), "-o", str(out), "--force"]) == 0
    return [json.loads(line) for line in out.read_text().splitlines()]


# 1. one rate rule ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("fps", list(NTSC))
def test_every_reader_gives_an_ntsc_rate_as_n_1000_over_1001(tmp_path, fps):
    """23.976 is 24000/1001 (SMPTE ST 12-1; docs/live.md), never 2997/125 = 23.976 exactly, in the AME CSV
    (Project FPS), REDline's static CSV (FPS) and ART JSON (Project Rate timebase) alike; 24 and 25 stay."""
    lines = ARRI.read_text(encoding="utf-8").splitlines()
    header = lines[0].split("\t")
    rows = []
    for line in lines[1:4]:
        cells = line.split("\t")
        cells[header.index("Project FPS")] = fps
        rows.append("\t".join(cells))
    (tmp_path / "a.csv").write_text("\n".join([lines[0], *rows]) + "\n", encoding="utf-8")
    static = RED[1].read_text(encoding="utf-8").splitlines()
    sh, sr = next(csv.reader([static[0]])), next(csv.reader([static[1]]))
    sr[sh.index("FPS")] = fps
    (tmp_path / "red.static.csv").write_text(static[0] + "\n" + ",".join(sr) + "\n", encoding="utf-8")
    doc = json.loads(ARRI_JSON.read_text(encoding="utf-8"))
    for s in doc["clipBasedMetadataSets"]:
        if s["metadataSetName"] == "Project Rate":
            s["metadataSetPayload"]["timebase"] = fps.rstrip("0").rstrip(".")
    (tmp_path / "a.json").write_text(json.dumps(doc), encoding="utf-8")
    from physcam.metadata import arri, arri_json, red  # the readers alone: 3 rows of timecode need no 29.97 count

    for rec in (arri.read(tmp_path / "a.csv"), red.read(RED[0], tmp_path / "red.static.csv"),
                arri_json.read(tmp_path / "a.json")):
        assert rec.frame_rate == NTSC[fps], rec.files


@given(st.floats(min_value=0.01, max_value=10000.0, allow_nan=False))
def test_the_readers_rate_rule_is_live_sends(r):
    """exact_rate is physcam.live.frames.rate_fraction (what `live send --fps` and `live record` use) on every
    rate a camera records: one rule, so a clip's samples and a sent stream's agree."""
    from physcam.live.frames import rate_fraction
    from physcam.metadata._text import exact_rate

    assert exact_rate(r) == rate_fraction(r)


def test_a_23_976_clip_reaches_show_opentrackio_and_usd_as_24000_over_1001(tmp_path, capsys):
    """The reviewer's r23976 (Project FPS 23.976): show --json says 24000/1001, OpenTrackIO's sampleRate and
    timecode frameRate are 24000/1001 with --fps 23.976 too, and the USD's timeCodesPerSecond is 24000/1001
    = 23.976023976... (usd.animate.ntsc_rate's), where 23.976 was written."""
    clip = EDITED / "r23976.mov.csv"
    assert set(_column(clip, "Project FPS")) == {"23.976"}
    assert main(["metadata", "show", str(clip), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["clip"]["frame_rate_exact"] == "24000/1001"
    for s in _samples(tmp_path, clip, "--fps", "23.976"):
        assert s["timing"]["sampleRate"] == s["timing"]["timecode"]["frameRate"] == {"num": 24000, "denom": 1001}
    pytest.importorskip("pxr")
    from pxr import Usd

    from physcam.usd.animate import ntsc_rate

    assert main(["metadata", "usd", str(clip), "-o", str(tmp_path / "c.usda")]) == 0
    tcps = Usd.Stage.Open(str(tmp_path / "c.usda")).GetTimeCodesPerSecond()
    assert tcps == 24000 / 1001 == ntsc_rate(23.976)


# 2. and 4. drop-frame from the file to OpenTrackIO ------------------------------------------------------------


def test_a_drop_frame_clip_goes_out_as_live_send_drop_frame_sends_it(tmp_path, capsys):
    """r2997df (Master TC Drop Frame yes, 00:00:59;20 to 00:01:01;21): every sample's timecode has
    dropFrame true at 30000/1001, as `physcam live send --drop-frame --fps 29.97` sends the same three
    timecodes 00:00:59;28, ;29 and 00:01:00;02 (the oracle: physcam's own sender, not the converter)."""
    clip = EDITED / "r2997df.mov.csv"
    tcs = _column(clip, "Master TC")
    assert set(_column(clip, "Master TC Drop Frame")) == {"yes"} and tcs[8:11] == ["00:00:59;28", "00:00:59;29",
                                                                                 "00:01:00;02"]
    got = [s["timing"] for s in _samples(tmp_path, clip)]
    assert all(t["timecode"]["dropFrame"] is True and t["sampleRate"] == {"num": 30000, "denom": 1001} for t in got)
    capsys.readouterr()
    assert main(["live", "send", "--fps", "29.97", "--drop-frame", "--timecode", "00:00:59;28", "--frames", "3",
                 "--focal", "40", "--fstop", "2", "--print"]) == 0
    sent = [json.loads(line)["timing"]["timecode"] for line in capsys.readouterr().out.splitlines()
            if line.startswith("{")]
    assert [t["timecode"] for t in got[8:11]] == sent


def test_the_drop_frame_column_counts_a_colon_timecode_drop_frame(tmp_path):
    """r2997df_colon: Master TC Drop Frame yes, timecodes written with ':' (00:00:59:29 -> 00:01:00:02). The
    column makes it drop-frame: one frame per row, and OpenTrackIO's dropFrame. The same file with the column
    set to no is a 29.97 non-drop timecode that skips frames :00 and :01 at the minute: refused there."""
    clip = EDITED / "r2997df_colon.mov.csv"
    tcs = _column(clip, "Master TC")
    assert set(_column(clip, "Master TC Drop Frame")) == {"yes"} and ";" not in "".join(tcs)
    rec = load(clip)
    assert rec.drop_frame and rec.frame_rate == Fraction(30000, 1001) and len(rec.frames) == 60
    assert all(s["timing"]["timecode"]["dropFrame"] for s in _samples(tmp_path, clip))
    line = tcs.index("00:01:00:02") + 2  # file line: the header is line 1
    ndf = tmp_path / "ndf.csv"
    ndf.write_text(re.sub(r"(?<=\t)yes(?=\t)", "no", clip.read_text(encoding="utf-8")), encoding="utf-8")
    assert set(_column(ndf, "Master TC Drop Frame")) == {"no"}
    with pytest.raises(MetadataError, match=rf"ndf.csv:{line}: the timecode skips 2 frames from 00:00:59:29 "):
        load(ndf)


def test_the_usd_camera_says_drop_frame_only_of_a_drop_frame_clip(tmp_path):
    """physcam:clip (the static values as JSON) carries drop_frame true for r2997df, and no drop_frame key for
    the real 24 fps take, whose USD is thus byte-for-byte what it was before the flag existed."""
    pytest.importorskip("pxr")
    from pxr import Usd

    def clip_of(src, name):
        assert main(["metadata", "usd", str(src), "-o", str(tmp_path / name)]) == 0
        stage = Usd.Stage.Open(str(tmp_path / name))
        return json.loads(stage.GetPrimAtPath("/Cameras/Camera").GetCustomDataByKey("physcam:clip"))

    assert clip_of(EDITED / "r2997df.mov.csv", "df.usda")["drop_frame"] is True
    assert "drop_frame" not in clip_of(ARRI, "ndf.usda")


@pytest.mark.parametrize("fps", ["25.000", "24.000"])
def test_drop_frame_at_a_rate_without_it_is_refused(tmp_path, fps):
    """SMPTE ST 12-1 drops frame numbers at 30000/1001 and 60000/1001 only: a drop-frame clip at 25 or 24 fps
    is a contradiction (a drop of 2 a minute would have been guessed), refused."""
    clip = EDITED / "r2997df.mov.csv"
    p = tmp_path / "df.csv"
    p.write_text(re.sub(r"(?<=\t)29\.970(?=\t)", fps, clip.read_text(encoding="utf-8")), encoding="utf-8")
    assert set(_column(p, "Project FPS")) == {fps}
    with pytest.raises(MetadataError, match=rf"drop-frame timecode at {float(fps):g} fps"):
        load(p)


def test_a_timecode_drop_frame_never_names_is_refused(tmp_path):
    """00:01:00;00 does not exist in drop-frame (numbers ;00 and ;01 of minute 1 are skipped): refused at its
    line, not read as a frame."""
    clip = EDITED / "r2997df.mov.csv"
    p = tmp_path / "df.csv"
    p.write_text(clip.read_text(encoding="utf-8").replace("00:01:00;02", "00:01:00;00"), encoding="utf-8")
    line = _column(clip, "Master TC").index("00:01:00;02") + 2
    with pytest.raises(MetadataError, match=rf"df.csv:{line}: timecode 00:01:00;00 names a frame number drop-frame"):
        load(p)


# 3. a drop-frame day ------------------------------------------------------------------------------------------


def test_a_drop_frame_clip_runs_through_midnight(tmp_path):
    """midnight2997df: 23:59:59;20 to 00:00:00;29 at 29.97 drop-frame. A drop-frame day has 24 x 60 minutes of
    1800 numbers less 2 in the 1296 minutes not divisible by ten: 2,592,000 - 2,592 = 2,589,408 frames, so
    23:59:59;29 (frame 2,589,407) -> 00:00:00;00 is one frame (it was "skips 2592 frames"). With the
    00:00:00;00 row deleted the skip is one frame, refused at the next row."""
    clip = EDITED / "midnight2997df.mov.csv"
    tcs = _column(clip, "Master TC")
    i = tcs.index("00:00:00;00")
    assert tcs[i - 1] == "23:59:59;29"
    assert [f.timecode for f in load(clip).frames] == tcs
    lines = clip.read_text(encoding="utf-8").splitlines()
    gap = tmp_path / "gap.csv"
    gap.write_text("\n".join(lines[: i + 1] + lines[i + 2:]) + "\n", encoding="utf-8")
    with pytest.raises(MetadataError, match=rf"gap.csv:{i + 2}: the timecode skips 1 frame from 23:59:59;29 to "
                                            r"00:00:00;01 at the clip's 29.97 fps drop-frame"):
        load(gap)


# 5.-7. damaged copies said as what they are ----------------------------------------------------------------


def test_a_missing_focus_column_is_said_missing_not_a_lens_without_focus(tmp_path):
    """The real take with its Lens Focus Distance column deleted (the reviewer's nofocus copy): the note says
    the column is absent, not "the lens reported no focus"; the rest of the clip is read as before."""
    rows = list(csv.reader(ARRI.open(encoding="utf-8"), delimiter="\t"))
    k = rows[0].index("Lens Focus Distance")
    p = tmp_path / "nofocus.csv"
    p.write_text("".join("\t".join(r[:k] + r[k + 1:]) + "\n" for r in rows), encoding="utf-8")
    rec, real = load(p), load(ARRI)
    assert rec.notes == ("no 'Lens Focus Distance' column: the file records no focus distance on any of its 500 "
                         "frames; timecode, iris and focal length kept",)
    assert [f.focus_mm for f in rec.frames] == [None] * 500
    assert [(f.timecode, f.tstop) for f in rec.frames] == [(f.timecode, f.tstop) for f in real.frames]


@pytest.mark.parametrize("row", [1, 100])
def test_a_latin1_copy_names_its_first_non_utf8_byte(tmp_path, capsys, row):
    """The real take with "éclair" added to one row's lens name and saved as Latin-1 (é = 0xE9, the reviewer's
    latin1b): refused at that byte's offset (found here in the file's bytes) and its line as not UTF-8. Row 1
    (in the first 4 kB, where the format is told) was "byte 0: a binary file that is not a Mo-Sys F4
    recording"; row 100 (117 kB in) was "line 95: not UTF-8 text", the line the text reader had decoded
    ahead to."""
    lines = ARRI.read_text(encoding="utf-8").splitlines()
    lines[row] = lines[row].replace("\tARRI SP40 T1.8\t", "\tARRI SP40 T1.8 éclair\t", 1)
    data = ("\n".join(lines) + "\n").encode("latin-1")
    at = data.index(b"\xe9")
    (tmp_path / "latin1.csv").write_bytes(data)
    assert main(["metadata", "show", str(tmp_path / "latin1.csv")]) == 2
    err = capsys.readouterr().err
    assert f"latin1.csv: byte {at}: not UTF-8 text: byte 0xE9 (line {row + 1})" in err and "binary" not in err


@pytest.mark.parametrize("encoding, first_nul, order", [("utf-16-le", 1, "little"), ("utf-16-be", 0, "big")])
def test_utf16_without_a_bom_is_said_utf16(tmp_path, encoding, first_nul, order):
    """The real take saved as UTF-16 without its byte-order mark ("Index" is I\\0n\\0... little-endian):
    refused as BOM-less UTF-16 at its first NUL byte, not as a binary file."""
    p = tmp_path / "u16.csv"
    p.write_bytes(ARRI.read_text(encoding="utf-8").encode(encoding))
    with pytest.raises(MetadataError, match=rf"u16.csv: byte {first_nul}: UTF-16 \({order}-endian\) text without "
                                            "a byte-order mark"):
        detect_file(p)


@pytest.mark.parametrize("start", [-5, 86400 * 24, 86400 * 24 + 5])
def test_an_art_start_frame_outside_the_day_is_refused(tmp_path, start):
    """clipStartFrameNumber -5 wrapped silently to 23:59:59:19 (and 2,073,605 = 24:00:00:05 at 24 fps to
    00:00:00:05): a day at 24 fps is frames 0 to 2,073,599; outside it is refused naming file and field."""
    doc = json.loads(ARRI_JSON.read_text(encoding="utf-8"))
    for s in doc["clipBasedMetadataSets"]:
        if s["metadataSetName"] == "Clip Info":
            s["metadataSetPayload"]["clipStartFrameNumber"] = start
    p = tmp_path / "start.json"
    p.write_text(json.dumps(doc), encoding="utf-8")
    with pytest.raises(MetadataError, match=rf"start.json: Clip Info: clipStartFrameNumber {start} is not a frame "
                                            "of the day .* 0 to 2073599"):
        load(p)


@pytest.mark.parametrize("written, exact", [
    (23.976, Fraction(24000, 1001)), (23.98, Fraction(24000, 1001)), (29.97, Fraction(30000, 1001)),
    (47.95, Fraction(48000, 1001)), (59.94, Fraction(60000, 1001)), (119.88, Fraction(120000, 1001)),
    (24.0, Fraction(24)), (25.0, Fraction(25)), (23.9, Fraction(239, 10)), (999.0, Fraction(999)),
    (1000.0, Fraction(1000))])
def test_one_frame_rate_rule_with_two_decimal_ntsc(written, exact):
    """VENICE writes captureFps "23.98p" (Avid and Resolve say 23.98 too): two decimals of 24000/1001, read
    as 1199/50 (0.017 % fast: a frame's drift every 2.5 minutes against the plate). The one rule
    (physcam.frame_rates) reads it as 24000/1001 for the metadata readers, OpenTrackIO and animated USD alike;
    24, 25 and rates near no NTSC rate are unchanged."""
    from physcam.frame_rates import exact_frame_rate
    from physcam.live.frames import rate_fraction
    from physcam.metadata._text import exact_rate
    from physcam.usd.animate import ntsc_rate

    assert exact_frame_rate(written) == rate_fraction(written) == exact_rate(written) == exact
    assert ntsc_rate(written) == (float(exact) if exact.denominator == 1001 else written)
