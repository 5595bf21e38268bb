"""ST-maps into a desqueezed raster (issue 49): ``distortion_field(..., desqueeze=True)`` and
``physcam distortion --stmap DIR --desqueeze``. The undistortion map of an anamorphic plate makes the
round pinhole's picture in square pixels, round(width f_y / f_x) wide, in one STMap.

Oracles: the framing focal lengths of the front 2x traced by hand in each meridian
(tests/_anamorphic_yu.py, a y-u trace from the lens file) for the width; chief rays aimed *forward*
from object points through the stop centre (tests/analysis/_forward_chief.py, independent of the
maps' backward rays, interpolation and inversion) for where each desqueezed pixel takes the plate from.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from _anamorphic_yu import hand_framing_focal_lengths
from _forward_chief import ideal_grid_and_real
from physcam.analysis.distortion.stmap import distortion_field
from physcam.cli import main
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state

LENS = "neil_front_anamorphic_2x"
SENSOR = (18.0, 13.5)  # 4:3, square plate pixels: 640 / 18 = 480 / 13.5 px per mm
W, H = 640, 480
FOCUS = 3000.0


@pytest.fixture(scope="module")
def field():
    return distortion_field(camera_state(load_lens(LENS), focus_mm=FOCUS, sensor_mm=SENSOR),
                            width_px=W, height_px=H, desqueeze=True)


def _bilinear(m, x, y):
    """Map values (n, 2) at continuous array positions (x columns, y rows from the bottom)."""
    h = m.shape[0]
    r = (h - 1) - y  # rows top first
    x0, r0 = np.floor(x).astype(int), np.floor(r).astype(int)
    fx, fr = (x - x0)[:, None], (r - r0)[:, None]
    v = lambda rr, xx: m[rr, xx, :2].astype(float)  # noqa: E731
    return ((1 - fr) * ((1 - fx) * v(r0, x0) + fx * v(r0, x0 + 1)) + fr * ((1 - fx) * v(r0 + 1, x0) + fx * v(r0 + 1, x0 + 1)))


def test_the_desqueezed_width_is_the_hand_traced_squeeze(field):
    fx, fy = hand_framing_focal_lengths(LENS, FOCUS)
    assert 1.9 < fy / fx < 2.1  # the front 2x
    assert abs(field.frame_px[0] - W * fy / fx) <= 0.5 + 1e-6
    assert field.frame_px[1] == H
    ox, oy = field.overscan_px
    assert field.undistortion_stmap.shape[:2] == (H + 2 * oy, field.frame_px[0] + 2 * ox)
    assert field.distortion_stmap.shape[:2] == (H, W)  # the plate's: the redistortion is unchanged
    assert field.to_dict()["desqueeze"] == pytest.approx(field.frame_px[0] / W)


def test_each_desqueezed_pixel_takes_the_plate_from_its_forward_traced_chief_ray(field):
    """The round pinhole's pixel (x', y) of an object point holds the plate where that point's chief ray
    lands: x' is the squeezed pinhole position stretched by frame / width about the centre."""
    ideal, real = ideal_grid_and_real(load_lens(LENS), FOCUS, SENSOR, (W, H))
    fw = field.frame_px[0]
    xd = (ideal[:, 0] - W / 2) * fw / W + fw / 2  # the desqueezed picture's position
    ox, oy = field.overscan_px
    got = _bilinear(field.undistortion_stmap, xd + ox - 0.5, ideal[:, 1] + oy - 0.5) * (W, H)
    # the map's interpolation and inversion (~1e-3 px) and bilinear sampling of a smooth map
    assert np.abs(got - real).max() < 0.02, np.abs(got - real).max()
    assert np.hypot(*(real - ideal).T).max() > 2.0  # the lens distorts: not passing by doing nothing


def test_a_spherical_lens_is_its_own_desqueezed_picture():
    res = distortion_field(camera_state(load_lens("dgauss_50mm"), focus_mm=FOCUS, sensor_mm=(36.0, 24.0)),
                           width_px=96, height_px=64, desqueeze=True)
    assert res.frame_px == (96, 64)
    assert any("not anamorphic" in n for n in res.notes)


def test_the_cli_writes_the_desqueezed_map_and_nuke_script(tmp_path, capsys):
    pytest.importorskip("OpenEXR")
    out = tmp_path / "maps"
    assert main(["distortion", "--lens", LENS, "--sensor-width", "18", "--sensor-height", "13.5", "--focus", "3m",
                 "--resolution", "128x96", "--stmap", str(out), "--desqueeze", "--fit", "nuke", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    fw = doc["undistorted_frame_px"][0]
    assert 250 <= fw <= 262  # 128 x ~2
    nk = (out / "physcam_stmap.nk").read_text()
    assert f"desqueezed from the plate's 128 x 96 to {fw} x 96 square pixels" in nk


def test_desqueeze_without_stmap_is_one_line(capsys):
    assert main(["distortion", "--lens", LENS, "--resolution", "128x96", "--desqueeze"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--desqueeze" in err and "--stmap" in err and len(err.splitlines()) == 1
