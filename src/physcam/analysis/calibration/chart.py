"""Finding a planar calibration chart in photographs (docs/calibrate.md), with OpenCV (``calibrate`` extra).

A **checkerboard** of ``corners`` = (columns, rows) *inner* corners and ``square_mm`` squares is
found by OpenCV's sector-based detector (``cv2.findChessboardCornersSB``, Duda & Frese 2018,
"Accurate Detection and Localization of Checkerboard Corners for Calibration", BMVC) and its
corners refined by ``cv2.cornerSubPix`` in a window scaled to the squares (the detector's own
sub-pixel corners are good to only ~0.3 px on blurred, noisy photographs); the whole board must be
in the picture. A **ChArUco** board
(Garrido-Jurado et al. 2014, *Pattern Recognition* 47(6)) of (columns, rows) *squares* carries an
ArUco marker in every white square, so each corner is identified on its own and partial views
(the chart cut by the frame's edge, which is where the distortion is largest) count:
``cv2.aruco.CharucoDetector``, then the corners refined to sub-pixel accuracy.

Pixel coordinates here are OpenCV's: x to the right, y down, the centre of the top-left pixel
at (0, 0). The chart's points are in millimetres on the chart (z = 0).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import InputError, require_positive
from .names import CHARTS, CHARUCO_DICTIONARY, MAX_IMAGE_PIXELS, parse_corners  # noqa: F401 (re-exported)

__all__ = [
    "CHARTS",
    "CHARUCO_DICTIONARY",
    "IMAGE_SUFFIXES",
    "ChartSpec",
    "ChartView",
    "detect_chart",
    "detect_views",
    "grid_problem",
    "image_files",
    "image_size",
    "parse_corners",
    "read_gray",
    "MAX_IMAGE_PIXELS",
]

#: Image files a folder given as IMAGES contributes (OpenCV reads them)
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp")
#: A view is kept when at least this many corners are found in it
MIN_CORNERS_PER_VIEW = 8
#: A checkerboard's corners in every 3 x 3 block must fit a homography to this fraction of a square
#: (a plane's picture through a lens: a homography locally, bent only by the distortion's curvature)
GRID_TOLERANCE = 0.2
#: A checkerboard photograph of at least this many pixels is searched at half size first (a quarter of
#: the pixels; the sector detector's time goes with them: 1.45 -> 0.46 s CPU a 1280 x 960 photo) and the
#: corners found are refined in the full image; the full-size search follows when that finds no grid
#: or a grid out of order (:func:`_half_size_grid`)
HALF_SIZE_SEARCH_PX = 1_000_000


def _cv2():
    from ...extras import require_extra

    require_extra("calibrate", "calibrating a camera from chart photographs")
    import cv2

    return cv2


@dataclass(frozen=True)
class ChartSpec:
    """A planar chart: ``kind`` checkerboard (``corners`` = inner corners) or charuco (``corners`` =
    squares, columns x rows); squares ``square_mm``; ChArUco markers ``marker_mm`` (default 3/4 of
    a square) from ``dictionary``."""

    kind: str
    corners: tuple[int, int]
    square_mm: float
    marker_mm: float | None = None
    dictionary: str = CHARUCO_DICTIONARY

    def __post_init__(self):
        if self.kind not in CHARTS:
            raise InputError(f"the chart must be one of {', '.join(CHARTS)}, got {self.kind!r}")
        require_positive("chart square", self.square_mm, unit="mm")
        if self.kind == "charuco" and min(self.corners) < 3:
            raise InputError(f"a ChArUco board needs 3 or more squares each way, got {self.corners}")
        if self.marker_mm is not None and not 0 < self.marker_mm < self.square_mm:
            raise InputError(f"the ChArUco marker ({self.marker_mm!r} mm) must be smaller than a square "
                             f"({self.square_mm:g} mm)")

    @property
    def inner(self) -> tuple[int, int]:
        """Inner corners (columns, rows)."""
        return self.corners if self.kind == "checkerboard" else (self.corners[0] - 1, self.corners[1] - 1)

    def object_points(self) -> np.ndarray:
        """(n, 3) chart mm of every inner corner, row by row (OpenCV's order; ChArUco ids in it)."""
        cols, rows = self.inner
        j, i = np.mgrid[0:rows, 0:cols]
        return np.stack([i.ravel() * self.square_mm, j.ravel() * self.square_mm, np.zeros(i.size)], axis=1)

    def charuco_board(self):
        cv2 = _cv2()
        if not hasattr(cv2.aruco, self.dictionary):
            raise InputError(f"unknown ArUco dictionary {self.dictionary!r}, e.g. {CHARUCO_DICTIONARY}")
        d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dictionary))
        marker = self.marker_mm if self.marker_mm is not None else 0.75 * self.square_mm
        return cv2.aruco.CharucoBoard(self.corners, self.square_mm, marker, d)


@dataclass
class ChartView:
    """One photograph's chart: the corners found (OpenCV px, (n, 2)) and their chart mm (n, 3)."""

    path: str
    size_px: tuple[int, int]  # width, height
    image_points: np.ndarray
    object_points: np.ndarray
    mark_mm: float | None = None  # the focus mark it was shot at (mm from the film)


def image_files(items) -> list[Path]:
    """The image files of ``items``: files as given, folders as their images (sorted)."""
    if isinstance(items, (str, Path)):
        items = [items]
    if not hasattr(items, "__iter__"):
        raise InputError(f"give image files or folders, got {type(items).__name__}")
    out: list[Path] = []
    for it in items:
        if not isinstance(it, (str, Path)):
            raise InputError(f"an image is a file name, got {type(it).__name__}")
        p = Path(it)
        if p.is_dir():
            found = sorted(q for q in p.iterdir() if q.suffix.lower() in IMAGE_SUFFIXES)
            if not found:
                raise InputError(f"{p}: a folder with no images ({', '.join(IMAGE_SUFFIXES)})")
            out += found
        elif p.is_file():
            out.append(p)
        else:
            raise InputError(f"{p}: no such image file or folder")
    return out


def image_size(path) -> tuple[int, int]:
    """(width, height) in pixels of a PNG, JPEG, TIFF or BMP file, from its header alone (nothing decoded):
    PNG's IHDR (ISO/IEC 15948, 11.2.2), JPEG's start-of-frame segment (ITU-T T.81, B.2.2), BMP's
    BITMAPINFOHEADER, TIFF's first image directory (Pillow's TIFF reader, which decodes lazily). Any
    other file is an InputError."""
    if not isinstance(path, (str, Path)):
        raise InputError(f"an image is a file name, got {type(path).__name__}")
    p = Path(path)
    try:
        with open(p, "rb") as fh:
            head = fh.read(32)
            if head.startswith(b"\x89PNG\r\n\x1a\n") and head[12:16] == b"IHDR":
                return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
            if head.startswith(b"BM") and len(head) >= 26:
                return abs(int.from_bytes(head[18:22], "little", signed=True)), \
                    abs(int.from_bytes(head[22:26], "little", signed=True))
            if head.startswith(b"\xff\xd8"):
                return _jpeg_size(p, fh)
            if head[:4] in (b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+"):
                return _tiff_size(p)
    except OSError as exc:
        raise InputError(f"{p}: cannot read it ({exc.strerror or exc})") from None
    raise InputError(f"{p}: not an image OpenCV can read (corrupt, cut, or not a PNG, JPEG, TIFF or BMP file: physcam "
                     "reads the size from the header before decoding)")


def _jpeg_size(p: Path, fh) -> tuple[int, int]:
    """The size in a JPEG's first start-of-frame marker (SOF0-SOF15 but DHT C4, JPG C8, DAC CC)."""
    fh.seek(2)
    for _ in range(10_000):  # markers before the frame: a bound, not a real limit
        b = fh.read(2)
        while len(b) == 2 and b[0] == 0xFF and b[1] == 0xFF:  # fill bytes
            b = b[1:] + fh.read(1)
        if len(b) < 2 or b[0] != 0xFF:
            break
        seg = fh.read(2)
        if len(seg) < 2:
            break
        if 0xC0 <= b[1] <= 0xCF and b[1] not in (0xC4, 0xC8, 0xCC):
            frame = fh.read(5)
            if len(frame) == 5:
                return int.from_bytes(frame[3:5], "big"), int.from_bytes(frame[1:3], "big")
            break
        fh.seek(int.from_bytes(seg, "big") - 2, 1)
    raise InputError(f"{p}: a JPEG without a readable frame header (corrupt or cut)")


def _tiff_size(p: Path) -> tuple[int, int]:
    from PIL import TiffImagePlugin

    try:
        with TiffImagePlugin.TiffImageFile(str(p)) as im:  # the header and first directory only
            return int(im.size[0]), int(im.size[1])
    except Exception as exc:  # noqa: BLE001 - any failure of Pillow's header parse is "not readable"
        raise InputError(f"{p}: a TIFF whose header cannot be read ({str(exc)[:80]})") from None


def read_gray(path, *, max_pixels: int = MAX_IMAGE_PIXELS) -> np.ndarray:
    """The image at ``path`` as a 2-D array (8 or 16 bit kept); its size is read from the header first
    and an image of more than ``max_pixels`` pixels is refused before decoding (a decompression bomb:
    a small file that decodes to gigabytes). A file OpenCV cannot read is an InputError."""
    w, h = image_size(path)
    check_pixels(path, w, h, max_pixels)
    cv2 = _cv2()
    img = cv2.imread(str(path), cv2.IMREAD_ANYDEPTH | cv2.IMREAD_GRAYSCALE)
    if img is None or img.ndim != 2 or min(img.shape) < 16:
        raise InputError(f"{path}: not an image OpenCV can read (corrupt, or not an image file)")
    if (img.shape[1], img.shape[0]) != (w, h):
        raise InputError(f"{path}: its header says {w}x{h} px, OpenCV decoded {img.shape[1]}x{img.shape[0]}")
    return img


def check_pixels(path, width: int, height: int, max_pixels: int = MAX_IMAGE_PIXELS) -> None:
    """An InputError when a ``width`` x ``height`` image is empty or has more than ``max_pixels`` pixels."""
    if isinstance(max_pixels, bool) or not isinstance(max_pixels, int) or max_pixels < 1:
        raise InputError(f"max_pixels is a whole number of pixels >= 1, got {max_pixels!r}")
    if width < 1 or height < 1:
        raise InputError(f"{path}: its header says {width}x{height} px: an empty image")
    if width * height > max_pixels:
        raise InputError(f"{path}: {width}x{height} px ({width * height / 1e6:.0f} Mpx) is more than the "
                         f"{max_pixels / 1e6:g} Mpx physcam decodes (refused from its header; --max-pixels raises "
                         "the limit)")


def _to8(img: np.ndarray) -> np.ndarray:
    if img.dtype == np.uint8:
        return img
    a = img.astype(np.float64)
    return np.clip(255.0 * (a - a.min()) / max(a.max() - a.min(), 1e-12), 0, 255).astype(np.uint8)


def detect_chart(image: np.ndarray, chart: ChartSpec):
    """(image points (n, 2) OpenCV px, chart points (n, 3) mm) of ``chart`` in ``image``, or None."""
    if not isinstance(chart, ChartSpec):
        raise InputError(f"give a ChartSpec, got {type(chart).__name__}")
    image = np.asarray(image)
    if image.ndim != 2 or image.dtype.kind not in "uif" or min(image.shape) < 16:
        raise InputError(f"the image is a 2-D grey array of 16 px or more each way, got shape {image.shape}")
    cv2 = _cv2()
    img = _to8(image)
    if chart.kind == "checkerboard":
        refined = _half_size_grid(cv2, img, chart.inner)
        if refined is not None:
            return refined, chart.object_points()
        ok, corners = cv2.findChessboardCornersSB(img, chart.inner, flags=_checkerboard_flags(cv2))
        if not ok:
            return None
        refined = _refine_checkerboard(cv2, img, corners.reshape(-1, 2), chart.inner)
        why = grid_problem(corners.reshape(-1, 2), chart.inner, folds_only=True) or grid_problem(refined, chart.inner)
        if why:  # OpenCV's detector now and then returns a grid out of order: never fitted
            raise InputError(f"OpenCV's checkerboard detector returned a wrong grid ({why}); reshoot or leave the "
                             "photo out")
        return refined, chart.object_points()
    board = chart.charuco_board()
    params = cv2.aruco.CharucoParameters()
    detector = cv2.aruco.CharucoDetector(board, params)
    corners, ids, _, _ = detector.detectBoard(img)
    if ids is None or len(ids) < MIN_CORNERS_PER_VIEW:
        return None
    pts = corners.reshape(-1, 1, 2).astype(np.float32)
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-4)
    pts = cv2.cornerSubPix(img, pts, (5, 5), (-1, -1), crit)
    obj = np.asarray(board.getChessboardCorners(), np.float64).reshape(-1, 3)
    return pts.reshape(-1, 2).astype(np.float64), obj[ids.ravel()]


def _checkerboard_flags(cv2) -> int:
    """The sector detector's flags: an exhaustive search on the normalised image. Without
    ``CALIB_CB_ACCURACY`` (its search on an upsampled image): every corner is refined on the full-size
    image afterwards (:func:`_refine_checkerboard`), and on 24 rendered photographs (tests/analysis/_charts.py,
    three shoots of 8) the refined corners were as close to the true ones without it as with it (mean RMS 0.063
    px without, 0.064 with; worst corner 0.282 px either way) while the search took 2x (half size) to 3x (full
    size) the CPU."""
    return cv2.CALIB_CB_EXHAUSTIVE | cv2.CALIB_CB_NORMALIZE_IMAGE


def _half_size_grid(cv2, img, inner):
    """The refined corners of the checkerboard found in ``img`` halved (area average), or None when the
    image is under :data:`HALF_SIZE_SEARCH_PX`, no grid is found at half size, or the grid found fails
    :func:`grid_problem` (the full-size search then decides). A half-size pixel's centre (i + 0.5) lies
    at full-size 2 (i + 0.5); the refinement (:func:`_refine_checkerboard`, its window 2-15 px) takes
    the corners from there to where the full-size search's would be (within 0.05 px on 16 rendered photographs,
    most within 1e-4 px)."""
    h, w = img.shape
    if h * w < HALF_SIZE_SEARCH_PX:
        return None
    small = cv2.resize(img, (w // 2, h // 2), interpolation=cv2.INTER_AREA)
    ok, corners = cv2.findChessboardCornersSB(small, inner, flags=_checkerboard_flags(cv2))
    if not ok:
        return None
    corners = (corners.reshape(-1, 2).astype(np.float64) + 0.5) * [w / small.shape[1], h / small.shape[0]] - 0.5
    if grid_problem(corners, inner, folds_only=True):
        return None
    refined = _refine_checkerboard(cv2, img, corners, inner)
    return None if grid_problem(refined, inner) else refined


def grid_problem(points, inner, *, folds_only: bool = False) -> str | None:
    """Why ``points`` ((cols x rows, 2) px, OpenCV's row-by-row order) cannot be a checkerboard's inner
    corners seen through a lens, or None. A plane's picture is a homography of it, bent only by the
    lens's smooth distortion, so (1) every 3 x 3 block of neighbouring corners fits a homography
    (least squares, ``cv2.findHomography``; Hartley & Zisserman 2004, 4.1) to within
    :data:`GRID_TOLERANCE` of the block's square, and (2) the grid never folds: the cross product of
    its row and column steps keeps one sign (a fold or a row out of order flips it somewhere)."""
    cv2 = _cv2()
    cols, rows = inner
    g = np.asarray(points, np.float64).reshape(rows, cols, 2)
    if not np.isfinite(g).all():
        return "corners that are not finite"
    du, dv = g[:, 1:] - g[:, :-1], g[1:] - g[:-1]
    cross = du[:-1, :, 0] * dv[:, :-1, 1] - du[:-1, :, 1] * dv[:, :-1, 0]
    if not ((cross > 0).all() or (cross < 0).all()):
        r, c = np.argwhere(np.sign(cross) != np.sign(np.median(cross)))[0]
        return f"the grid folds over itself at row {r + 1}, column {c + 1}"
    if folds_only:
        return None
    j, i = np.mgrid[0:3, 0:3]
    obj = np.column_stack([i.ravel(), j.ravel()]).astype(np.float64)
    worst = (0.0, 0, 0)
    for r in range(rows - 2):
        for c in range(cols - 2):
            block = g[r:r + 3, c:c + 3].reshape(-1, 2)
            H, _ = cv2.findHomography(obj, block, 0)
            if H is None:
                return f"the corners at row {r + 1}, column {c + 1} fit no homography"
            q = np.column_stack([obj, np.ones(9)]) @ H.T
            miss = np.hypot(*(q[:, :2] / q[:, 2:] - block).T).max()
            b = g[r:r + 3, c:c + 3]
            side = np.median(np.concatenate([np.hypot(*(b[:, 1:] - b[:, :-1]).reshape(-1, 2).T),
                                             np.hypot(*(b[1:] - b[:-1]).reshape(-1, 2).T)]))
            worst = max(worst, (miss / side, r + 1, c + 1))
    if worst[0] > GRID_TOLERANCE:
        return (f"the corners around row {worst[1]}, column {worst[2]} fit no homography: off by "
                f"{worst[0]:.2f} of a square, more than {GRID_TOLERANCE:g}")
    return None


def _refine_checkerboard(cv2, img, corners, inner) -> np.ndarray:
    """The sector detector's corners refined by ``cv2.cornerSubPix`` (Foerstner & Guelch 1987: the point
    every edge gradient around it is orthogonal to), in a window of 0.4 of the smallest corner spacing
    (2 to 15 px each way): on blurred, noisy chart photographs the detector alone is good to ~0.3 px
    RMS and now and then misplaces a corner by several pixels; refined, 0.03-0.08 px
    (tests/analysis/calibration/test_calibrate.py's rendered checkerboards)."""
    g = corners.reshape(inner[1], inner[0], 2)
    spacing = min(np.linalg.norm(np.diff(g, axis=0), axis=2).min(), np.linalg.norm(np.diff(g, axis=1), axis=2).min())
    w = int(np.clip(0.4 * spacing, 2, 15))
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-4)
    pts = cv2.cornerSubPix(img, corners.reshape(-1, 1, 2).astype(np.float32), (w, w), (-1, -1), crit)
    return pts.reshape(-1, 2).astype(np.float64)


def detect_views(paths, chart: ChartSpec, marks=None, *, max_pixels: int = MAX_IMAGE_PIXELS) -> list[ChartView]:
    """Every image's chart; an image without one, a checkerboard grid out of order (:func:`grid_problem`),
    a corrupt file, an image above ``max_pixels`` (:func:`read_gray`) or mixed sizes is an InputError
    naming the file. ``marks``: the focus mark (mm from the film) of each path, or None."""
    if not isinstance(chart, ChartSpec):
        raise InputError(f"give a ChartSpec, got {type(chart).__name__}")
    paths = image_files(paths)
    if marks is not None and (isinstance(marks, (str, bytes)) or not hasattr(marks, "__len__")):
        raise InputError(f"marks is one focus mark (mm) per image, got {type(marks).__name__}")
    marks = [None] * len(paths) if marks is None else list(marks)
    if len(marks) != len(paths):
        raise InputError(f"{len(marks)} focus marks for {len(paths)} images: give one mark per image")
    views: list[ChartView] = []
    for path, mark in zip(paths, marks):
        img = read_gray(path, max_pixels=max_pixels)
        size = (int(img.shape[1]), int(img.shape[0]))
        if views and size != views[0].size_px:
            raise InputError(f"{path}: {size[0]}x{size[1]} px, but {views[0].path} is "
                             f"{views[0].size_px[0]}x{views[0].size_px[1]}: give images of one camera mode")
        try:
            found = detect_chart(img, chart)
        except InputError as exc:
            raise InputError(f"{path}: {exc}") from None
        if found is None:
            raise InputError(f"{path}: no {chart.kind} of {chart.corners[0]}x{chart.corners[1]} "
                             f"{'inner corners' if chart.kind == 'checkerboard' else 'squares'} found in it")
        views.append(ChartView(str(path), size, found[0], found[1], mark))
    return views
