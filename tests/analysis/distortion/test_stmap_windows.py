"""The ST-map files carry their own frame (issue 26 item 6), checked by a consumer that is not physcam:
OpenImageIO reads the EXR windows and applies the maps with its own ``ImageBufAlgo.st_warp``.

The undistortion map's display window is the plate's frame and its data window the overscanned
region; the distortion map's coordinates are normalised to that frame. The oracle for where a plate
pixel belongs is tests/analysis/_forward_chief.py: object points placed where physcam's pinhole sees
a chosen ideal pixel, their chief rays traced *forward* through the centre of the stop to the film
(independent of the maps' backward rays, interpolation and inversion).
"""

from __future__ import annotations

import numpy as np
import pytest

from physcam.lens.library import load_lens
from physcam.optics.state import camera_state
from _forward_chief import ideal_grid_and_real

oiio = pytest.importorskip("OpenImageIO", reason="OpenImageIO (pip openimageio, the test extra) is not installed")

W_PX, H_PX = 640, 480
SENSOR = (36.0, 24.0)
FOCUS = 2000.0


def _picture(x, y):
    """A smooth test picture as a function of plate-style coordinates (x right, y up, pixels)."""
    return np.sin(x / 17.0) * np.cos(y / 11.0) + 0.002 * x


def _plate():
    yy, xx = np.mgrid[0:H_PX, 0:W_PX] + 0.5
    return _picture(xx, H_PX - yy).astype(np.float32)  # rows top first; plate y is up from the bottom


def _undistort(plate, folder):
    """st_warp through undistortion.exr over the map's data window, the result framed by the map's
    display window (what Nuke's STMap does: its output takes the map's format and bounding box)."""
    stbuf = oiio.ImageBuf(str(folder / "undistortion.exr"))
    und = oiio.ImageBufAlgo.st_warp(_buf(plate), stbuf, filtername="triangle", flip_t=True,  # t up (Nuke's)
                                    roi=stbuf.roi)
    assert not und.has_error, und.geterror()
    f = stbuf.roi_full
    und.set_full(f.xbegin, f.xend, f.ybegin, f.yend, 0, 1)
    return und


def _buf(a):
    spec = oiio.ImageSpec(a.shape[1], a.shape[0], 1, "float")
    b = oiio.ImageBuf(spec)
    b.set_pixels(oiio.ROI(0, a.shape[1], 0, a.shape[0], 0, 1, 0, 1), a[..., None])
    return b


@pytest.fixture(scope="module")
def maps(tmp_path_factory):
    from physcam.analysis.distortion.stmap import distortion_field, write_stmaps

    lens = load_lens("zeiss_distagon_35mm_f4")
    res = distortion_field(camera_state(lens, focus_mm=FOCUS, sensor_mm=SENSOR), width_px=W_PX, height_px=H_PX)
    folder = tmp_path_factory.mktemp("maps")
    write_stmaps(res, folder)
    return lens, res, folder


def test_the_undistortion_exr_says_where_the_plate_sits(maps):
    _, res, folder = maps
    ox, oy = res.overscan_px
    assert ox > 0 and oy > 0  # the Distagon's barrel: the undistorted picture is larger than the plate
    spec = oiio.ImageBuf(str(folder / "undistortion.exr")).spec()
    assert (spec.full_x, spec.full_y, spec.full_width, spec.full_height) == (0, 0, W_PX, H_PX)
    assert (spec.x, spec.y, spec.width, spec.height) == (-ox, -oy, W_PX + 2 * ox, H_PX + 2 * oy)
    spec = oiio.ImageBuf(str(folder / "distortion.exr")).spec()
    assert (spec.x, spec.y, spec.width, spec.height) == (spec.full_x, spec.full_y, W_PX, H_PX) == (0, 0, W_PX, H_PX)


def test_openimageio_undistorts_the_plate_to_the_pinhole_picture(maps):
    """OIIO's st_warp through undistortion.exr: the undistorted picture at an ideal (pinhole) pixel
    holds the plate's picture where the forward-traced chief ray of that pixel's object lands."""
    lens, res, folder = maps
    ox, oy = res.overscan_px
    und = _undistort(_plate(), folder)
    s = und.spec()
    assert (s.x, s.y, s.width, s.height) == (-ox, -oy, W_PX + 2 * ox, H_PX + 2 * oy)  # the map's frame kept
    img = und.get_pixels(oiio.FLOAT)[..., 0]  # rows top first over the data window
    ideal, real = ideal_grid_and_real(lens, FOCUS, SENSOR, (W_PX, H_PX))
    # the undistorted pixel whose centre is nearest each ideal point; the picture there is the plate's
    # picture at the real point moved by the same sub-pixel offset (the map is locally a shift)
    col = np.floor(ideal[:, 0]).astype(int)
    row_up = np.floor(ideal[:, 1]).astype(int)
    d = np.stack([col + 0.5, row_up + 0.5], axis=1) - ideal
    got = img[(H_PX - 1 - row_up) + oy, col + ox]
    want = _picture(real[:, 0] + d[:, 0], real[:, 1] + d[:, 1])
    # bilinear sampling of a picture whose second derivative is at most 1/11^2 per px^2: 0.01
    assert np.abs(got - want).max() < 0.02, np.abs(got - want).max()
    assert np.hypot(*(real - ideal).T).max() > 3.0  # the lens distorts: not passing by doing nothing


def test_openimageio_redistorts_back_to_the_plate(maps):
    """undistort then redistort, both in OIIO: the undistorted buffer (display = plate, data =
    overscan) is st_warp's source, and distortion.exr's coordinates are normalised to its display
    window, so the plate comes back (two bilinear passes: a small blur only)."""
    _, _, folder = maps
    plate = _plate()
    und = _undistort(plate, folder)
    stbuf = oiio.ImageBuf(str(folder / "distortion.exr"))
    back = oiio.ImageBufAlgo.st_warp(und, stbuf, filtername="triangle", flip_t=True, roi=stbuf.roi)
    assert not back.has_error, back.geterror()
    s = back.spec()
    assert (s.x, s.y, s.width, s.height) == (0, 0, W_PX, H_PX)
    img = back.get_pixels(oiio.FLOAT)[..., 0]
    inner = (slice(8, -8), slice(8, -8))
    assert np.abs(img - plate)[inner].max() < 0.03, np.abs(img - plate)[inner].max()
