"""Exports the readers refused before (issue 40 item 8): ARRI Reference Tool JSON, Canon's older
decimal FocusPosition, an ARRI clip whose lens reports a focal length but no focus unit.

Expected values are read from the files by eye and converted by hand; the ARRI JSON's units are
cross-checked against ARRI Meta Extract's CSV of a clip shot the same day on the same camera and
lens (tests/data/camera-metadata/arri/, SOURCES.md)."""

from __future__ import annotations

import json
import struct

import pytest

from physcam.cli import main
from physcam.errors import MetadataError
from physcam.metadata import detect_file, load

from test_metadata_readers import ARRI, D

ARRI_JSON = D / "arri-json" / "B003C003_180327_R1ZA.json"
CANON_2022 = [D / "canon-2022-08" / "20220830_CanonCameraMetadata_Frames.csv",
              D / "canon-2022-08" / "20220830_CanonCameraMetadata_Static.csv"]


def _frames_json():
    return json.loads(ARRI_JSON.read_text(encoding="utf-8"))["frameBasedMetadata"]["frames"]


def test_arri_json_is_told_from_its_content_and_read():
    """frame 0's Lens State: lensFocusDistanceMetric 4844 (mm), lensIris 2667 (1/1000 stop, T1 = 1000:
    T = 2^(1667/2000) = 1.782, the T-stop AME prints as "1.4 + 7/10" for the same lens), lensFocalLength
    40000 (um); frame 100: 815 mm. Clip Info: clipStartFrameNumber 1198051 at Project Rate 24 is
    1198051 = ((13 x 60 + 51) x 60 + 58) x 24 + 19: 13:51:58:19; clipDuration 475. exposureTime 1/50 s
    at sensorSampleRate 24 is 360 x 24 / 50 = 172.8 degrees (AME's Shutter Angle of B001C001, same day)."""
    assert detect_file(ARRI_JSON) == ("arri-json", "frames")
    r = load(ARRI_JSON)
    assert r.source == "arri" and len(r.frames) == 475
    f0, f100, last = r.frames[0], r.frames[100], r.frames[-1]
    assert (f0.focus_mm, f0.focal_length_mm) == (4844.0, 40.0)
    assert f0.tstop == pytest.approx(2 ** (1667 / 2000)) == pytest.approx(1.782, abs=5e-4)
    assert f100.focus_mm == 815.0
    assert f0.timecode == "13:51:58:19" and f100.timecode == "13:52:02:23" and last.timecode == "13:52:18:13"
    assert r.frame_rate == 24 and r.shutter_angle_deg == pytest.approx(172.8) and r.iso == 400
    assert r.exposure_time_s == pytest.approx(0.02) and r.squeeze == 1.0
    assert (r.camera_model, r.camera_serial, r.lens_model, r.lens_serial) == \
        ("Alexa LF Plus W", "2566", "ARRI SP40 T1.8", "2")
    assert r.resolution_px == (4448, 3096) and r.active_area_mm == (36.70, 25.54)  # ARRI's LF Open Gate
    assert r.clip_name == "B003C003_180327_R1ZA"  # the header's mxfFileName (Slate Info's clipName is empty)
    assert all(f.fstop is None for f in r.frames)  # a T-stop only: no f-stop invented


def test_arri_json_units_agree_with_ame_on_the_same_camera():
    """AME's B001C001 (same camera, lens and day) prints Lens Linear Iris 2667 beside Lens Iris
    "1.4 + 7/10" and Lens Focal Length 40.000: the JSON's lensIris 2667 and lensFocalLength 40000 read
    the same T-stop and focal length; Master TC Frame Count 1176223 is its 13:36:49:07, the relation
    the JSON's clipStartFrameNumber is read by."""
    ame, art = load(ARRI).frames[0], load(ARRI_JSON).frames[0]
    assert art.tstop == pytest.approx(ame.tstop, rel=1e-12) and art.focal_length_mm == ame.focal_length_mm
    h, m, s, f = (int(x) for x in ame.timecode.split(":"))
    assert ((h * 60 + m) * 60 + s) * 24 + f == 1176223


def test_arri_json_every_frame_against_the_file():
    frames = _frames_json()
    r = load(ARRI_JSON)
    for fr, s in zip(frames, r.frames):
        lens = fr["frameBasedMetadataSets"]["Lens State"]
        assert s.focus_mm == lens["lensFocusDistanceMetric"]
        assert s.tstop == pytest.approx(2 ** ((lens["lensIris"] - 1000) / 2000))
        assert s.focal_length_mm == lens["lensFocalLength"] / 1000


def test_arri_json_focus_at_infinity_is_absent_and_said(tmp_path):
    doc = json.loads(ARRI_JSON.read_text(encoding="utf-8"))
    doc["frameBasedMetadata"]["frames"][3]["frameBasedMetadataSets"]["Lens State"]["lensFocusDistanceMetric"] = -1
    p = tmp_path / "inf.json"
    p.write_text(json.dumps(doc))
    r = load(p)
    assert r.frames[3].focus_mm is None and r.frames[3].focal_length_mm == 40.0
    assert any("at infinity (-1) on 1 of 475 frames (first: frame 3)" in n for n in r.notes)


@pytest.mark.parametrize("edit, words", [
    (lambda d: d["arriJsonHeader"].update(jsonSchemaUri="https://www.arri.com/schema/json/metadata_output/v1-0-0"),
     "physcam reads metadata_output v2"),
    (lambda d: d["clipBasedMetadataSets"][2]["metadataSetPayload"].update(clipDuration=476),
     "Clip Info says 476 frames, frameBasedMetadata holds 475"),
    (lambda d: d["frameBasedMetadata"]["frames"][7]["frameBasedMetadataSets"]["Lens State"].update(lensIris="x"),
     "frame 7: lensIris 'x' is not a number"),
])
def test_bad_arri_json_is_one_sentence(tmp_path, capsys, edit, words):
    doc = json.loads(ARRI_JSON.read_text(encoding="utf-8"))
    edit(doc)
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(doc))
    assert main(["metadata", "show", str(p)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err, err


def test_truncated_arri_json_names_the_line(tmp_path, capsys):
    p = tmp_path / "cut.json"
    p.write_text(ARRI_JSON.read_text(encoding="utf-8")[:5000])
    assert main(["metadata", "show", str(p)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "cut.json:" in err and "not well-formed JSON" in err, err


def test_older_canon_export_with_a_decimal_focus_position():
    """camdkit's first Canon sample writes FocusPosition 1055286886: as a 32-bit pattern 0x3EE66666, the
    big-endian float 0.45 (m); FocalLength 500/10 = 50 mm, ApertureNumber 40/10 with ApertureMode 1 = f/4;
    LensSqueezeFactor 0 = 1x; ShotNumber A002C002."""
    r = load(CANON_2022)
    f = r.frames[0]
    assert 1055286886 == 0x3EE66666
    assert f.focus_mm == pytest.approx(struct.unpack(">f", bytes.fromhex("3EE66666"))[0] * 1000) \
        == pytest.approx(450.0, abs=1e-3)
    assert (f.focal_length_mm, f.fstop, f.tstop, f.timecode) == (50.0, 4.0, None, "00:00:03:15")
    assert r.clip_name == "A002C002" and r.squeeze == 1.0
    assert any("decimal" in n for n in r.notes)


@pytest.mark.parametrize("cell", ["3EE6666", "10552868866", "4294967296", "0x3EE66666"])
def test_a_focus_position_neither_hex_nor_decimal_bits_is_refused(tmp_path, cell):
    text = CANON_2022[0].read_text(encoding="utf-8").replace("1055286886", cell)
    p = tmp_path / "frames.csv"
    p.write_text(text)
    with pytest.raises(MetadataError, match="neither 8 hex digits nor the decimal integer"):
        load(p)


def test_arri_without_a_focus_unit_keeps_timecode_and_focal_length(tmp_path):
    """The AME sample with every row's Lens Distance Unit and Lens Focus Distance emptied (a lens that
    gives its focal length but no focus): 500 frames kept with their Master TC and 40 mm; focus absent
    and the notes say so. A focus value without its unit is not guessed either."""
    rows = ARRI.read_text(encoding="utf-8").splitlines()
    header = rows[0].split("\t")
    iu, ifo = header.index("Lens Distance Unit"), header.index("Lens Focus Distance")
    out = [rows[0]]
    for k, line in enumerate(rows[1:]):
        cells = line.split("\t")
        cells[iu] = ""
        if k:  # the first row keeps its focus value: a value without a unit
            cells[ifo] = ""
        out.append("\t".join(cells))
    p = tmp_path / "nounit.csv"
    p.write_text("\n".join(out) + "\n", encoding="utf-8")
    r = load(p)
    assert len(r.frames) == 500 and all(f.focus_mm is None for f in r.frames)
    assert r.frames[0].timecode == "13:36:49:07" and r.frames[-1].timecode == "13:37:10:02"
    assert {f.focal_length_mm for f in r.frames} == {40.0}
    assert any("500 of 500 frames have no focus distance" in n and "line 2" in n for n in r.notes)
