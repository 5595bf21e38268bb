"""The clip as an animated USD camera, OpenTrackIO samples and CLI output (issue 30)."""

from __future__ import annotations

import json

import pytest

from physcam.cli import main
from physcam.metadata import load

from test_metadata_readers import ARRI, CANON, MOSYS, RED, VENICE

FT = 304.8


def _samples(attr):
    return {t: attr.Get(t) for t in attr.GetTimeSamples()}


def test_arri_usd_has_one_time_sample_per_frame_with_the_files_focus_and_tstop(tmp_path, capsys):
    """Authored on the plate's frame numbers (issue 40 item 6): plate frame 1001 + t holds the file's
    row t (its focus in metres x 1000, its Lens Linear Iris as 2^((L - 1000) / 2000), its Master TC);
    the stage's start and end time codes are the plate range."""
    pytest.importorskip("pxr")
    from pxr import Usd

    out = tmp_path / "shot.usda"
    assert main(["metadata", "usd", str(ARRI), "-o", str(out), "--plate", "plates/B001C001.####.exr",
                 "--plate-frames", "1001-1500"]) == 0
    stage = Usd.Stage.Open(str(out))
    focus = _samples(stage.GetPrimAtPath("/Cameras/Camera/Pinhole").GetAttribute("focusDistance"))
    tstop = _samples(stage.GetPrimAtPath("/Cameras/Camera/Camera").GetAttribute("exposure:fStop"))
    tc = _samples(stage.GetPrimAtPath("/Cameras/Camera").GetAttribute("physcam:live:timecode"))
    assert sorted(focus) == sorted(tstop) == [float(1001 + i) for i in range(500)]  # one sample per row
    assert (stage.GetStartTimeCode(), stage.GetEndTimeCode()) == (1001.0, 1500.0)
    rows = ARRI.read_text(encoding="utf-8").splitlines()
    header = rows[0].split("\t")
    i_focus, i_iris, i_tc = header.index("Lens Focus Distance"), header.index("Lens Linear Iris"), header.index("Master TC")
    for t in range(500):
        cells = rows[t + 1].split("\t")
        assert focus[1001 + t] == pytest.approx(float(cells[i_focus]) * 1000, rel=1e-6)  # metres in the file, mm in USD
        assert tstop[1001 + t] == pytest.approx(2 ** ((int(cells[i_iris]) - 1000) / 2000), rel=1e-6)
        assert tc[1001 + t] == cells[i_tc]
    attr = stage.GetPrimAtPath("/Cameras/Camera/Pinhole").GetAttribute("focusDistance")
    assert attr.Get(1001) == pytest.approx(4812.0) and attr.Get(1500) == pytest.approx(3056.0)  # rows 1 and 500
    plate = stage.GetPrimAtPath("/Cameras/Camera").GetCustomDataByKey("physcam:plate")
    assert dict(plate) == {"path": "plates/B001C001.####.exr", "firstFrame": 1001, "lastFrame": 1500}
    assert stage.GetTimeCodesPerSecond() == 24


def test_tracker_pose_reaches_usd(tmp_path):
    pytest.importorskip("pxr")
    from pxr import Usd

    out = tmp_path / "track.usda"
    assert main(["metadata", "usd", str(MOSYS), "-o", str(out), "--fstop", "2.8", "--focal", "25",
                 "--sensor", "S35"]) == 0
    stage = Usd.Stage.Open(str(out))
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    rot = cam.GetAttribute("xformOp:rotateZXY")
    r0 = rot.Get(0.0)
    rec = load(MOSYS)
    pan, tilt, roll = rec.frames[0].tracker.rotation_deg
    assert tuple(r0) == pytest.approx((tilt, pan, -roll), abs=1e-4)  # live.record's rotateZXY convention
    assert len(rot.GetTimeSamples()) == len(rec.frames)


def test_opentrackio_output_validates_and_keeps_the_values(tmp_path):
    pytest.importorskip("jsonschema")
    from physcam.live.sample import validate_sample

    out = tmp_path / "red.jsonl"
    assert main(["metadata", "opentrackio", *map(str, RED), "-o", str(out)]) == 0
    samples = [json.loads(line) for line in out.read_text().splitlines()]
    assert len(samples) == 2
    for s in samples:
        validate_sample(s)
    a = samples[0]
    assert a["lens"]["focusDistance"] == pytest.approx(0.410)  # frames.csv line 2: 410 mm
    assert a["lens"]["tStop"] == 5.6 and a["lens"]["entrancePupilOffset"] == pytest.approx(0.127)
    assert a["timing"]["timecode"] == {"hours": 23, "minutes": 17, "seconds": 21, "frames": 8,
                                       "frameRate": {"num": 24, "denom": 1}}
    assert a["static"]["lens"]["serialNumber"] == "G53599764"


def test_opentrackio_of_every_source_validates(capsys):
    pytest.importorskip("jsonschema")
    for files in ([ARRI], VENICE, CANON, [MOSYS]):
        fps = [] if files == [MOSYS] else ["--fps", "24"]  # the F4 recording is 25 fps: --fps 24 would contradict it
        assert main(["metadata", "opentrackio", *map(str, files), *fps]) == 0
        lines = capsys.readouterr().out.splitlines()
        assert len(lines) == len(load(files).frames)


def test_report_thin_lens_matches_the_closed_form(capsys):
    """Frame 0 of the RED clip: focus 410 mm, f/5.6, 40 mm, on its 20.48 mm wide area; near and far
    from the thin-lens formulas s(H - f)/(H + s - 2f) and s(H - f)/(H - s) with H = f^2/(N c) + f,
    the distances from the lens (the report's from the film: s = D - image distance, D = 410)."""
    assert main(["metadata", "report", *map(str, RED), "--json", "--coc", "0.02"]) == 0
    d = json.loads(capsys.readouterr().out)
    row = d["frames"][0]
    f, n, c, D = 40.0, 5.6, 0.02, 410.0
    # thin lens: object distance s and image distance v with s + v = D and 1/s + 1/v = 1/f
    s = (D + (D * D - 4 * f * D) ** 0.5) / 2
    v = D - s
    H = f * f / (n * c) + f
    near = s * (H - f) / (H + s - 2 * f)
    far = s * (H - f) / (H - s)
    assert row["near_from_film_mm"] == pytest.approx(near + v, rel=1e-6)
    assert row["far_from_film_mm"] == pytest.approx(far + v, rel=1e-6)
    assert d["model"] == "thin lens" and d["sensor_mm"] == pytest.approx([20.48, 10.8])


def test_report_with_a_lens_breathes(capsys):
    assert main(["metadata", "report", *map(str, RED), "--lens", "sonnar_50mm_f1_5", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["frames"]
    assert rows[0]["hfov_deg"] != rows[1]["hfov_deg"]  # 410 and 420 mm: the field of view changes with focus


@pytest.mark.parametrize("argv, where", [
    (["metadata", "show", "{tmp}/cut.csv"], "cut.csv:3: "),
    (["metadata", "show", "{tmp}/x.bin"], "x.bin: byte 0: "),
    (["metadata", "report", "{tmp}/layout.csv"], "layout.csv:1: unknown column layout"),
])
def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys, argv, where):
    lines = ARRI.read_text(encoding="utf-8").splitlines(keepends=True)
    (tmp_path / "cut.csv").write_text("".join(lines[:2]) + lines[2][:300])
    (tmp_path / "x.bin").write_bytes(b"\x00\xff" * 300)
    (tmp_path / "layout.csv").write_text("a,b\n1,2\n")
    assert main([a.format(tmp=tmp_path) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("physcam: error: ") and where in err


def test_show_csv_rows_equal_json_rows(capsys):
    assert main(["metadata", "show", str(CANON[0]), str(CANON[1]), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["frames"][0]["focus_mm"] == 500.0 and d["clip"]["frame_count"] == 1
    assert main(["metadata", "show", str(CANON[0]), "--csv"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("frame,line,timecode,focus_mm,tstop") and len(out) == 2


def test_a_clip_without_a_name_is_titled_without_a_gap(capsys):
    """Canon's per-frame file alone names no clip: the report's title read "canon clip : a thin lens ..."
    (round 8). Its static file names it A001C001 (its ShotNumber column)."""
    assert main(["metadata", "report", str(CANON[0]), "--sensor", "S35"]) == 0
    assert capsys.readouterr().out.startswith("canon clip: a thin lens of the recorded focal length")
    assert main(["metadata", "report", *map(str, CANON), "--sensor", "S35"]) == 0
    assert capsys.readouterr().out.startswith("canon clip A001C001: a thin lens")


def test_a_clips_notes_are_one_per_kind(capsys):
    """The ARRI clip's 500 frames gave 21 diffraction notes that differed only in the working f-number
    (round 8: a TD's JSON, and the table's "and 19 more notes"). Oracle: the per-frame reports'
    own notes, read again here: one note per kind, the first frame's, counting the versions."""
    from physcam.cli.metadata import clip_notes
    from physcam.metadata.convert import solve
    from physcam.optics.sensors import find_sensor

    solved = solve(load([ARRI]), sensor=find_sensor("S35"))
    per_frame = [x.report.notes for x in solved]
    notes = clip_notes(per_frame)
    diffraction = [n for n in notes if n.startswith("diffraction")]
    versions = {n for f in per_frame for n in f if n.startswith("diffraction")}
    assert len(diffraction) == 1 and len(versions) > 1
    assert diffraction[0].startswith(per_frame[0][[n.startswith("diffraction") for n in per_frame[0]].index(True)])
    assert f"{len(versions)} versions of this note on {len(solved)} frames" in diffraction[0]
    assert clip_notes([("a note", "b 1.5"), ("a note", "b 1.5")]) == ["a note", "b 1.5"]
