"""Chart photographs made with OpenCV's own projection (cv2.projectPoints and its inverse), an
independent ground truth for physcam.analysis.calibration.calibrate: a known pinhole, principal point and
Brown-Conrady distortion, poses at many angles (some cut by the frame), blur and noise."""

from __future__ import annotations

import cv2
import numpy as np

from physcam.analysis.calibration.chart import ChartSpec, ChartView

SIZE = (1280, 960)  # width, height px
SENSOR_MM = (12.8, 9.6)  # 10 um photosites
K_TRUE = np.array([[1150.0, 0.0, 652.4], [0.0, 1150.0, 471.3], [0.0, 0.0, 1.0]])
DIST_TRUE = np.array([-0.19, 0.11, 0.0006, -0.0004, -0.03])  # k1 k2 p1 p2 k3 (OpenCV's order)
CHARUCO = ChartSpec("charuco", (24, 18), 15.0, 11.0, "DICT_5X5_250")  # 360 x 270 mm
CHECKER = ChartSpec("checkerboard", (9, 6), 30.0)


def poses(n=15, seed=1, chart=CHARUCO, partial=True):
    """``n`` chart poses (rvec, tvec): tilted up to ~40 degrees, the chart filling much of the
    frame; with ``partial`` every third one pushed so that the frame cuts it."""
    rng = np.random.default_rng(seed)
    cols, rows = chart.corners if chart.kind == "charuco" else (chart.corners[0] + 1, chart.corners[1] + 1)
    centre = np.array([cols * chart.square_mm / 2, rows * chart.square_mm / 2, 0.0])
    out = []
    for i in range(n):
        ax, ay = np.radians(rng.uniform(-45, 45, 2))
        az = np.radians(rng.uniform(-15, 15))
        R = cv2.Rodrigues(np.array([ax, 0, 0]))[0] @ cv2.Rodrigues(np.array([0, ay, 0]))[0] @ \
            cv2.Rodrigues(np.array([0, 0, az]))[0]
        z = rng.uniform(330, 420) if chart.kind == "charuco" else rng.uniform(560, 700)
        shift = rng.uniform(-0.12, 0.12, 2) * z
        if partial and i % 3 == 0:
            shift = shift + np.sign(rng.uniform(-1, 1, 2)) * 0.3 * z
        t = np.array([shift[0], shift[1], z]) - R @ centre
        out.append((cv2.Rodrigues(R)[0].ravel(), t))
    return out


def whole_board_poses(n, seed, chart=CHECKER, K=K_TRUE, margin_px=12.0):
    """The first ``n`` of :func:`poses` (no partial views) whose whole board (its outer corners and
    every inner one) lands ``margin_px`` inside the frame through ``K`` and DIST_TRUE: a checkerboard
    is found only whole."""
    cols, rows = chart.corners[0] + 1, chart.corners[1] + 1
    outer = np.array([[0, 0, 0], [cols, 0, 0], [cols, rows, 0], [0, rows, 0]], float) * chart.square_mm
    obj = np.concatenate([board_points(chart), outer])
    out = []
    for r, t in poses(4 * n, seed, chart, partial=False):
        img, _ = cv2.projectPoints(obj, r, t, K, DIST_TRUE)
        img = img.reshape(-1, 2)
        if (img.min(axis=0) > margin_px).all() and (img < np.array(SIZE) - margin_px).all():
            out.append((r, t))
        if len(out) == n:
            return out
    raise ValueError(f"only {len(out)} whole-board poses in {4 * n} draws")


def board_points(chart):
    if chart.kind == "charuco":
        return np.asarray(chart.charuco_board().getChessboardCorners(), float).reshape(-1, 3)
    return chart.object_points() + [chart.square_mm, chart.square_mm, 0.0]


def point_views(chart=CHARUCO, n=15, noise_px=0.3, seed=1, mark=None, K=K_TRUE, dist=DIST_TRUE):
    """Views from projected corners (pinhole ``K``, OpenCV distortion ``dist``) with Gaussian noise;
    corners outside the frame dropped."""
    rng = np.random.default_rng(seed + 100)
    views = []
    obj = board_points(chart)
    for k, (r, t) in enumerate(poses(n, seed, chart)):
        img, _ = cv2.projectPoints(obj, r, t, K, dist)
        img = img.reshape(-1, 2) + rng.normal(0, noise_px, (len(obj), 2))
        inside = (img[:, 0] > 2) & (img[:, 1] > 2) & (img[:, 0] < SIZE[0] - 3) & (img[:, 1] < SIZE[1] - 3)
        views.append(ChartView(f"pose{k}", SIZE, img[inside], obj[inside], mark))
    return views


def board_image(chart, px_per_mm=8.0):
    """The chart's picture (white margin of one square around it), and its px per mm."""
    if chart.kind == "charuco":
        w, h = chart.corners[0] * chart.square_mm, chart.corners[1] * chart.square_mm
        img = chart.charuco_board().generateImage((int(w * px_per_mm), int(h * px_per_mm)), marginSize=0)
    else:
        cols, rows = chart.corners[0] + 1, chart.corners[1] + 1
        s = int(chart.square_mm * px_per_mm)
        j, i = np.mgrid[0:rows * s, 0:cols * s] // s
        img = np.where((i + j) % 2 == 0, 0, 255).astype(np.uint8)
    return img, px_per_mm


def _upsample(coarse, fine):
    """Bilinear interpolation of a smooth coarse map (node spacing 1) at fractional node positions
    (the chart's map bends by far less than a thousandth of a pixel over one node spacing): along x on
    the coarse rows, then along y (the same bilinear weights, one pass a direction)."""
    fx, fy = fine
    i, j = np.minimum(fx.astype(int), coarse.shape[1] - 2), np.minimum(fy.astype(int), coarse.shape[0] - 2)
    tx, ty = fx - i, (fy - j)[:, None]
    rows = (1 - tx) * coarse[:, i] + tx * coarse[:, i + 1]  # (coarse rows, fine columns)
    out = np.empty((len(fy), rows.shape[1]), np.float32)
    for a in range(0, len(fy), 64):  # 64 fine rows at a time: the same sums, in cache (3 x faster than at once)
        b = slice(a, a + 64)
        out[b] = (1 - ty[b]) * rows[j[b]] + ty[b] * rows[j[b] + 1]
    return out


def render(chart, rvec, tvec, *, board=None, supersample=2, blur_px=0.8, noise=2.0, seed=0, K=K_TRUE, dist=DIST_TRUE):
    """An 8-bit photograph of the chart at the pose through ``K`` and ``dist`` (K_TRUE and DIST_TRUE by
    default): every (sub)pixel's
    ray found by OpenCV's inverse of its distortion (undistortPointsIter), met with the chart's
    plane, and the chart's picture sampled there; then a Gaussian blur and noise (grey levels)."""
    img, ppm = board if board is not None else board_image(chart)
    w, h = SIZE
    s = supersample
    step = 8  # the chart mm of every 8th subpixel, exactly; bicubic between (the map is smooth)
    xs = (np.arange(0, w * s + step, step) + 0.5) / s - 0.5
    ys = (np.arange(0, h * s + step, step) + 0.5) / s - 0.5
    X, Y = np.meshgrid(xs, ys)
    pts = np.stack([X.ravel(), Y.ravel()], axis=1).reshape(-1, 1, 2)
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 40, 1e-10)
    q = cv2.undistortPointsIter(pts, K, dist, None, None, crit).reshape(-1, 2)
    R = cv2.Rodrigues(np.asarray(rvec, float))[0]
    t = np.asarray(tvec, float)
    d = np.column_stack([q, np.ones(len(q))])
    lam = (R[:, 2] @ t) / (d @ R[:, 2])
    uv = (d * lam[:, None] - t) @ R[:, :2]  # chart mm
    fine = np.arange(w * s) / step, np.arange(h * s) / step
    mapx = _upsample((uv[:, 0] * ppm - 0.5).reshape(len(ys), len(xs)), fine)
    mapy = _upsample((uv[:, 1] * ppm - 0.5).reshape(len(ys), len(xs)), fine)
    big = cv2.remap(img, mapx, mapy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=255)
    small = cv2.resize(big.astype(np.float32), (w, h), interpolation=cv2.INTER_AREA)
    small = cv2.GaussianBlur(small, (0, 0), blur_px)
    small = 0.15 * 255 + 0.7 * small + np.random.default_rng(seed).normal(0, noise, small.shape)
    return np.clip(small + 0.5, 0, 255).astype(np.uint8)


def field_error_px(K, dist):
    """RMS over a grid of the whole frame of the difference between two distortion fields
    (undistorted minus distorted position, each camera undistorting with its own pinhole), px."""
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 100, 1e-12)
    x, y = np.meshgrid(np.linspace(0, SIZE[0] - 1, 41), np.linspace(0, SIZE[1] - 1, 31))
    g = np.stack([x.ravel(), y.ravel()], axis=1).reshape(-1, 1, 2)
    true = cv2.undistortPointsIter(g, K_TRUE, DIST_TRUE, None, K_TRUE, crit).reshape(-1, 2) - g.reshape(-1, 2)
    got = cv2.undistortPointsIter(g, K, dist, None, K, crit).reshape(-1, 2) - g.reshape(-1, 2)
    return float(np.sqrt(np.mean(np.sum((true - got) ** 2, axis=1))))
