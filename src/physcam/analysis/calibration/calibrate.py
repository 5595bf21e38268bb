"""A lens characterized from chart photographs: pinhole, principal point, distortion, breathing (docs/calibrate.md).

**The fit.** For each focus mark, the chart corners of every view (:mod:`.calibrate_chart`) are
fitted by OpenCV's camera calibration (``cv2.calibrateCameraExtended``: Zhang 2000, "A flexible
new technique for camera calibration", IEEE PAMI 22(11), refined by Levenberg-Marquardt over every
view's pose): a pinhole (f_x, f_y, c_x, c_y in pixels) with Brown-Conrady distortion undistorted
to distorted (k1, k2, p1, p2, k3; OpenCV's ``calib3d`` model, y down). Square photosites are
assumed (f_x / f_y fixed to the sensor's pitch ratio) unless ``fix_aspect=False``. The photosite
pitch is the sensor's size over the image's (``--sensor`` is the recorded area), so the pinhole
focal length in mm is f_y x pitch_y. The residual of each view is the RMS distance, in pixels,
between the corners found and the fitted camera's projection of the chart.

**physcam's models.** The measured field is sampled on a grid over the whole frame (plate pixels
and their undistorted positions for the measured pinhole, about the measured principal point,
y up, picture mm) and handed to :mod:`physcam.analysis.distortion.models`' fitters, exactly as
``physcam distortion --fit`` hands them traced rays: Brown-Conrady D-U and U-D, 3DE4 Radial -
Standard, Degree 4, USD lensDistortion, each with its residual over the frame and its verdict.

**Uncertainty.** A bootstrap over the views (Efron & Tibshirani 1993, ch. 6): the views are drawn
with replacement ``bootstrap`` times and the camera refitted; the standard deviation of each figure
over the refits is its standard uncertainty (the distortion field's: the RMS over the frame of each
grid point's standard deviation, in pixels). OpenCV's own standard deviations of the intrinsics
(from the fit's covariance) are reported beside it. With ``bootstrap=0`` the focal length's and the
principal point's uncertainties are OpenCV's covariance's, and the field's is not estimated (absent,
"not estimated" in print); 1 or 2 refits give no standard deviation and are refused.

**Verdict.** A mark is good when the corners fit (total and per-view residual), the chart covered
the frame, every model fits the measured field, and the principal point lies inside the frame (a
principal point outside it is a wrong fit, e.g. of a detected grid out of order).

**Breathing.** With several marks, each mark's pinhole focal length against the farthest mark's:
``f(mark) / f(farthest) - 1``, with the two uncertainties added in quadrature.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, OpticsError, require_positive
from .chart import ChartView, _cv2
from ..distortion.models import (
    DEFAULT_MAX_RESIDUAL_PX,
    DistortionSamples,
    FittedDistortion,
    fit_models,
)

__all__ = ["MIN_VIEWS", "BreathingRow", "Calibration", "MarkCalibration", "calibrate_mark", "calibrate_views"]

#: Fewest views a focus mark is calibrated from (the pinhole and five coefficients need several poses)
MIN_VIEWS = 5
#: Grid (columns, rows) the measured field is sampled on for physcam's fitters and its uncertainty
FIELD_GRID = (33, 23)
#: A view whose residual exceeds this many times the allowed one is named in the verdict
VIEW_RESIDUAL_FACTOR = 2.0


def _calibrate(views, size, aspect, fix_aspect, guess=None):
    """OpenCV's calibration of ``views``: (rms, K, dist (5,), per-view rms, std of fx fy cx cy k1 k2 p1 p2 k3)."""
    cv2 = _cv2()
    w, h = size
    obj = [v.object_points.astype(np.float32) for v in views]
    img = [v.image_points.astype(np.float32).reshape(-1, 1, 2) for v in views]
    flags = cv2.CALIB_FIX_ASPECT_RATIO if fix_aspect else 0
    if guess is None:
        K = np.array([[aspect, 0.0, w / 2.0], [0.0, 1.0, h / 2.0], [0.0, 0.0, 1.0]])
        dist = np.zeros(5)
    else:
        K, dist = guess[0].copy(), guess[1].copy()
        flags |= cv2.CALIB_USE_INTRINSIC_GUESS
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-12)
    try:
        rms, K, dist, _, _, std_in, _, per_view = cv2.calibrateCameraExtended(obj, img, (w, h), K, dist, flags=flags,
                                                                              criteria=crit)
    except cv2.error as e:
        raise OpticsError(f"OpenCV could not calibrate these views ({str(e).strip().splitlines()[-1]})") from None
    dist = np.asarray(dist, float).ravel()[:5]
    if not (np.isfinite(K).all() and np.isfinite(dist).all() and K[0, 0] > 0 and K[1, 1] > 0):
        raise OpticsError("the calibration diverged: no finite pinhole (more views, at more angles, help)")
    return float(rms), np.asarray(K, float), dist, np.asarray(per_view, float).ravel(), np.asarray(std_in).ravel()[:9]


def _grid(size, n=FIELD_GRID):
    """(m, 2) OpenCV pixel positions on a regular grid over the whole frame, edges included."""
    w, h = size
    x, y = np.meshgrid(np.linspace(-0.5, w - 0.5, n[0]), np.linspace(-0.5, h - 0.5, n[1]))
    return np.column_stack([x.ravel(), y.ravel()])


def undistort_px(K, dist, pts) -> np.ndarray:
    """Undistorted pixel positions (pinhole K) of distorted ones (n, 2), OpenCV px."""
    cv2 = _cv2()
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-12)
    p = np.asarray(pts, np.float64).reshape(-1, 1, 2)
    return cv2.undistortPointsIter(p, K, dist, None, K, crit).reshape(-1, 2)


def distort_px(K, dist, pts) -> np.ndarray:
    """Distorted pixel positions of undistorted ones (n, 2), OpenCV px (``cv2.projectPoints``)."""
    cv2 = _cv2()
    p = np.asarray(pts, float).reshape(-1, 2)
    q = np.column_stack([(p[:, 0] - K[0, 2]) / K[0, 0], (p[:, 1] - K[1, 2]) / K[1, 1], np.ones(len(p))])
    out, _ = cv2.projectPoints(q.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K, dist)
    return out.reshape(-1, 2)


def displacement_px(K, dist, size) -> np.ndarray:
    """(m, 2) undistorted minus distorted position at each :func:`_grid` point of the plate, px."""
    g = _grid(size)
    return undistort_px(K, dist, g) - g


@dataclass
class MarkCalibration:
    """The camera measured at one focus mark (module notes); pixels are OpenCV's (y down)."""

    mark_mm: float | None
    size_px: tuple[int, int]
    sensor_mm: tuple[float, float]
    camera_matrix: np.ndarray
    distortion: np.ndarray  # OpenCV k1, k2, p1, p2, k3 (undistorted to distorted, y down)
    rms_px: float
    views: list[ChartView]
    view_rms_px: list[float]
    opencv_std: dict  # OpenCV's own standard deviations (fit covariance)
    uncertainty: dict  # bootstrap standard deviations
    coverage: float  # share of a 8 x 6 grid of the frame's cells holding a corner
    fits: list[FittedDistortion] = field(default_factory=list)
    max_residual_px: float = DEFAULT_MAX_RESIDUAL_PX
    notes: list[str] = field(default_factory=list)

    @property
    def pitch_mm(self) -> tuple[float, float]:
        return self.sensor_mm[0] / self.size_px[0], self.sensor_mm[1] / self.size_px[1]

    @property
    def focal_length_mm(self) -> tuple[float, float]:
        """Pinhole focal length (x, y) in mm: f px x photosite pitch."""
        return self.camera_matrix[0, 0] * self.pitch_mm[0], self.camera_matrix[1, 1] * self.pitch_mm[1]

    @property
    def principal_point_px(self) -> tuple[float, float]:
        return float(self.camera_matrix[0, 2]), float(self.camera_matrix[1, 2])

    @property
    def principal_offset_mm(self) -> tuple[float, float]:
        """The principal point from the frame centre on the sensor, mm, x right, y up."""
        cx, cy = self.principal_point_px
        w, h = self.size_px
        return (cx - (w - 1) / 2.0) * self.pitch_mm[0], -(cy - (h - 1) / 2.0) * self.pitch_mm[1]

    @property
    def verdict(self) -> tuple[bool, list[str]]:
        """(good, reasons it is not): total residual, every view, coverage, every model fit."""
        why = []
        if self.rms_px > self.max_residual_px:
            why.append(f"the corners miss the fitted camera by {self.rms_px:.3g} px RMS, more than "
                       f"{self.max_residual_px:g} px")
        bad = [v.path for v, r in zip(self.views, self.view_rms_px)
               if r > VIEW_RESIDUAL_FACTOR * self.max_residual_px]
        if bad:
            why.append(f"views off by more than {VIEW_RESIDUAL_FACTOR * self.max_residual_px:g} px RMS: "
                       + ", ".join(bad))
        (cx, cy), (w, h) = self.principal_point_px, self.size_px
        if not (-0.5 <= cx <= w - 0.5 and -0.5 <= cy <= h - 0.5):
            why.append(f"the principal point ({cx:.0f}, {cy:.0f}) px lies outside the {w}x{h} px frame: a wrong fit")
        if self.coverage < 0.5:
            why.append(f"the chart covered only {100 * self.coverage:.0f} % of the frame (shoot it in the "
                       "corners too)")
        why += [f"{f.model} misses the measured field by up to {f.max_residual_px:.3g} px" for f in self.fits
                if not f.acceptable]
        return not why, why

    def undistort_px(self, pts) -> np.ndarray:
        return undistort_px(self.camera_matrix, self.distortion, pts)

    def distort_px(self, pts) -> np.ndarray:
        return distort_px(self.camera_matrix, self.distortion, pts)

    def samples(self, lens_name: str = "measured") -> DistortionSamples:
        """The measured field as physcam's fitters take it: picture mm about the principal point, y up."""
        g = _grid(self.size_px, (49, 33))
        u = self.undistort_px(g)
        c = np.array(self.principal_point_px)
        to_mm = np.array([self.pitch_mm[0], -self.pitch_mm[1]])
        focus = math.inf if self.mark_mm is None else float(self.mark_mm)
        return DistortionSamples(lens_name, focus, (g - c) * to_mm, (u - c) * to_mm, tuple(self.sensor_mm),
                                 tuple(self.size_px), tuple(float(v) for v in self.focal_length_mm))

    def to_dict(self) -> dict:
        k1, k2, p1, p2, k3 = (float(v) for v in self.distortion)
        good, why = self.verdict
        return {
            "focus_mark_mm": self.mark_mm, "size_px": list(self.size_px), "sensor_mm": list(self.sensor_mm),
            "photosite_pitch_mm": list(self.pitch_mm),
            "focal_length_mm": {"x": self.focal_length_mm[0], "y": self.focal_length_mm[1]},
            "focal_length_px": {"x": float(self.camera_matrix[0, 0]), "y": float(self.camera_matrix[1, 1])},
            "principal_point_px": list(self.principal_point_px),
            "principal_point_offset_mm": list(self.principal_offset_mm),
            "opencv": {"k1": k1, "k2": k2, "p1": p1, "p2": p2, "k3": k3,
                       "convention": "OpenCV calib3d: undistorted to distorted, pixels y down"},
            "residual_px": {"rms": self.rms_px, "allowed": self.max_residual_px,
                            "views": [{"image": v.path, "rms": r, "corners": len(v.image_points)}
                                      for v, r in zip(self.views, self.view_rms_px)]},
            "coverage": self.coverage,
            "uncertainty": {k: v for k, v in self.uncertainty.items() if k != "field_std_px"}, "opencv_std": dict(self.opencv_std),
            "fits": [f.to_dict() for f in self.fits], "good": good, "verdict_reasons": why,
            "notes": list(self.notes),
        }


def _coverage(views, size) -> float:
    w, h = size
    cells = set()
    for v in views:
        ij = np.floor(v.image_points / [w / 8.0, h / 6.0]).astype(int)
        cells |= {(int(i), int(j)) for i, j in ij if 0 <= i < 8 and 0 <= j < 6}
    return len(cells) / 48.0


def _bootstrap(views, size, aspect, fix_aspect, guess, pitch, n, seed):
    """Standard deviations of f (mm), the principal point (px) and the field (RMS px) over ``n`` refits."""
    rng = np.random.default_rng(seed)
    fs, cs, fields = [], [], []
    for _ in range(n):
        pick = rng.integers(0, len(views), len(views))
        if len(set(pick.tolist())) < 3:
            continue
        try:
            _, K, dist, _, _ = _calibrate([views[i] for i in pick], size, aspect, fix_aspect, guess)
        except OpticsError:
            continue
        fs.append([K[0, 0] * pitch[0], K[1, 1] * pitch[1]])
        cs.append([K[0, 2], K[1, 2]])
        fields.append(displacement_px(K, dist, size))
    if len(fs) < max(3, n // 2):
        raise OpticsError(f"only {len(fs)} of {n} bootstrap refits converged: too few or too similar views")
    fs, cs, fields = np.array(fs), np.array(cs), np.array(fields)
    field_std = np.sqrt(np.mean(np.sum(fields.std(axis=0, ddof=1) ** 2, axis=1)))
    return {"method": f"bootstrap over the views ({len(fs)} refits)",
            "focal_length_mm": {"x": float(fs[:, 0].std(ddof=1)), "y": float(fs[:, 1].std(ddof=1))},
            "principal_point_px": [float(cs[:, 0].std(ddof=1)), float(cs[:, 1].std(ddof=1))],
            "field_rms_px": float(field_std), "field_std_px": fields.std(axis=0, ddof=1)}


def photosite_pitch(size_px, sensor_mm, *, square: bool = True) -> tuple[float, float]:
    """(x, y) mm per pixel of images of ``size_px`` (width, height) recording a sensor area of ``sensor_mm``;
    with ``square``, an InputError where the two differ by over 1 % (the calibration fixes fx / fy to them)."""
    sw, sh = (require_positive("sensor width", sensor_mm[0], unit="mm"),
              require_positive("sensor height", sensor_mm[1], unit="mm"))
    pitch = (sw / size_px[0], sh / size_px[1])
    if square and abs(pitch[0] / pitch[1] - 1.0) > 0.01:
        raise InputError(f"the images are {size_px[0]}x{size_px[1]} px but the sensor is {sw:g} x {sh:g} mm: the "
                         "photosites would not be square; give the sensor's recorded area (--sensor-width/"
                         "--sensor-height)")
    return pitch


def calibrate_mark(views, sensor_mm, *, fix_aspect: bool = True, bootstrap: int = 30, seed: int = 0,
                   max_residual_px: float = DEFAULT_MAX_RESIDUAL_PX, models=("brown", "3de4", "usd"),
                   lens_name: str = "measured") -> MarkCalibration:
    """Calibrate the views of one focus mark on a sensor of ``sensor_mm`` (width, height; the images'
    recorded area) and fit physcam's models to the measured field (module notes)."""
    views = _check_views(views)
    sensor_mm = _pair("sensor_mm", sensor_mm)
    if len(views) < MIN_VIEWS:
        raise InputError(f"{len(views)} view{'s' if len(views) != 1 else ''} of the chart"
                         f"{_at(views)}: calibrating needs {MIN_VIEWS} or more, at several angles")
    size = views[0].size_px
    pitch = photosite_pitch(size, sensor_mm, square=fix_aspect)
    sw, sh = sensor_mm
    aspect = pitch[1] / pitch[0]  # fx / fy for square-on-the-sensor pixels
    bootstrap = _bootstrap_count(bootstrap)
    rms, K, dist, per_view, std_in = _calibrate(views, size, aspect, fix_aspect)
    unc = _bootstrap(views, size, aspect, fix_aspect, (K, dist), pitch, bootstrap, seed) if bootstrap \
        else _covariance_uncertainty(std_in, pitch)
    names = ("fx_px", "fy_px", "cx_px", "cy_px", "k1", "k2", "p1", "p2", "k3")
    cal = MarkCalibration(views[0].mark_mm, size, (sw, sh), K, dist, rms, views, [float(r) for r in per_view],
                          {n: float(s) for n, s in zip(names, std_in)}, unc, _coverage(views, size),
                          max_residual_px=max_residual_px)
    cal.fits = fit_models(cal.samples(lens_name), models, max_residual_px=max_residual_px)
    cal.notes.append("physcam's models are about the measured principal point "
                     f"({cal.principal_offset_mm[0]:+.4f}, {cal.principal_offset_mm[1]:+.4f}) mm from the frame centre")
    return cal


def _bootstrap_count(n) -> int:
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0 or n in (1, 2):
        raise InputError(f"bootstrap is 0 (OpenCV's covariance) or 3 or more refits, got {n!r}")
    return int(n)


def _covariance_uncertainty(std_in, pitch) -> dict:
    """The uncertainties OpenCV's fit covariance gives (``bootstrap=0``): f in mm, the principal point in
    px; the distortion field's is not estimated (absent)."""
    sfx, sfy, scx, scy = (float(v) for v in std_in[:4])
    return {"method": "OpenCV's covariance of the fit (no bootstrap; the field's uncertainty is not estimated)",
            "focal_length_mm": {"x": sfx * pitch[0], "y": sfy * pitch[1]}, "principal_point_px": [scx, scy]}


def _check_views(views) -> list:
    if isinstance(views, (str, bytes)) or not hasattr(views, "__iter__"):
        raise InputError(f"give the chart views (detect_views), got {type(views).__name__}")
    views = list(views)
    if not all(isinstance(v, ChartView) for v in views):
        raise InputError("give the chart views (physcam.analysis.calibration.chart.detect_views)")
    return views


def _pair(name, v) -> tuple[float, float]:
    if isinstance(v, (str, bytes)) or not hasattr(v, "__len__") or len(v) != 2:
        raise InputError(f"{name} is (width, height) in mm, got {v!r}")
    return (require_positive(f"{name} width", v[0], unit="mm"), require_positive(f"{name} height", v[1], unit="mm"))


def _at(views) -> str:
    m = views[0].mark_mm if views else None
    return "" if m is None else (" at focus infinity" if math.isinf(m) else f" at the focus mark {m:g} mm")


@dataclass(frozen=True)
class BreathingRow:
    mark_mm: float
    focal_length_mm: float
    std_mm: float
    change_pct: float  # against the farthest mark
    change_std_pct: float

    def to_dict(self) -> dict:
        return {"focus_mark_mm": None if math.isinf(self.mark_mm) else self.mark_mm,
                "focal_length_mm": self.focal_length_mm, "focal_length_std_mm": self.std_mm,
                "change_pct": self.change_pct, "change_std_pct": self.change_std_pct}


@dataclass
class Calibration:
    """Every mark's camera, the breathing between them, and optional flat-field and prediction results."""

    marks: list[MarkCalibration]
    breathing: list[BreathingRow]
    lens_name: str = "measured"
    illumination: object | None = None  # calibrate_flat.MeasuredIllumination
    comparison: object | None = None  # calibrate_compare.Comparison
    notes: list[str] = field(default_factory=list)

    @property
    def good(self) -> bool:
        return all(m.verdict[0] for m in self.marks)

    def to_dict(self) -> dict:
        return {"lens": self.lens_name, "marks": [m.to_dict() for m in self.marks],
                "breathing": [r.to_dict() for r in self.breathing], "good": self.good,
                "illumination": None if self.illumination is None else self.illumination.to_dict(),
                "comparison": None if self.comparison is None else self.comparison.to_dict(),
                "notes": list(self.notes)}


def _breathing(marks) -> list[BreathingRow]:
    known = [m for m in marks if m.mark_mm is not None]
    if len(known) < 2:
        return []
    ref = max(known, key=lambda m: m.mark_mm)
    f0 = ref.focal_length_mm[1]
    s0 = (ref.uncertainty.get("focal_length_mm") or {}).get("y", math.nan)
    rows = []
    for m in sorted(known, key=lambda m: -m.mark_mm):
        f = m.focal_length_mm[1]
        s = (m.uncertainty.get("focal_length_mm") or {}).get("y", math.nan)
        rel = 0.0 if m is ref else 100.0 * math.hypot(s / f, s0 / f0) * f / f0
        rows.append(BreathingRow(float(m.mark_mm), float(f), float(s), 100.0 * (f / f0 - 1.0), float(rel)))
    return rows


def calibrate_views(views, sensor_mm, *, lens_name: str = "measured", **kwargs) -> Calibration:
    """Group ``views`` by their focus mark, calibrate each (:func:`calibrate_mark`; ``kwargs`` passed on)
    and tabulate the breathing between the marks (module notes)."""
    views = _check_views(views)
    sensor_mm = _pair("sensor_mm", sensor_mm)
    if not views:
        raise InputError("give the chart views (physcam.analysis.calibration.chart.detect_views)")
    sizes = {v.size_px for v in views}
    if len(sizes) > 1:
        raise InputError(f"the views are of {len(sizes)} image sizes ({', '.join(f'{w}x{h}' for w, h in sizes)}): "
                         "give images of one camera mode")
    groups: dict = {}
    for v in views:
        groups.setdefault(v.mark_mm, []).append(v)
    order = sorted(groups, key=lambda m: (m is None, -(m or 0.0)))
    marks = [calibrate_mark(groups[m], sensor_mm, lens_name=lens_name, **kwargs) for m in order]
    return Calibration(marks, _breathing(marks), lens_name)
