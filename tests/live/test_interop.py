"""What virtual-production consumers read from physcam's stream (issue 31).

Distortion is decoded with two readers written from their public documentation, not from physcam
(tests/_opentrackio_readers.py: camdkit's conversion note and Unreal's Live Link OpenTrackIO
receiver). Frustum corners are worked by hand on a flat wall; the
anamorphic and breathing values come from ``physcam lens breathing``; timecodes from SMPTE ST 12-1's
drop-frame rule (107,892 labels an hour at 29.97).
"""

from __future__ import annotations

import json
import math
from fractions import Fraction

import numpy as np
import pytest

from physcam.cli import main
from physcam.errors import InputError
from physcam.lens.library import load_lens
from physcam.live.camera import camera_samples
from physcam.live.frames import TrackedFrame, frame_from_sample, timecode_fields
from physcam.live.frustum import frustum_frames, wall_from_usd, write_wall
from physcam.live.record import lens_report_rows, solve_frames, write_recording_usd
from physcam.live.sample import decode_sample, encode_sample, sample_problems
from physcam.live.usd_io import frames_from_usd
from physcam.optics.sensors import find_sensor

from _opentrackio_readers import camdkit_reader, opencv_rational, unreal_reader

S35 = find_sensor("Super 35")
WIDTH_PX = 4096


# --- independent readers (tests/_opentrackio_readers.py) -------------------------------------------
def _corners(w, h, f):
    return np.array([[w / 2, h / 2], [-w / 2, h / 2], [w / 2, -h / 2], [-w / 2, -h / 2]]) / f


def _physcam_fit(lens, focus_mm):
    """physcam's own distortion model of the lens at this focus (OpenCV form, normalised by F_y)."""
    from physcam.analysis.distortion.models import fit_brown_conrady, samples_from_field
    from physcam.analysis.distortion.stmap import distortion_field
    from physcam.optics.state import camera_state

    h_px = round(WIDTH_PX * S35.height_mm / S35.width_mm)
    camera = camera_state(lens, focus_mm=focus_mm, sensor_mm=(S35.width_mm, S35.height_mm))
    field = distortion_field(camera, width_px=WIDTH_PX, height_px=h_px, maps=False)
    c = fit_brown_conrady(samples_from_field(field), "U-D", max_residual_px=math.inf).coefficients
    return [c["k1"], c["k2"], c["k3"], 0.0, 0.0, 0.0], c["fy_mm"]


@pytest.mark.parametrize("name,focus_mm", [("dgauss_50mm", 2000.0), ("zeiss_distagon_35mm_f4", 2000.0)])
@pytest.mark.parametrize("reader", [camdkit_reader, unreal_reader], ids=["camdkit", "unreal"])
def test_both_readers_get_physcams_distortion_at_the_4k_corners(name, focus_mm, reader):
    lens = load_lens(name)
    sample = decode_sample(encode_sample(camera_samples(sensor=S35, frames=1, rate=24, focus_mm=focus_mm,
                                                        lens=lens)[0]))
    dist, f = sample["lens"]["distortion"][0], sample["lens"]["pinholeFocalLength"]
    assert dist["model"] == "Brown-Conrady U-D"
    own_k, f_own = _physcam_fit(lens, focus_mm)
    xy = _corners(S35.width_mm, S35.height_mm, f_own)
    px = WIDTH_PX / S35.width_mm  # pixels per mm on the sensor
    own = opencv_rational(xy, own_k) * f_own * px
    theirs = opencv_rational(xy * f_own / f, reader(dist, f)) * f * px
    # the corner moves by pixels (so a reader that reads nothing fails), and both land within 0.1 px
    assert np.abs(own - xy * f_own * px).max() > 2.0
    assert np.abs(theirs - own).max() < 0.1


# --- anamorphic and shifted lenses: send -> record -> frustum -----------------------------------
def _send(tmp_path, capsys, *args):
    capsys.readouterr()
    assert main(["live", "send", "--frames", "1", "--print", *args]) == 0
    return [decode_sample(line.encode()) for line in capsys.readouterr().out.splitlines()]


def _record(tmp_path, samples, **kw):
    static = None
    frames = []
    for s in samples:
        static = s.get("static") or static
        frames.append(frame_from_sample(s, static=static))
    solved = solve_frames(frames, **kw)
    usd = write_recording_usd(tmp_path / "take.usda", solved)
    return solved, frames_from_usd(usd)


def _lens_breathing(capsys, name, focus):
    capsys.readouterr()
    assert main(["lens", "breathing", "--lens", name, "--focus", focus, "--json"]) == 0
    return json.loads(capsys.readouterr().out)["rows"][0]


def _flat_wall_corners(tmp_path, frames, **kw):
    wall = write_wall(tmp_path / "wall.usda", kind="flat", width_m=400.0, height_m=400.0, distance_m=6.0,
                      force=True)
    fr = frustum_frames(frames, wall_from_usd(wall), samples_per_edge=1, **kw)[0]
    return fr.footprint * 0.01  # cm -> m, USD Y-up (x, z_otio, -y_otio)


def _hand_corners(pupil_y_m, film_z_m, tan_u, tan_v):
    """Where the corner rays from a pupil at (0, pupil_y, film_z) looking along +Y meet the plane y = 6 m,
    in USD's Y-up metres: bottom-left, bottom-right, top-right, top-left."""
    d = 6.0 - pupil_y_m
    pts = [(tan_u[0], tan_v[0]), (tan_u[1], tan_v[0]), (tan_u[1], tan_v[1]), (tan_u[0], tan_v[1])]
    return np.array([[d * u, film_z_m + d * v, -6.0] for u, v in pts])


def test_an_anamorphic_keeps_its_horizontal_view_through_send_record_frustum(tmp_path, capsys):
    samples = _send(tmp_path, capsys, "--lens", "navarro_anamorphic_2x", "--focus", "3m")
    oracle = _lens_breathing(capsys, "navarro_anamorphic_2x", "3m")
    sq = samples[0]["static"]["camera"]["anamorphicSqueeze"]
    squeeze = sq["num"] / sq["denom"]
    f = samples[0]["lens"]["pinholeFocalLength"]
    # a consumer's horizontal focal length F / squeeze is lens breathing's
    assert f / squeeze == pytest.approx(oracle["breathing_focal_length_mm"], rel=1e-5)
    solved, frames = _record(tmp_path, samples)
    row = lens_report_rows(solved)[0]
    assert row["hfov_deg"] == pytest.approx(oracle["hfov_deg"], abs=0.01)
    assert frames[0].squeeze == pytest.approx(squeeze, rel=1e-6)
    got = _flat_wall_corners(tmp_path, frames, overscan=0.0)
    w, h = S35.width_mm, S35.height_mm
    pupil = oracle["entrance_pupil_from_film_mm"] / 1000.0
    tan_half_h = math.tan(math.radians(oracle["hfov_deg"] / 2))
    hand = _hand_corners(pupil, 1.5, (-tan_half_h, tan_half_h), (-h / 2 / f, h / 2 / f))
    assert np.abs(got - hand).max() < 1e-3  # 1 mm on the wall
    assert w * squeeze / 2 / f == pytest.approx(tan_half_h, rel=1e-5)


def test_a_shifted_lens_moves_the_frustum_by_its_offset(tmp_path, capsys):
    samples = _send(tmp_path, capsys, "--lens", "dgauss_50mm", "--focus", "3m", "--shift-x", "1.5",
                    "--shift-y=-0.8")
    lens = samples[0]["lens"]
    # OpenLensIO's perspective offset: where the axis lands, x right, y down; the view moved right and down
    assert lens["projectionOffset"] == {"x": -1.5, "y": -0.8}
    assert lens["distortionOffset"] == {"x": 0.0, "y": 0.0}
    _, frames = _record(tmp_path, samples)
    assert frames[0].projection_offset_mm == pytest.approx((-1.5, -0.8))
    f, pupil = lens["pinholeFocalLength"], lens["entrancePupilOffset"]
    w, h = S35.width_mm, S35.height_mm
    hand = _hand_corners(pupil, 1.5, ((-w / 2 + 1.5) / f, (w / 2 + 1.5) / f), ((-h / 2 - 0.8) / f, (h / 2 - 0.8) / f))
    got = _flat_wall_corners(tmp_path, frames, overscan=0.0)
    assert np.abs(got - hand).max() < 1e-3
    # the shift moves the view by D x shift / F on the wall (0.49 m at x for 1.5 mm here, not 0)
    assert (got[1, 0] + got[0, 0]) / 2 == pytest.approx((6.0 - pupil) * 1.5 / f, rel=1e-6)


def test_record_and_frustum_read_a_streams_squeeze_and_projection_offset(tmp_path):
    """Another tracker's stream (values set by hand, not physcam's sender): squeeze 2 and a projection
    offset of (0.9, -0.6) mm reach the lens report and the wall."""
    sample = camera_samples(sensor=S35, frames=1, rate=24, focus_mm=3000.0, focal_length_mm=50.0, fstop=2.8,
                            distortion=False)[0]
    sample["static"]["camera"]["anamorphicSqueeze"] = {"num": 2, "denom": 1}
    sample["lens"].update(projectionOffset={"x": 0.9, "y": -0.6}, distortionOffset={"x": 0.1, "y": 0.2})
    sample = decode_sample(encode_sample(sample))
    solved, frames = _record(tmp_path, [sample])
    f, pupil = sample["lens"]["pinholeFocalLength"], sample["lens"]["entrancePupilOffset"]
    w, h = S35.width_mm, S35.height_mm
    assert lens_report_rows(solved)[0]["hfov_deg"] == pytest.approx(2 * math.degrees(math.atan(w / f)), abs=1e-4)
    assert frames[0].distortion_offset_mm == pytest.approx((0.1, 0.2))
    hand = _hand_corners(pupil, 1.5, (2 * (-w / 2 - 0.9) / f, 2 * (w / 2 - 0.9) / f),
                         ((-h / 2 - 0.6) / f, (h / 2 - 0.6) / f))
    assert np.abs(_flat_wall_corners(tmp_path, frames, overscan=0.0) - hand).max() < 1e-3


def test_ndisplay_overscan_multiplies_the_angle(tmp_path):
    frame = TrackedFrame(rate=Fraction(24), translation_m=(0.0, 0.0, 5.0), pinhole_focal_length_mm=35.0,
                         focus_from_film_mm=3000.0, fstop=2.8, entrance_pupil_mm=0.0, sensor_mm=(24.89, 18.66))
    half_u, half_v = math.atan(24.89 / 2 / 35.0), math.atan(18.66 / 2 / 35.0)
    got = _flat_wall_corners(tmp_path, [frame], overscan=0.2, overscan_mode="ndisplay")
    hand = _hand_corners(0.0, 5.0, (-math.tan(1.2 * half_u), math.tan(1.2 * half_u)),
                         (-math.tan(1.2 * half_v), math.tan(1.2 * half_v)))
    assert np.abs(got - hand).max() < 1e-6
    tangent = _flat_wall_corners(tmp_path, [frame], overscan=0.2)
    assert tangent[1, 0] == pytest.approx(6.0 * 1.2 * math.tan(half_u), rel=1e-9)
    assert got[1, 0] > tangent[1, 0]


# --- encoders and FIZ tables ----------------------------------------------------------------------
FIZ = "axis,encoder,value\nfocus,0,inf\nfocus,1,0.5\niris,0,2\niris,1,16  # three stops\n"


def _encoder_sample(focus_enc, iris_enc, seq):
    sample = camera_samples(sensor=S35, frames=1, rate=24, focus_mm=3000.0, focal_length_mm=50.0, fstop=2.8)[0]
    sample["lens"] = {"encoders": {"focus": focus_enc, "iris": iris_enc}}
    sample["timing"]["sequenceNumber"] = seq
    del sample["timing"]["sampleTimestamp"]
    return sample


def test_an_encoder_only_stream_records_focus_and_breathing_from_the_fiz_table(tmp_path, capsys):
    from physcam.live.fiz import read_fiz_table

    (tmp_path / "fiz.csv").write_text(FIZ)
    samples = [_encoder_sample(0.5, 1 / 3, 0), _encoder_sample(0.75, 2 / 3, 1)]
    static = samples[0]["static"]
    frames = [frame_from_sample(s, static=static) for s in samples]
    with pytest.raises(InputError, match="pinhole focal length"):
        solve_frames(frames)  # before: no focus, no breathing
    solved = solve_frames(frames, lens=load_lens("dgauss_50mm"), fiz=read_fiz_table(tmp_path / "fiz.csv"))
    rows = lens_report_rows(solved)
    # dioptres: 0 at encoder 0, 2 at encoder 1 -> 1 m at 0.5, 2/3 m at 0.75; stops: f/2 * 2^(3e)
    assert [r["focus_from_film_mm"] for r in rows] == pytest.approx([1000.0, 2000.0 / 3.0])
    assert [r["fstop"] for r in rows] == pytest.approx([4.0, 8.0])
    assert rows[0]["from_encoders"] == ["fStop", "focusDistance"] or set(rows[0]["from_encoders"]) == {
        "fStop", "focusDistance"}
    oracle = _lens_breathing(capsys, "dgauss_50mm", "1m")
    assert rows[0]["pinhole_focal_length_mm"] == pytest.approx(oracle["breathing_focal_length_mm"], rel=1e-6)
    assert rows[0]["entrance_pupil_from_film_mm"] == pytest.approx(oracle["entrance_pupil_from_film_mm"], rel=1e-6)


def test_record_takes_lens_and_fiz_on_the_command_line(tmp_path):
    import argparse

    from physcam.cli import build_parser

    args = build_parser().parse_args(["live", "record", "t.usda", "--lens", "dgauss_50mm", "--fiz", "f.csv"])
    assert isinstance(args, argparse.Namespace) and args.lens == "dgauss_50mm" and args.fiz == "f.csv"


def test_a_bad_fiz_table_names_file_and_line(tmp_path):
    from physcam.live.fiz import read_fiz_table

    p = tmp_path / "fiz.csv"
    p.write_text("axis,encoder,value\nfocus,0,inf\nfocus,1.5,0.5\n")
    with pytest.raises(InputError, match=r"fiz\.csv:3: an encoder is normalised"):
        read_fiz_table(p)
    p.write_text("axis,encoder,value\nfocus,0.2,3\nfocus,0.8,1\n")
    with pytest.raises(InputError, match="outside the calibrated range"):
        read_fiz_table(p).focus_mm(0.9)


# --- focus distance plane ---------------------------------------------------------------------------
def test_unreal_focus_is_measured_from_the_entrance_pupil(capsys):
    from physcam.live.lens_data import focus_for_consumer

    oracle = _lens_breathing(capsys, "dgauss_50mm", "1m")
    pupil = oracle["entrance_pupil_from_film_mm"]
    assert focus_for_consumer(1000.0, pupil) == 1.0  # OpenTrackIO: the mark, metres from the film
    assert focus_for_consumer(1000.0, pupil, "unreal") == pytest.approx((1000.0 - pupil) / 10.0)


# --- timing -----------------------------------------------------------------------------------------
def test_a_timecode_frame_beyond_the_rate_is_refused():
    sample = camera_samples(sensor=S35, frames=1, rate=24, focus_mm=3000.0, focal_length_mm=50.0, fstop=2.8)[0]
    sample["timing"]["timecode"]["frames"] = 24  # the schema allows 0-119; at 24 fps 0-23 exist
    problems = sample_problems(sample)
    assert [(p.path, p.rule) for p in problems] == [("$.timing.timecode.frames", "frameRate")]
    sample["timing"]["timecode"]["frames"] = 23
    assert sample_problems(sample) == []


def test_drop_frame_timecode_follows_smpte_12():
    from physcam.live.frames import parse_timecode

    r = Fraction(30000, 1001)
    label = lambda n: timecode_fields(n, r, drop_frame=True)  # noqa: E731
    assert (label(1800)["minutes"], label(1800)["frames"]) == (1, 2)  # ;00 and ;01 skipped
    assert (label(17982)["minutes"], label(17982)["frames"]) == (10, 0)  # every tenth minute keeps them
    assert label(107892)["hours"] == 1 and label(107891)["hours"] == 0  # 107,892 labels an hour
    assert label(0)["dropFrame"] is True
    assert parse_timecode("01:00:00;00", r) == 107892
    with pytest.raises(InputError, match="skips"):
        parse_timecode("00:01:00;01", r)
    with pytest.raises(InputError, match="drop-frame"):
        timecode_fields(0, 24, drop_frame=True)


def test_send_starts_at_the_given_timecode(tmp_path, capsys):
    samples = _send(tmp_path, capsys, "--focal", "50mm", "--fstop", "2.8", "--fps", "29.97", "--timecode",
                    "01:02:03;04")
    tc = samples[0]["timing"]["timecode"]
    assert (tc["hours"], tc["minutes"], tc["seconds"], tc["frames"], tc["dropFrame"]) == (1, 2, 3, 4, True)
    assert tc["frameRate"] == {"num": 30000, "denom": 1001}


def test_animate_and_record_write_the_same_ntsc_rate(tmp_path):
    from pxr import Usd

    from physcam.usd.animate import FocusKey, write_animated_camera

    out = write_animated_camera(tmp_path / "a.usda", [FocusKey(0, 2000.0), FocusKey(1, 3000.0)], sensor=S35,
                                focal_length_mm=50.0, fstop=2.8, fps=23.976)
    assert Usd.Stage.Open(str(out)).GetTimeCodesPerSecond() == 24000 / 1001
    samples = camera_samples(sensor=S35, frames=2, rate=23.976, focus_mm=3000.0, focal_length_mm=50.0, fstop=2.8)
    _, frames = _record(tmp_path, samples)
    rec = Usd.Stage.Open(str(tmp_path / "take.usda")).GetTimeCodesPerSecond()
    assert rec == Usd.Stage.Open(str(out)).GetTimeCodesPerSecond()
