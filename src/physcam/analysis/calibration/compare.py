"""A lens measured from chart photographs against physcam's prediction from its prescription (docs/calibrate.md).

For each focus mark the prediction is the one ``physcam distortion`` makes for that lens, mark and
sensor at the images' resolution (:func:`physcam.analysis.distortion.stmap.distortion_field`): the pinhole
focal length at that focus (breathing included; the best-match pinhole of the lens report) and the
real chief rays' distortion over the frame. The distortions are compared as functions of the
direction of the ray: at the predicted field's traced rays, the undistorted position normalised by
the predicted pinhole (about the frame centre) is distorted by the *measured* Brown-Conrady model
(about the measured principal point) and by the lens; the difference, times the measured focal
length in pixels, is the disagreement in pixels over the frame (RMS and largest), free of the
difference in focal length, which is compared on its own.

A figure **agrees** when its difference from the prediction is at most ``k`` (default 2, about 95 %)
times the measurement's standard uncertainty: the focal length, the breathing between marks, the
distortion field (its RMS difference against the RMS uncertainty of the measured field, from
:mod:`.calibrate`'s bootstrap) and, with flat fields, every ring of the relative illumination.
The focal length's standard uncertainty is the larger of the bootstrap's and OpenCV's (the fit's
covariance): over a few views the bootstrap's own estimate scatters widely (8 views, corners with
0.046 px of noise per axis, 12 draws: it said 0.02-0.08 % where the focal length scattered by
0.049 % and the covariance said 0.044-0.048 %; docs/calibrate.md), so alone it can understate;
the covariance alone would miss errors that are not independent corner noise. The breathing's is
the two marks' so found, added in quadrature.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from ...lens.prescription import Prescription

__all__ = ["AGREEMENT_K", "Comparison", "compare_with_lens"]

#: Coverage factor: a difference within AGREEMENT_K standard uncertainties agrees
AGREEMENT_K = 2.0


def _row(name, measured, predicted, std, unit, k):
    diff = measured - predicted
    agrees = bool(abs(diff) <= k * std) if not math.isnan(std) else False
    return {"figure": name, "measured": float(measured), "predicted": float(predicted), "difference": float(diff),
            "std": float(std), "unit": unit, "agrees": agrees}


@dataclass
class Comparison:
    lens_name: str
    k: float
    rows: list[dict]
    notes: list[str] = field(default_factory=list)

    @property
    def agrees(self) -> bool:
        return all(r["agrees"] for r in self.rows)

    def to_dict(self) -> dict:
        return {"lens": self.lens_name, "coverage_factor": self.k, "agrees": self.agrees, "rows": list(self.rows),
                "rule": f"agrees when |measured - predicted| <= {self.k:g} x the measurement's standard uncertainty",
                "notes": list(self.notes)}


def _focal_std_mm(m) -> float:
    """Standard uncertainty of a mark's pinhole focal length (y), mm: the larger of the bootstrap's and
    OpenCV's covariance's (module notes); NaN when neither is known."""
    boot = (m.uncertainty.get("focal_length_mm") or {}).get("y", math.nan)
    cov = m.opencv_std.get("fy_px", math.nan) * m.pitch_mm[1]
    known = [float(v) for v in (boot, cov) if math.isfinite(v)]
    return max(known) if known else math.nan


def _distortion_difference(mark, field_) -> np.ndarray:
    """Measured minus predicted distortion (px) at the predicted field's traced rays inside the frame."""
    from .chart import _cv2
    from ..distortion.models import samples_from_field

    cv2 = _cv2()
    s = samples_from_field(field_)
    fp = np.array(field_.pinhole_focal_length_mm)
    q = s.undistorted_mm / fp * [1.0, -1.0]  # normalised, y down (OpenCV)
    pred = s.distorted_mm / fp * [1.0, -1.0]
    half = np.array(field_.sensor_mm) / 2.0
    inside = (np.abs(s.distorted_mm) <= half).all(axis=1)
    pts = np.column_stack([q, np.ones(len(q))]).reshape(-1, 1, 3)
    meas, _ = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), np.eye(3), mark.distortion)
    f_px = np.array([mark.camera_matrix[0, 0], mark.camera_matrix[1, 1]])
    return ((meas.reshape(-1, 2) - pred) * f_px)[inside]


def compare_with_lens(calibration, lens: Prescription, *, k: float = AGREEMENT_K, fstop: float | None = None) -> Comparison:
    """Every measured figure of ``calibration`` against ``lens``'s prediction (module notes); ``fstop``: the
    stop the flat fields were shot at (None: wide open)."""
    from ...optics.state import camera_state
    from .calibrate import Calibration
    from ..distortion.stmap import distortion_field

    if not isinstance(calibration, Calibration):
        raise InputError(f"give a Calibration (calibrate_views), got {type(calibration).__name__}")
    if not isinstance(lens, Prescription):
        raise InputError(f"give the lens as a Prescription, got {type(lens).__name__}")
    rows, pred_f, notes = [], {}, []
    for m in calibration.marks:
        mark = math.inf if m.mark_mm is None else float(m.mark_mm)
        fld = distortion_field(camera_state(lens, focus_mm=mark, sensor_mm=tuple(m.sensor_mm)),
                               width_px=m.size_px[0], height_px=m.size_px[1], maps=False)
        where = "infinity" if math.isinf(mark) else f"{mark:g} mm"
        f_pred = fld.pinhole_focal_length_mm[1]
        pred_f[m.mark_mm] = f_pred
        std_f = _focal_std_mm(m)
        rows.append(_row(f"pinhole focal length at {where}", m.focal_length_mm[1], f_pred, std_f, "mm", k))
        d = _distortion_difference(m, fld)
        rms = float(np.sqrt(np.mean(np.sum(d * d, axis=1))))
        std_d = m.uncertainty.get("field_rms_px")
        if std_d is None:  # bootstrap 0: no uncertainty to judge the difference by
            notes.append(f"distortion field at {where}: RMS difference {rms:.3g} px, not judged (its uncertainty is "
                         "not estimated without a bootstrap)")
            continue
        row = _row(f"distortion field at {where} (RMS difference)", rms, 0.0, std_d, "px", k)
        row["max_difference_px"] = float(np.hypot(*d.T).max())
        rows.append(row)
    by_mark = {m.mark_mm: m for m in calibration.marks}
    for r in calibration.breathing[1:]:
        ref = calibration.breathing[0]
        p = 100.0 * (pred_f[r.mark_mm] / pred_f[ref.mark_mm] - 1.0)
        m, m0 = by_mark[r.mark_mm], by_mark[ref.mark_mm]
        std = 100.0 * math.hypot(_focal_std_mm(m) / r.focal_length_mm, _focal_std_mm(m0) / ref.focal_length_mm) \
            * r.focal_length_mm / ref.focal_length_mm
        rows.append(_row(f"breathing {r.mark_mm:g} mm against {ref.mark_mm:g} mm", r.change_pct, p, std, "%", k))
    if calibration.illumination is not None:
        from ...errors import OpticsError

        try:
            rows += _illumination_rows(calibration, lens, k, fstop, pred_f[calibration.marks[0].mark_mm])
        except OpticsError as e:
            notes.append(f"relative illumination not predicted: {e}")
            rows.append(_row("relative illumination (the lens does not cover the frame)", 1.0, 0.0, 0.0, "ratio", k))
    return Comparison(lens.name, k, rows, notes)


def _illumination_rows(calibration, lens, k, fstop, f_pred) -> list[dict]:
    """Each ring of the measured relative illumination against the lens's, interpolated at its image height."""
    from ...optics.state import camera_state
    from ..image_quality.illumination import relative_illumination

    ill, m = calibration.illumination, calibration.marks[0]
    heights = ill.height_mm[1:]
    top = math.degrees(math.atan(1.02 * heights.max() / f_pred))  # the lens's own pinhole at the mark
    # the lens at infinity focus, its iris set to the flat fields' f-stop (None: as its file stops it)
    state = camera_state(lens, fstop=fstop, sensor_mm=tuple(m.sensor_mm))
    res = relative_illumination(state, list(np.linspace(0.0, top, 12)), grid=64)
    pts = [p for p in res.points if p.axis == "y"]
    pred = np.interp(heights, [abs(p.film_height_mm) for p in pts], [p.relative_illumination for p in pts])
    return [_row(f"relative illumination at {h:.2f} mm", r, p, s, "ratio", k)
            for h, r, p, s in zip(heights, ill.relative[1:], pred, ill.std[1:])]
