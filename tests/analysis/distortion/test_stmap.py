"""ST-maps at a focus (physcam.analysis.distortion.stmap), checked against forward-traced object points.

The oracle (tests/analysis/_forward_chief.py): object points on the plane of sharp focus, each
placed where physcam's best-match pinhole sees a chosen ideal pixel, their chief rays aimed
*forward* through the centre of the stop and traced to the film; independent of the module's
backward chief rays from film points, its interpolation and its inversion.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from physcam.errors import PhysCamError
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state
from _forward_chief import ideal_grid_and_real

W_PX, H_PX = 2048, 1366
SENSOR = (36.0, 24.0)
FOCUS = 2000.0


def _sample(stmap, xy_px, size):
    """Bilinear sample of a map at plate-style pixel positions (n, 2) of an image ``size`` (w, h)."""
    from physcam.analysis.distortion.stmap import apply_stmap

    w, h = size
    probe = np.zeros((1, xy_px.shape[0], 3))
    probe[0, :, 0] = xy_px[:, 0] / w
    probe[0, :, 1] = xy_px[:, 1] / h
    return apply_stmap(stmap, probe)[0, :, :2]


@pytest.fixture(scope="module", params=["zeiss_distagon_35mm_f4", "zuiko_18mm_f3_5"])
def case(request):
    from physcam.analysis.distortion.stmap import distortion_field

    lens = load_lens(request.param)
    res = distortion_field(camera_state(lens, focus_mm=FOCUS, sensor_mm=SENSOR), width_px=W_PX, height_px=H_PX)
    return lens, res


def _ideal_grid_and_real(lens, res):
    return ideal_grid_and_real(lens, FOCUS, SENSOR, (W_PX, H_PX))


def test_undistortion_map_takes_traced_points_to_the_pinhole_grid(case):
    lens, res = case
    ideal, real = _ideal_grid_and_real(lens, res)
    ox, oy = res.overscan_px
    W2, H2 = W_PX + 2 * ox, H_PX + 2 * oy
    assert res.undistortion_stmap.shape == (H2, W2, 3)
    # the undistorted image's pixel at the ideal position fetches the plate at the traced position
    src = _sample(res.undistortion_stmap, ideal + [ox, oy], (W2, H2)) * [W_PX, H_PX]
    err = np.hypot(*(src - real).T)
    assert err.max() < 0.1, err.max()
    # the lens distorts visibly, so this is not passing by doing nothing
    assert np.hypot(*(real - ideal).T).max() > 5.0


def test_distortion_map_returns_the_undistorted_grid(case):
    lens, res = case
    ideal, real = _ideal_grid_and_real(lens, res)
    ox, oy = res.overscan_px
    W2, H2 = W_PX + 2 * ox, H_PX + 2 * oy
    # distortion map at the traced (plate) position fetches the undistorted image at the ideal one
    # (normalised to the undistorted image's frame, the plate's: its display window)
    back = _sample(res.distortion_stmap, real, (W_PX, H_PX)) * [W_PX, H_PX]
    assert np.hypot(*(back - ideal).T).max() < 0.1
    # and the round trip through both maps
    src = _sample(res.undistortion_stmap, ideal + [ox, oy], (W2, H2)) * [W_PX, H_PX]
    again = _sample(res.distortion_stmap, src, (W_PX, H_PX)) * [W_PX, H_PX]
    assert np.hypot(*(again - ideal).T).max() < 0.1


def test_overscan_keeps_every_plate_pixel(case):
    _, res = case
    ox, oy = res.overscan_px
    d = res.distortion_stmap
    assert d.shape == (H_PX, W_PX, 3)
    # every plate pixel's ideal position lies inside the overscanned frame (plate-normalised)
    assert d[..., 0].min() >= -ox / W_PX and d[..., 0].max() <= 1.0 + ox / W_PX
    assert d[..., 1].min() >= -oy / H_PX and d[..., 1].max() <= 1.0 + oy / H_PX
    assert (d[..., 2] == 0).all()
    assert ox > 0 and oy > 0  # barrel at the corners: the ideal image is larger than the plate
    assert res.interpolation_error_px < 0.05 and res.inverse_error_px < 0.05


def test_image_round_trip_through_both_maps(case):
    """A smooth image undistorted then distorted comes back (bilinear twice: small blur only)."""
    from physcam.analysis.distortion.stmap import apply_stmap

    _, res = case
    yy, xx = np.mgrid[0:H_PX, 0:W_PX] + 0.5
    img = np.sin(xx / 37.0) * np.cos(yy / 23.0)
    und = apply_stmap(img, res.undistortion_stmap)
    back = apply_stmap(und, res.distortion_stmap, overscan=res.overscan_px)
    inner = (slice(20, -20), slice(20, -20))
    assert np.abs(back - img)[inner].max() < 0.02


def test_identity_map_and_bilinear_by_hand():
    from physcam.analysis.distortion.stmap import apply_stmap

    img = np.arange(12.0).reshape(3, 4)  # rows top first
    h, w = img.shape
    ident = np.zeros((h, w, 3))
    ident[..., 0] = (np.arange(w) + 0.5) / w
    ident[..., 1] = ((h - 1 - np.arange(h)) + 0.5)[:, None] / h
    assert np.allclose(apply_stmap(img, ident), img)
    # halfway between the centres of columns 1 and 2 of the middle row: (5 + 6) / 2
    probe = np.array([[[2.0 / w, 1.5 / h]]])
    assert apply_stmap(img, probe)[0, 0] == pytest.approx(5.5)


def test_exr_files_open_as_float_rgb(tmp_path, case):
    import OpenEXR

    from physcam.analysis.distortion.stmap import write_stmaps

    _, res = case
    paths = write_stmaps(res, tmp_path / "maps")
    assert sorted(p.name for p in paths) == ["distortion.exr", "distortion.png", "undistortion.exr", "undistortion.png"]
    for name, arr in (("distortion", res.distortion_stmap), ("undistortion", res.undistortion_stmap)):
        with OpenEXR.File(str(tmp_path / "maps" / f"{name}.exr"), separate_channels=True) as f:
            ch = f.channels()
            assert set(ch) >= {"R", "G", "B"}
            for c in "RGB":
                assert ch[c].type() == OpenEXR.FLOAT
                assert ch[c].pixels.dtype == np.float32
                assert ch[c].pixels.shape == arr.shape[:2]
            assert np.array_equal(ch["R"].pixels, arr[..., 0])
            assert np.array_equal(ch["G"].pixels, arr[..., 1])
            assert (ch["B"].pixels == 0).all()
        # the PNG preview (read back by matplotlib's reader): the same map in 8 bits, row 0 on top
        from matplotlib.image import imread

        png = imread(tmp_path / "maps" / f"{name}.png")
        assert png.shape[:2] == arr.shape[:2]
        assert np.abs(png[..., :3] - np.clip(arr, 0, 1)).max() <= 0.5 / 255 + 1e-6
    # no clobber without force, and nothing half written
    before = {p.name: p.stat().st_mtime_ns for p in (tmp_path / "maps").iterdir()}
    with pytest.raises(PhysCamError):
        write_stmaps(res, tmp_path / "maps")
    assert {p.name: p.stat().st_mtime_ns for p in (tmp_path / "maps").iterdir()} == before


@pytest.mark.parametrize("kw", [dict(width_px=0, height_px=1366), dict(width_px=100000, height_px=1366),
                                dict(width_px=8192, height_px=8192), dict(width_px=2048.0, height_px=1366),
                                dict(width_px=2048, height_px=1366, focus_mm=50.0),
                                dict(width_px=2048, height_px=1366, focus_mm=-3.0),
                                dict(width_px=2048, height_px=1366, focus_mm=math.nan)])
def test_bad_inputs_are_one_clear_error(kw):
    from physcam.analysis.distortion.stmap import distortion_field

    kw = dict(kw)
    focus_mm = kw.pop("focus_mm", 2000.0)
    with pytest.raises(PhysCamError) as e:
        distortion_field(camera_state(load_lens("zeiss_distagon_35mm_f4"), focus_mm=focus_mm, sensor_mm=(36, 24)), **kw)
    assert str(e.value).strip().endswith((".", ")")) or len(str(e.value)) > 20
