"""An anamorphic's two entrance pupils in OpenTrackIO and the LED-wall frustum (issue 49).

Oracles: the hand y-u trace of each meridian (tests/_anamorphic_yu.py) for the pupils a take sends;
for the frustum, rays written out here from the two-pupil projection (docs/anamorphic.md): a subject
point lands at horizontal tangent X / (s - e_x) and vertical tangent Y / (s - e_y), s its depth in
front of the film, so the frame's edge at tangents (t_u, t_v) is reached where the wall meets
film + right t_u (s - e_x) + forward s + up t_v (s - e_y), solved for s by hand on a flat wall."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physcam.errors import PhysCamWarning
from physcam.lens.library import load_lens
from physcam.live.camera import camera_samples
from physcam.live.frames import HORIZONTAL_PUPIL_KEY, TrackedFrame, frame_from_sample, sample_from_frame
from physcam.live.frustum import frustum_frames, wall_from_usd, write_frustum_usd, write_wall
from physcam.live.sample import validate_sample
from physcam.optics.sensors import find_sensor

from _anamorphic_yu import hand_framing_focal_lengths, hand_pupils_from_film

W, H, F_PIN, SQ = 24.89, 18.66, 50.0, 2.0  # mm, squeeze
EX, EY = 172.48, 140.39  # mm in front of the film: a front anamorphic's pan and tilt pivots
FILM = (0.4, -0.3, 2.2)  # m, OpenTrackIO stage (Z up, Y toward the wall)
D = 6.0  # the flat wall's plane y = D (m)


def _r(pan, tilt, roll):
    """Rz(pan) Rx(tilt) Ry(roll) by the right-hand rule, as tests/live/test_frustum.py writes it."""
    p, t, r = map(math.radians, (pan, tilt, roll))
    rz = np.array([[math.cos(p), -math.sin(p), 0], [math.sin(p), math.cos(p), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, math.cos(t), -math.sin(t)], [0, math.sin(t), math.cos(t)]])
    ry = np.array([[math.cos(r), 0, math.sin(r)], [0, 1, 0], [-math.sin(r), 0, math.cos(r)]])
    return rz @ rx @ ry


def _hand_point(tu, tv, pose):
    """Where the frame's point at tangents (tu, tv) meets the plane y = D (stage metres)."""
    R = _r(*pose)
    right, fwd, up = R[:, 0], R[:, 1], R[:, 2]
    ex, ey = EX / 1000.0, EY / 1000.0
    # film_y + right_y tu (s - ex) + fwd_y s + up_y tv (s - ey) = D, linear in s
    a = right[1] * tu + fwd[1] + up[1] * tv
    s = (D - FILM[1] + right[1] * tu * ex + up[1] * tv * ey) / a
    return np.array(FILM) + right * tu * (s - ex) + fwd * s + up * tv * (s - ey)


def _to_usd_cm(p):
    return np.array([p[0], p[2], -p[1]]) * 100.0


@pytest.mark.parametrize("pose", [(0.0, 0.0, 0.0), (10.0, 5.0, -4.0)])
def test_left_right_edges_from_the_x_pupil_top_bottom_from_the_y_pupil(tmp_path, pose):
    wall = wall_from_usd(write_wall(tmp_path / "flat.usda", kind="flat", width_m=60, height_m=40, distance_m=D))
    frame = TrackedFrame(translation_m=FILM, rotation_deg=pose, pinhole_focal_length_mm=F_PIN, sensor_mm=(W, H),
                         squeeze=SQ, entrance_pupil_mm=EY, entrance_pupil_horizontal_mm=EX)
    fr = frustum_frames([frame], wall, overscan=0.0, samples_per_edge=4)[0]
    tl, tr, tb, tt = -SQ * W / 2 / F_PIN, SQ * W / 2 / F_PIN, -H / 2 / F_PIN, H / 2 / F_PIN
    s = (np.linspace(-1.0, 1.0, 5)[:-1] + 1.0) / 2.0  # the edge's samples, counter-clockwise from bottom-left
    uv = np.concatenate([np.c_[tl + s * (tr - tl), np.full(4, tb)], np.c_[np.full(4, tr), tb + s * (tt - tb)],
                         np.c_[tr - s * (tr - tl), np.full(4, tt)], np.c_[np.full(4, tl), tt - s * (tt - tb)]])
    hand = np.array([_to_usd_cm(_hand_point(u, v, pose)) for u, v in uv])
    assert fr.missed == 0
    assert np.allclose(fr.footprint, hand, atol=1e-3)  # 0.01 mm
    if pose == (0.0, 0.0, 0.0):  # by hand: the footprint is 2 t_r (D - e_x) wide and 2 t_t (D - e_y) tall
        width = fr.footprint[:, 0].max() - fr.footprint[:, 0].min()
        height = fr.footprint[:, 1].max() - fr.footprint[:, 1].min()
        assert width == pytest.approx(2 * tr * (D - FILM[1] - EX / 1000) * 100, abs=1e-6)
        assert height == pytest.approx(2 * tt * (D - FILM[1] - EY / 1000) * 100, abs=1e-6)
    one = frustum_frames([TrackedFrame(translation_m=FILM, rotation_deg=pose, pinhole_focal_length_mm=F_PIN,
                                       sensor_mm=(W, H), squeeze=SQ, entrance_pupil_mm=EY)], wall, overscan=0.0,
                         samples_per_edge=4)[0]
    # one pupil at the Y one misses the left and right edges by t_u (e_x - e_y): 33 mm x 0.5 at 6 m
    assert np.abs(one.footprint - fr.footprint).max() > 1.0  # cm
    out = write_frustum_usd(tmp_path / "f.usda", [fr], meters_per_unit=0.01, fps=24.0)
    from pxr import Usd

    stage = Usd.Stage.Open(str(out))
    px = stage.GetPrimAtPath("/Frustum/Footprint").GetAttribute("physcam:frustum:horizontalPupil")
    assert np.allclose(np.array(px.Get(0.0)), fr.pupil_horizontal)


def test_a_take_sends_both_pupils_the_standard_field_the_vertical_one():
    lens = load_lens("neil_front_anamorphic_2x")
    # the patent's lens covers less than the ALEXA 35's open gate: each frame says so (its real field)
    with pytest.warns(PhysCamWarning, match="outside the lens's image circle"):
        samples = camera_samples(sensor=find_sensor("ALEXA 35"), frames=3, rate=24, focus_mm=3000.0,
                                 focus_to_mm=1500.0, lens=lens, distortion=False, t0_ns=0)
    for s, mark in zip(samples, (3000.0, 2250.0, 1500.0)):
        validate_sample(s)  # OpenTrackIO 1.0.1's schema: the top-level custom object is allowed
        x, y = hand_pupils_from_film("neil_front_anamorphic_2x", mark)
        assert s["lens"]["entrancePupilOffset"] == pytest.approx(y / 1000.0, abs=1e-5)
        assert s["custom"][HORIZONTAL_PUPIL_KEY] == pytest.approx(x / 1000.0, abs=1e-5)
        assert x - y > 20.0  # a front anamorphic's pan pivot lies nearer the subject
        f = frame_from_sample(s)
        assert f.entrance_pupil_horizontal_mm == pytest.approx(s["custom"][HORIZONTAL_PUPIL_KEY] * 1000.0)
        back = sample_from_frame(f, source_id=s["sourceId"], sequence_number=0)
        assert back["custom"] == s["custom"]
    spherical = camera_samples(sensor=find_sensor("ALEXA 35"), frames=1, rate=24, focus_mm=3000.0,
                               lens=load_lens("dgauss_50mm"), distortion=False, t0_ns=0)[0]
    assert "custom" not in spherical and frame_from_sample(spherical).entrance_pupil_horizontal_mm is None


def test_a_bad_custom_pupil_is_refused_with_its_name():
    from physcam.errors import InputError

    s = sample_from_frame(TrackedFrame(entrance_pupil_mm=100.0, entrance_pupil_horizontal_mm=120.0),
                          source_id="urn:uuid:00000000-0000-0000-0000-000000000000", sequence_number=0)
    s["custom"][HORIZONTAL_PUPIL_KEY] = "far"
    with pytest.raises(InputError, match=HORIZONTAL_PUPIL_KEY):
        frame_from_sample(s)


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_a_recorded_take_keeps_both_pupils_in_usd_and_reads_them_back(tmp_path):
    from pxr import Usd

    from physcam.live.record import lens_report_rows, solve_frames, write_recording_usd
    from physcam.live.usd_io import frames_from_usd
    from physcam.usd.validate import validation_errors

    slug, marks = "neil_front_anamorphic_2x", (3000.0, 2250.0, 1500.0)
    samples = camera_samples(sensor=find_sensor("ALEXA 35"), frames=3, rate=24, focus_mm=3000.0, focus_to_mm=1500.0,
                             lens=load_lens(slug), distortion=False, t0_ns=0)
    # the third sample leaves the horizontal pupil out: it is carried over from the second, as the others are
    del samples[2]["custom"]
    solved = solve_frames([frame_from_sample(s) for s in samples])
    assert HORIZONTAL_PUPIL_KEY in solved[2].carried and HORIZONTAL_PUPIL_KEY not in solved[1].carried
    out = write_recording_usd(tmp_path / "take.usda", solved)
    stage = Usd.Stage.Open(str(out))
    assert validation_errors(stage) == []
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    a_x, a_y = cam.GetAttribute("lens:main:horizontalEntrancePupilDistance"), cam.GetAttribute(
        "lens:main:entrancePupilDistance")
    sent = [hand_pupils_from_film(slug, m) for m in marks[:2]]
    expected = [sent[0], sent[1], (sent[1][0], hand_pupils_from_film(slug, marks[2])[1])]
    times = [s.time_code for s in solved]
    for t, (x, y), row in zip(times, expected, lens_report_rows(solved)):
        assert a_x.Get(t) == pytest.approx(x, abs=0.02) and a_y.Get(t) == pytest.approx(y, abs=0.02)
        assert row["entrance_pupil_horizontal_from_film_mm"] == pytest.approx(x, abs=0.02)
    back = frames_from_usd(out)
    assert [f.entrance_pupil_horizontal_mm for f in back] == pytest.approx([x for x, _ in expected], abs=0.02)


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_a_spherical_take_records_no_second_pupil(tmp_path):
    from pxr import Usd

    from physcam.live.record import solve_frames, write_recording_usd

    samples = camera_samples(sensor=find_sensor("ALEXA 35"), frames=2, rate=24, focus_mm=3000.0,
                             lens=load_lens("dgauss_50mm"), distortion=False, t0_ns=0)
    out = write_recording_usd(tmp_path / "take.usda", solve_frames([frame_from_sample(s) for s in samples]))
    stage = Usd.Stage.Open(str(out))
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    assert cam.GetAttribute("lens:main:entrancePupilDistance").HasAuthoredValue()
    assert not cam.GetAttribute("lens:main:horizontalEntrancePupilDistance").HasAuthoredValue()


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_a_focus_pull_sends_the_breathing_of_each_axis():
    """OpenTrackIO's pinholeFocalLength is the vertical framing focal length; anamorphicSqueeze, re-sent
    in the static block whenever it changes, makes pinholeFocalLength / squeeze the horizontal one: both
    breathe as the hand trace of each meridian says (42.03 -> 41.49 mm and 21.02 -> 20.52 mm, 3 m -> 1.5 m)."""
    from fractions import Fraction

    slug, marks = "neil_front_anamorphic_2x", (3000.0, 2250.0, 1500.0)
    samples = camera_samples(sensor=find_sensor("ALEXA 35"), frames=3, rate=24, focus_mm=3000.0, focus_to_mm=1500.0,
                             lens=load_lens(slug), distortion=False, t0_ns=0)
    squeezes = []
    for s, mark in zip(samples, marks):
        validate_sample(s)
        sq = s["static"]["camera"]["anamorphicSqueeze"]  # a new squeeze each frame: re-sent each frame
        squeezes.append(float(Fraction(sq["num"], sq["denom"])))
        fx, fy = hand_framing_focal_lengths(slug, mark)
        assert s["lens"]["pinholeFocalLength"] == pytest.approx(fy, rel=1e-6)
        assert s["lens"]["pinholeFocalLength"] / squeezes[-1] == pytest.approx(fx, rel=1e-5)
    assert squeezes[0] < squeezes[1] < squeezes[2]  # the horizontal shortens faster as the lens focuses close
