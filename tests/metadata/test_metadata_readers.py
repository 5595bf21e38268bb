"""Every sample export loads, with values read by eye from the files (issue 30).

Each expected value names the file and row it was read from; conversions are worked by hand here
(1 ft = 304.8 mm; a stop marking N plus x/10 stop is T = 2^((AV + x/10)/2) with AV = 2 log2 N;
Cooke /i fields are 6 bits a byte, bit 6 set). The samples are copies of
../shared/reference/camera-metadata (SOURCES.md there and in tests/data/camera-metadata).
"""

from __future__ import annotations

import math
import struct
from pathlib import Path

import pytest

from physcam.errors import MetadataError, PhysCamError
from physcam.metadata import detect, detect_file, load
from physcam.metadata.record import timecode_frames

D = Path(__file__).resolve().parents[1] / "data" / "camera-metadata"
ARRI = D / "arri" / "B001C001_180327_R1ZA.mov.csv"
RED = [D / "red" / "A001_C066_0303LZ_001.frames.csv", D / "red" / "A001_C066_0303LZ_001.static.csv"]
VENICE = [D / "venice" / "D001C005_210716AG.csv", D / "venice" / "D001C005_210716AGM01.xml"]
CANON = [D / "canon" / "20221007_TNumber_CanonCameraMetadata_Frames.csv",
         D / "canon" / "20221007_TNumber_CanonCameraMetadata_Static.csv"]
BMD = D / "bmd" / "metadata.txt"
MOSYS = D / "mosys" / "A003_C001_01 15-03-47-01.f4"
FT = 304.8


def f32(hex8: str) -> float:
    return struct.unpack(">f", bytes.fromhex(hex8))[0]


def test_arri_first_and_last_frame():
    r = load(ARRI)
    assert r.source == "arri" and len(r.frames) == 500  # 501 lines: header + 500 rows
    first, last = r.frames[0], r.frames[-1]
    # line 2: Master TC 13:36:49:07, Lens Distance Unit Meter, Lens Focus Distance 4.812, Lens Focal Length 40.000,
    # Lens Iris "1.4 + 7/10", Lens Linear Iris 2667
    assert first.line == 2 and first.timecode == "13:36:49:07"
    assert first.focus_mm == pytest.approx(4812.0)
    assert first.focal_length_mm == 40.0
    assert first.tstop == pytest.approx(2 ** (1.667 / 2))  # linear iris: 1667/1000 stop above T1
    assert abs(2 * math.log2(first.tstop / 2 ** (1.7 / 2))) < 0.05  # agrees with "1.4 + 7/10" to 1/20 stop
    assert first.fstop is None  # the file gives a T-stop only: no f-stop invented
    # line 501: Master TC 13:37:10:02, Lens Focus Distance 3.056
    assert last.line == 501 and last.timecode == "13:37:10:02" and last.focus_mm == pytest.approx(3056.0)
    assert last.focal_length_mm == 40.0
    assert r.frame_rate == 24 and r.shutter_angle_deg == 172.8 and r.squeeze == 1.0
    assert r.lens_model == "ARRI SP40 T1.8" and r.camera_model == "Alexa LF Plus W" and r.iso == 400
    assert r.resolution_px == (1920, 1080)
    assert r.active_area_mm == (31.68, 17.82)  # ARRI's LF 16:9 HD area; said in active_area_source
    assert r.nominal_focal_length_mm is None  # not a field of the file


def test_arri_timecodes_match_the_frame_count_column_and_increase_by_one():
    r = load(ARRI)
    # line 2: Master TC Frame Count 1176223 = frames since midnight at 24 fps of 13:36:49:07
    assert timecode_frames(r.frames[0].timecode, 24) == 1176223
    counts = [timecode_frames(f.timecode, r.frame_rate) for f in r.frames]
    assert counts == list(range(counts[0], counts[0] + len(counts)))


def test_red_frames_and_cooke_bytes():
    r = load(RED)
    assert r.source == "red" and len(r.frames) == 2  # Total Frames 2 in the static CSV
    a, b = r.frames
    # frames.csv line 2: 23:17:21:08, Aperture 5.600000, Focus Distance 410, Focal Length 40
    assert (a.timecode, a.fstop, a.focus_mm, a.focal_length_mm) == ("23:17:21:08", 5.6, 410.0, 40.0)
    # line 3: 23:17:21:09, 5.6, 420, 40
    assert (b.timecode, b.fstop, b.focus_mm, b.focal_length_mm) == ("23:17:21:09", 5.6, 420.0, 40.0)
    # Cooke bytes of line 2: 64 | 40 40 46 68 | 48 70 | B8 80 | 40 40 | 40 42 66 6D | 40 40 46 5E | 40 40 46 73
    #                        | 45 4E | 41 7F | 40 40 | 53 "G53599764" 0A 0D
    c = a.cooke
    assert c.focus_distance_mm == 6 * 64 + 0x28  # 424
    assert c.t_stop == (8 * 64 + 0x30) / 100  # 5.60
    assert c.zoom_mm is None  # a prime: zz = 0
    assert c.hyperfocal_mm == 2 * 4096 + 0x26 * 64 + 0x2D  # 10669
    assert (c.near_mm, c.far_mm) == (6 * 64 + 0x1E, 6 * 64 + 0x33)  # 414, 435
    assert c.entrance_pupil_mm == 64 + 63 and a.entrance_pupil_mm == 127  # 41 7F, sign bit clear
    assert c.serial == "G53599764" == r.lens_serial
    assert b.cooke.focus_distance_mm == 6 * 64 + 0x34 and b.entrance_pupil_mm == 126  # 46 74; 41 7E
    assert a.tstop == 5.6  # the T-stop comes from the lens data
    assert r.frame_rate == 24 and r.shutter_angle_deg == 180 and r.iso == 250
    assert r.active_area_mm == pytest.approx((4096 * 0.005, 2160 * 0.005))  # MONSTRO 8K VV: 5 um photosites


def test_venice_feet_and_stop_notation():
    r = load(VENICE)
    assert r.source == "venice" and len(r.frames) == 588  # 589 lines; XML Duration 588
    a, z = r.frames[0], r.frames[-1]
    # csv line 2: "16:47:04:19", Focal Length (mm) "32", Aperture "T 2 3/10", Focus Distance (ft) "5.83"
    assert a.timecode == "16:47:04:19" and a.focal_length_mm == 32
    assert a.focus_mm == pytest.approx(5.83 * FT)
    assert a.tstop == pytest.approx(2 ** (2.3 / 2))  # T2 and 3/10 stop
    # line 589: "16:47:29:06", "32", "T 2 3/10", "8.94"
    assert z.timecode == "16:47:29:06" and z.focus_mm == pytest.approx(8.94 * FT) and z.focal_length_mm == 32
    assert r.frame_rate == 24 and r.lens_model == "S7i-32" and r.camera_model == "MPC-3610"
    assert r.shutter_angle_deg == pytest.approx(103.8)  # ShutterSpeedAngle 10380 (1/100 degree)
    assert r.active_area_mm is None  # neither file gives it


def test_venice_timecodes_increase_by_one_frame():
    r = load(VENICE)
    counts = [timecode_frames(f.timecode, 24) for f in r.frames]
    assert counts == list(range(counts[0], counts[0] + 588))


def test_canon():
    r = load(CANON)
    assert r.source == "canon" and len(r.frames) == 1
    f = r.frames[0]
    # Frames.csv line 2: Timecode 0:00:00:00, FocusPosition 3F000000, FocalLength 180/10, ApertureNumber 45/10,
    # ApertureMode 2 (T-number)
    assert f.timecode == "00:00:00:00"
    assert f.focus_mm == pytest.approx(0.5 * 1000)  # 0x3F000000: exponent 126, mantissa 0 -> 0.5 (metres)
    assert f.focal_length_mm == 18 and f.tstop == 4.5 and f.fstop is None
    assert r.shutter_angle_deg == 180  # ExposureTime 18000/100
    assert r.iso == 2147485248 - 0x80000000 == 1600
    assert r.squeeze == 1.0 and r.frame_rate is None  # LensSqueezeFactor 0; no frame rate in the files


def test_blackmagic():
    r = load(BMD)
    assert r.source == "bmd" and len(r.frames) == 1
    f = r.frames[0]
    # "Frame 0 Metadata": aperture T2.3, focal_length 50mm, distance 991mm; no timecode key
    assert (f.tstop, f.focal_length_mm, f.focus_mm, f.timecode) == (2.3, 50.0, 991.0, None)
    assert r.frame_rate == 48 and r.squeeze == 2.0 and r.shutter_angle_deg == 180  # sensor_rate 48,1; 2x; 180°
    assert r.lens_model == "Cooke Anamorphic /i Prime Lens 50mm"


def test_mosys_f4_first_and_last_packet():
    r = load(MOSYS)
    assert r.source == "mosys"
    assert len(r.frames) == MOSYS.stat().st_size // 105  # 20 axes: 4 + 20 x 5 + 1 = 105 bytes a packet
    a, z = r.frames[0], r.frames[-1]
    # first packet (xxd): f8 20 3c 3b c2 -> 25 fps (bits 5-6 of 0x20), 15:03:47:02; 57 3e dd 50 23: 1/focus
    assert a.timecode == "15:03:47:02" and r.frame_rate == 25
    assert a.focus_mm == pytest.approx(1000 / f32("3edd5023"))
    # 01 00 ff f4 29: pan 0xfff429 - 2^24 = -3031 -> -3.031 deg; 05 00 ff e0 93: x -8045 / 1000
    assert a.tracker.rotation_deg[0] == pytest.approx(-3.031) and a.tracker.translation[0] == pytest.approx(-8.045)
    assert a.tracker.status == "Optical Good"
    assert (a.tstop, a.fstop, a.focal_length_mm) == (None, None, None)  # F4 sends none of them here
    # last packet: f8 20 3c 4b 97 -> 15:04:46:23; 57 3f 01 90 79
    assert z.timecode == "15:04:46:23" and z.focus_mm == pytest.approx(1000 / f32("3f019079"))
    counts = [timecode_frames(f.timecode, 25) for f in r.frames]
    assert counts == list(range(counts[0], counts[0] + len(counts)))


@pytest.mark.parametrize("files, fmt", [([ARRI], "arri"), (RED, "red"), (VENICE, "venice"), (CANON, "canon"),
                                        ([BMD], "bmd"), ([MOSYS], "mosys")])
def test_format_is_told_by_content_not_name(tmp_path, files, fmt):
    renamed = []
    for i, f in enumerate(files):
        p = tmp_path / f"clip{i}.dat"
        p.write_bytes(f.read_bytes())
        renamed.append(p)
    assert detect(renamed) == fmt
    assert len(load(renamed).frames) == len(load(files).frames)


def test_units_are_millimetres_everywhere():
    for files in ([ARRI], RED, VENICE, CANON, [BMD], [MOSYS]):
        r = load(files)
        for f in r.frames:
            # 10 cm to 100 m, in mm (the F4 inverse focus near 0 at an infinity rack reads farther: lower bound only)
            far = math.inf if r.source == "mosys" else 100_000
            assert f.focus_mm is None or 100 < f.focus_mm < far, (r.source, f)
            assert f.focal_length_mm is None or 5 < f.focal_length_mm < 500


# ---- bad input: one sentence with the file and the line ---------------------------------------
def _arri_lines():
    return ARRI.read_text(encoding="utf-8").splitlines(keepends=True)


def test_truncated_csv_names_its_line(tmp_path):
    lines = _arri_lines()
    p = tmp_path / "cut.csv"
    p.write_text("".join(lines[:10]) + lines[10][:200])  # the 11th line cut mid-row
    with pytest.raises(MetadataError) as e:
        load(p)
    assert e.value.line == 11 and str(e.value).startswith(f"{p}:11: ") and "truncated" in str(e.value)


def test_unknown_layout(tmp_path):
    p = tmp_path / "x.csv"
    p.write_text("Frame,Focus,Iris\n1,2,3\n")
    with pytest.raises(MetadataError, match=r"x\.csv:1: unknown column layout"):
        load(p)


def test_a_binary_that_is_not_f4(tmp_path):
    p = tmp_path / "x.f4"
    p.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(MetadataError, match="not a Mo-Sys F4 recording"):
        load(p)
    q = tmp_path / "cut.f4"  # a real recording cut inside its third packet
    q.write_bytes(MOSYS.read_bytes()[:2 * 105 + 50])
    with pytest.raises(MetadataError, match=r"byte 210: the file is truncated"):
        load(q)


def test_feet_where_metres_were_expected(tmp_path):
    lines = _arri_lines()
    header = lines[0].rstrip("\n").split("\t")
    row = lines[5].rstrip("\n").split("\t")
    row[header.index("Lens Focus Distance")] = "15'9\""
    p = tmp_path / "ft.csv"
    p.write_text("".join(lines[:5]) + "\t".join(row) + "\n")
    with pytest.raises(MetadataError) as e:
        load(p)
    assert e.value.line == 6 and "feet and inches where the Lens Distance Unit says metres" in str(e.value)


def test_arri_in_feet_is_converted(tmp_path):
    lines = _arri_lines()
    header = lines[0].rstrip("\n").split("\t")
    i_unit, i_focus = header.index("Lens Distance Unit"), header.index("Lens Focus Distance")
    rows = []
    for text, focus in ((lines[1], "15'9\""), (lines[2], "15.75")):
        row = text.rstrip("\n").split("\t")
        row[i_unit], row[i_focus] = "Feet", focus
        rows.append("\t".join(row) + "\n")
    p = tmp_path / "ft.csv"
    p.write_text(lines[0] + "".join(rows))
    r = load(p)
    assert [f.focus_mm for f in r.frames] == pytest.approx([15.75 * FT, 15.75 * FT])


def test_errors_are_physcam_errors():
    assert issubclass(MetadataError, PhysCamError)
    with pytest.raises(MetadataError):
        detect_file(D / "does-not-exist.csv")


def _resaved(src: Path, dst: Path, quoting, drop: str | None = None) -> Path:
    """``src`` read as CSV and written again as a spreadsheet would, with other quoting (and without ``drop``)."""
    import csv

    rows = list(csv.reader(src.read_text(encoding="utf-8-sig").splitlines()))
    keep = [i for i, h in enumerate(rows[0]) if h != drop]
    with dst.open("w", encoding="utf-8", newline="") as fh:
        csv.writer(fh, quoting=quoting, lineterminator="\n").writerows([[r[i] for i in keep] for r in rows])
    return dst


def test_a_csv_saved_again_with_other_quoting_reads_the_same_frames(tmp_path):
    """VENICE quotes every cell, REDline none: a spreadsheet's save swaps that, and the clip is the same."""
    import csv

    for src, others, quoting, name in ((VENICE[0], VENICE[1:], csv.QUOTE_MINIMAL, "v.csv"),
                                       (RED[0], RED[1:], csv.QUOTE_ALL, "r.frames.csv"),
                                       (CANON[0], CANON[1:], csv.QUOTE_ALL, "c_Frames.csv")):
        again, original = load([_resaved(src, tmp_path / name, quoting), *others]), load([src, *others])
        assert again.frames == original.frames and len(again.frames) > 0


@pytest.mark.parametrize("src, column", [(VENICE[0], "Focus Distance (ft)"), (VENICE[0], "Aperture"),
                                         (RED[0], "Focus Distance"), (CANON[0], "FocusPosition")])
def test_a_missing_column_is_named(tmp_path, src, column):
    import csv

    p = _resaved(src, tmp_path / ("cut_Frames.csv" if src in CANON else "cut.frames.csv"), csv.QUOTE_MINIMAL, column)
    with pytest.raises(MetadataError, match=r"cut.*:1: the header looks like .* but has no '" +
                       column.split(" (")[0]):
        load(p)


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be"])
def test_a_clip_saved_as_utf16_reads_as_its_utf8_export(tmp_path, encoding):
    """A TD's VENICE CSV and XML re-saved as "Unicode text" (UTF-16 with a byte-order mark) were "a
    binary file that is not a Mo-Sys F4 recording" (round 8). Oracle: the camera's own UTF-8 files."""
    copies = []
    for f in VENICE:
        text = f.read_text(encoding="utf-8-sig")
        c = tmp_path / f.name
        c.write_bytes((b"\xfe\xff" if encoding.endswith("be") else b"") + text.encode(encoding))
        copies.append(c)
    assert detect_file(copies[0]) == detect_file(VENICE[0]) and detect_file(copies[1]) == detect_file(VENICE[1])
    got, want = load(copies), load(VENICE)
    assert got.frame_rows() == want.frame_rows()
    assert {k: v for k, v in got.static_dict().items() if k != "files"} == \
        {k: v for k, v in want.static_dict().items() if k != "files"}
