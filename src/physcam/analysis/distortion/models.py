"""Lens distortion models fitted to real chief rays over the whole frame (docs/distortion.md).

The data are the traced pairs of :func:`physcam.analysis.distortion.stmap.distortion_field` at one focus:
for every traced film point, where the real lens puts it (*distorted*, the plate) and where the
best-match pinhole at that focus puts it (*undistorted*: the paraxial focal length at that focus,
camera at the entrance pupil). Positions here are **picture millimetres**: on the film, measured
from the optical axis (the frame centre), x to the right and y up in the upright picture.

Each model is written in the direction its software writes it, fitted by linear least squares in
that direction with every residual weighted in pixels, and reported with the RMS and the largest
residual in pixels over every traced ray (the whole frame, corners included). The other
direction is Newton's method on the formula.

**Brown-Conrady** (Brown 1966, *Photogrammetric Engineering* 32(3); the radial k1-k3 and
tangential p1, p2 terms as OpenCV's ``calib3d`` writes them; OpenTrackIO 1.0.1 ``lens.distortion``
names the two directions)::

    x' = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 x y + p2 (r^2 + 2 x^2)
    y' = y (1 + k1 r^2 + k2 r^4 + k3 r^6) + p1 (r^2 + 2 y^2) + 2 p2 x y

with x, y normalised by the pinhole focal length (x = x_mm / f_x, y = y_mm / f_y; OpenCV's
normalised camera coordinates, f_x = f_y but for anamorphic lenses). "Brown-Conrady D-U" maps
distorted (x, y) to undistorted (x', y'); "Brown-Conrady U-D" maps undistorted to distorted.

**3DE4 Radial - Standard, Degree 4** (3DEqualizer's Lens Distortion Plugin Kit,
``tde4_ldp_radial_decentered_deg_4_cylindric``): distorted to undistorted in *diagonally
normalised* coordinates, x = x_mm / r_fb with r_fb half the filmback diagonal (around the lens
centre; physcam's lenses are centred)::

    x' = x (1 + c2 r^2 + c4 r^4) + (r^2 + 2 x^2)(u1 + u3 r^2) + 2 x y (v1 + v3 r^2)
    y' = y (1 + c2 r^2 + c4 r^4) + (r^2 + 2 y^2)(v1 + v3 r^2) + 2 x y (u1 + u3 r^2)
    (x_u, y_u) = M (x', y'),  M = [[c^2 q + s^2 / q, (q - 1/q) c s], [(q - 1/q) c s, c^2 / q + s^2 q]]

q = sqrt(1 + b), c, s = cos, sin of phi: "Phi - Cylindric Direction" (degrees) and
"B - Cylindric Bending". c2 "Distortion - Degree 2", u1 "U - Degree 2", v1 "V - Degree 2",
c4 "Quartic Distortion - Degree 4", u3 "U - Degree 4", v3 "V - Degree 4". For an anamorphic lens
3DE's focal length is the Y pinhole and its pixel aspect f_y / f_x; the cylindric terms are fitted
(variable projection: phi and b outside, the six linear coefficients inside).

**USD / Hydra ``lensDistortion:*``** ("standard": k1, k2, center, anaSq, asym, scale): physcam's
convention of :mod:`physcam.analysis.distortion.field` (undistorted to distorted,
r_d = r_u (1 + k1 rho^2 + k2 rho^4), rho = r_u / (gate width / 2)), now fitted over the 2-D frame
at the shot's focus; ``anaSq`` stays 1 (its meaning in hdPrman is not documented).

A model is **good** (``acceptable`` in code and JSON) when its largest residual is at most
``max_residual_px`` (default 0.5 px); otherwise physcam says the residual and calls it "NOT good"
(exporters refuse it): one word, :attr:`FittedDistortion.verdict`, in the CLI and on the residual figure.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import ExportError, InputError, OpticsError, require_positive

__all__ = [
    "DistortionSamples", "FittedDistortion", "BrownConrady", "TDE4RadialStandard", "USDStandard",
    "samples_from_field", "fit_brown_conrady", "fit_tde4_radial", "fit_usd_standard", "fit_models",
    "MODEL_CHOICES", "DEFAULT_MAX_RESIDUAL_PX",
]

from .names import DEFAULT_MAX_RESIDUAL_PX, MODEL_CHOICES  # noqa: E402  (re-exported)
from ...figures import styled


@dataclass(frozen=True)
class DistortionSamples:
    """Traced pairs at one focus, in picture mm from the optical axis (module notes)."""

    lens_name: str
    focus_from_film_mm: float
    distorted_mm: np.ndarray  # (n, 2): where the real lens images the point
    undistorted_mm: np.ndarray  # (n, 2): where the best-match pinhole images it
    sensor_mm: tuple[float, float]
    size_px: tuple[int, int]
    pinhole_focal_length_mm: tuple[float, float]  # (x, y)

    @property
    def px_per_mm(self) -> np.ndarray:
        return np.array([self.size_px[0] / self.sensor_mm[0], self.size_px[1] / self.sensor_mm[1]])

    def residual_px(self, predicted_mm, target_mm) -> np.ndarray:
        """Per-sample distance in plate pixels between two (n, 2) mm arrays."""
        return np.hypot(*((np.asarray(predicted_mm) - np.asarray(target_mm)) * self.px_per_mm).T)


def samples_from_field(result) -> DistortionSamples:
    """The traced pairs of a :class:`~physcam.analysis.distortion.stmap.DistortionField` in picture mm."""
    from .stmap import DistortionField

    if not isinstance(result, DistortionField):
        raise InputError(f"samples_from_field takes a DistortionField, got {type(result).__name__}")
    w, h = result.size_px
    scale = np.array([w / result.sensor_mm[0], h / result.sensor_mm[1]])
    centre = np.array([w / 2.0, h / 2.0])
    return DistortionSamples(
        result.lens_name, result.focus_from_film_mm,
        (result.traced_real_px - centre) / scale, (result.traced_ideal_px - centre) / scale,
        tuple(result.sensor_mm), tuple(result.size_px), tuple(result.pinhole_focal_length_mm))


def _newton(formula, target, start, scale):
    """Solve formula(p) = target for p (n, 2) by Newton with a central-difference Jacobian."""
    p = np.array(start, dtype=float)
    h = 1e-6 * scale
    for _ in range(50):
        f = formula(p) - target
        if np.abs(f).max() < 1e-12 * scale:
            break
        fx = (formula(p + [h, 0.0]) - formula(p - [h, 0.0])) / (2 * h)
        fy = (formula(p + [0.0, h]) - formula(p - [0.0, h])) / (2 * h)
        det = fx[:, 0] * fy[:, 1] - fy[:, 0] * fx[:, 1]
        if not (np.abs(det) > 1e-12).all():
            raise OpticsError("the distortion model folds the picture over here: it has no inverse")
        step = np.stack([(fy[:, 1] * f[:, 0] - fy[:, 0] * f[:, 1]) / det,
                         (-fx[:, 1] * f[:, 0] + fx[:, 0] * f[:, 1]) / det], axis=1)
        p -= step
    if not np.isfinite(p).all() or np.abs(formula(p) - target).max() > 1e-9 * scale:
        raise OpticsError("the distortion model's inverse did not converge")
    return p


@dataclass
class FittedDistortion:
    """A fitted model: its coefficients, direction, and residual over the whole frame (pixels)."""

    model: str
    direction: str  # "D-U" (distorted to undistorted) or "U-D"
    coefficients: dict
    rms_residual_px: float
    max_residual_px: float
    max_residual_allowed_px: float
    size_px: tuple[int, int]
    sensor_mm: tuple[float, float]
    focus_from_film_mm: float
    notes: list[str] = field(default_factory=list)
    residual_at: np.ndarray | None = field(default=None, repr=False)  # (n, 3): x px, y px, residual px

    @property
    def acceptable(self) -> bool:
        return self.max_residual_px <= self.max_residual_allowed_px

    # subclasses: formula (picture mm -> picture mm in the model's direction) and _norm (mm scale)
    def formula(self, p_mm):  # pragma: no cover - abstract
        raise NotImplementedError

    def _mm_scale(self) -> float:
        return 0.5 * math.hypot(*self.sensor_mm)

    def undistort_mm(self, distorted_mm) -> np.ndarray:
        """Undistorted picture mm (n, 2) of distorted ones."""
        d = np.atleast_2d(np.asarray(distorted_mm, dtype=float))
        if self.direction == "D-U":
            return self.formula(d)
        return _newton(self.formula, d, d, self._mm_scale())

    def distort_mm(self, undistorted_mm) -> np.ndarray:
        """Distorted picture mm (n, 2) of undistorted ones."""
        u = np.atleast_2d(np.asarray(undistorted_mm, dtype=float))
        if self.direction == "U-D":
            return self.formula(u)
        return _newton(self.formula, u, u, self._mm_scale())

    @property
    def verdict(self) -> str:
        """The one word for the fit, as the CLI prints it and its residual figure draws it: "good", or "NOT good
        (> N px)" (``acceptable`` in the JSON)."""
        return "good" if self.acceptable else f"NOT good (> {self.max_residual_allowed_px:g} px)"

    def require_acceptable(self, what: str) -> None:
        """Raise :class:`ExportError` when the residual is above the allowed one."""
        if not self.acceptable:
            raise ExportError(
                f"the {self.model} fit misses the traced rays by up to {self.max_residual_px:.3g} px "
                f"(RMS {self.rms_residual_px:.3g} px) over the {self.size_px[0]}x{self.size_px[1]} frame, more than "
                f"the {self.max_residual_allowed_px:g} px allowed: no {what} written (use the ST-maps, or allow "
                "a larger residual with --max-residual)")

    def to_dict(self) -> dict:
        return {
            "model": self.model, "direction": self.direction,
            "direction_meaning": "distorted to undistorted" if self.direction == "D-U" else "undistorted to distorted",
            "coefficients": dict(self.coefficients),
            "residual_px": {"rms": self.rms_residual_px, "max": self.max_residual_px,
                            "allowed_max": self.max_residual_allowed_px, "over": "every traced chief ray of the frame"},
            "acceptable": self.acceptable, "size_px": list(self.size_px), "sensor_mm": list(self.sensor_mm),
            "focus_from_film_mm": None if math.isinf(self.focus_from_film_mm) else self.focus_from_film_mm,
            "notes": list(self.notes),
        }

    @styled
    def plot_residual(self, path=None, *, force: bool = False, units: str = "m"):
        """Residual (pixels) over the frame at every traced ray, with its RMS and max; the focus in the
        title in ``units`` (m, or ft for feet and inches); PNG/SVG if ``path``."""
        from ...units import format_distance
        from .._plot import figure, per_unit, save

        per_unit(units)

        w, h = self.size_px
        fig, ax = figure(6.0, 6.0 * h / w + 0.8)
        r = self.residual_at
        sc = ax.scatter(r[:, 0], r[:, 1], c=r[:, 2], s=14, cmap="viridis", vmin=0.0)
        fig.colorbar(sc, ax=ax, label="residual (px)", shrink=0.8)
        ax.set_xlim(0, w)
        ax.set_ylim(0, h)
        ax.set_aspect("equal")
        ax.set_xlabel("x (px from the left)")
        ax.set_ylabel("y (px from the bottom)")
        focus = "infinity" if math.isinf(self.focus_from_film_mm) else format_distance(self.focus_from_film_mm, units)
        ax.set_title(f"{self.model} ({self.direction}) at focus {focus}\nresidual RMS {self.rms_residual_px:.3f} px, "
                     f"max {self.max_residual_px:.3f} px: {self.verdict}", fontsize=8)
        return save(fig, path, force)


def _finish(fit: FittedDistortion, s: DistortionSamples) -> FittedDistortion:
    """Fill the residual of ``fit`` over the samples, in the model's own direction."""
    if fit.direction == "D-U":
        pred, target = fit.formula(s.distorted_mm), s.undistorted_mm
    else:
        pred, target = fit.formula(s.undistorted_mm), s.distorted_mm
    where = s.distorted_mm  # the residual is drawn where the point is on the plate
    res = s.residual_px(pred, target)
    if not np.isfinite(res).all():
        raise OpticsError(f"the {fit.model} fit gives non-finite positions: no fit")
    px = where * s.px_per_mm + np.array(s.size_px) / 2.0
    fit.rms_residual_px = float(np.sqrt(np.mean(res * res)))
    fit.max_residual_px = float(res.max())
    fit.residual_at = np.column_stack([px, res])
    if not fit.acceptable:
        fit.notes.append(f"residual up to {fit.max_residual_px:.3g} px exceeds {fit.max_residual_allowed_px:g} px: "
                         "not a good fit of this lens")
    return fit


def _check(samples) -> None:
    if not isinstance(samples, DistortionSamples):
        raise InputError(f"give DistortionSamples (samples_from_field), got {type(samples).__name__}")


def _allowed(max_residual_px) -> float:
    """The allowed residual: a positive number of pixels, or infinity (fit without judging)."""
    if isinstance(max_residual_px, float) and max_residual_px == math.inf:
        return math.inf
    return require_positive("allowed residual", max_residual_px, unit="px")


def _lstsq(A, b):
    sol, *_ = np.linalg.lstsq(A, b, rcond=None)
    if not np.isfinite(sol).all():
        raise OpticsError("the distortion fit is singular: no coefficients")
    return sol


# ---------------------------------------------------------------------------------------- Brown-Conrady


def _brown_terms(x, y):
    """Columns (n, 5) per axis of k1, k2, k3, p1, p2 in the Brown-Conrady increment (module notes)."""
    r2 = x * x + y * y
    ax = np.stack([x * r2, x * r2 ** 2, x * r2 ** 3, 2 * x * y, r2 + 2 * x * x], axis=1)
    ay = np.stack([y * r2, y * r2 ** 2, y * r2 ** 3, r2 + 2 * y * y, 2 * x * y], axis=1)
    return ax, ay


@dataclass
class BrownConrady(FittedDistortion):
    """Brown-Conrady (OpenTrackIO's names); ``coefficients``: k1, k2, k3, p1, p2, fx_mm, fy_mm."""

    def formula(self, p_mm):
        c = self.coefficients
        f = np.array([c["fx_mm"], c["fy_mm"]])
        q = np.atleast_2d(p_mm) / f
        ax, ay = _brown_terms(q[:, 0], q[:, 1])
        k = np.array([c["k1"], c["k2"], c["k3"], c["p1"], c["p2"]])
        return np.stack([q[:, 0] + ax @ k, q[:, 1] + ay @ k], axis=1) * f

    def opentrackio(self) -> dict:
        """The OpenTrackIO 1.0.1 ``lens.distortion`` entry in OpenLensIO's units and order, as
        ``physcam live`` sends it (:func:`physcam.analysis.distortion.openlensio.opencv_to_opentrackio`):
        millimetres on the sensor from the centre, y down, for the pinhole of focal length F
        (``pinholeFocalLength``, the Y pinhole here); ``radial`` six terms [k1/F^2, 0, k2/F^4, 0,
        k3/F^6, 0] (OpenLensIO's l1-l6, the denominator's l2, l4, l6 zero), ``tangential``
        [-p1/F, p2/F] (the p1 terms change sign with y). For an anamorphic lens (f_x != f_y) one F
        cannot carry both meridians: the entry is then only the Y meridian's reading, as
        OpenTrackIO 1.0.1 has no anamorphic distortion model.
        """
        from .openlensio import opencv_to_opentrackio

        c = self.coefficients
        return opencv_to_opentrackio(c["k1"], c["k2"], c["k3"], -c["p1"], c["p2"], c["fy_mm"],
                                     direction=self.direction)


def fit_brown_conrady(samples: DistortionSamples, direction: str = "D-U", *,
                      max_residual_px: float = DEFAULT_MAX_RESIDUAL_PX) -> BrownConrady:
    """Least-squares Brown-Conrady k1-k3, p1, p2 in ``direction`` "D-U" or "U-D" (module notes)."""
    _check(samples)
    if direction not in ("D-U", "U-D"):
        raise InputError(f"direction must be 'D-U' or 'U-D', got {direction!r}")
    allowed = _allowed(max_residual_px)
    f = np.array(samples.pinhole_focal_length_mm, dtype=float)
    src, dst = ((samples.distorted_mm, samples.undistorted_mm) if direction == "D-U"
                else (samples.undistorted_mm, samples.distorted_mm))
    q, t = src / f, dst / f
    ax, ay = _brown_terms(q[:, 0], q[:, 1])
    wx, wy = f * samples.px_per_mm  # pixels per normalised unit: the fit minimises pixel error
    A = np.concatenate([ax * wx, ay * wy])
    b = np.concatenate([(t[:, 0] - q[:, 0]) * wx, (t[:, 1] - q[:, 1]) * wy])
    k1, k2, k3, p1, p2 = (float(v) for v in _lstsq(A, b))
    fit = BrownConrady(f"Brown-Conrady {direction}", direction,
                       dict(k1=k1, k2=k2, k3=k3, p1=p1, p2=p2, fx_mm=float(f[0]), fy_mm=float(f[1])),
                       math.nan, math.nan, allowed, samples.size_px, samples.sensor_mm, samples.focus_from_film_mm,
                       ["x, y normalised by the pinhole focal length (fx_mm, fy_mm) about the frame centre"])
    return _finish(fit, samples)


# ---------------------------------------------------------------------------------------- 3DE4

TDE4_MODEL = "3DE4 Radial - Standard, Degree 4"
TDE4_PARAMETERS = ("Distortion - Degree 2", "U - Degree 2", "V - Degree 2", "Quartic Distortion - Degree 4",
                   "U - Degree 4", "V - Degree 4", "Phi - Cylindric Direction", "B - Cylindric Bending")


def _tde4_terms(x, y):
    """Columns (n, 6) per axis of c2, u1, v1, c4, u3, v3 in the radial-decentred increment."""
    r2 = x * x + y * y
    ax = np.stack([x * r2, r2 + 2 * x * x, 2 * x * y, x * r2 * r2, (r2 + 2 * x * x) * r2, 2 * x * y * r2], axis=1)
    ay = np.stack([y * r2, 2 * x * y, r2 + 2 * y * y, y * r2 * r2, 2 * x * y * r2, (r2 + 2 * y * y) * r2], axis=1)
    return ax, ay


def _cylindric(phi_deg, b):
    """The cylindric bending matrix M (module notes)."""
    if not b > -1.0:
        raise InputError(f"the cylindric bending must be above -1, got {b!r}")
    q = math.sqrt(1.0 + b)
    c, s = math.cos(math.radians(phi_deg)), math.sin(math.radians(phi_deg))
    return np.array([[c * c * q + s * s / q, (q - 1 / q) * c * s], [(q - 1 / q) * c * s, c * c / q + s * s * q]])


@dataclass
class TDE4RadialStandard(FittedDistortion):
    """3DE4 Radial - Standard, Degree 4; ``coefficients`` keyed by 3DE's parameter names, plus the lens."""

    def formula(self, p_mm):
        c = self.coefficients
        r_fb = 0.5 * math.hypot(*self.sensor_mm)
        q = np.atleast_2d(p_mm) / r_fb
        ax, ay = _tde4_terms(q[:, 0], q[:, 1])
        k = np.array([c[n] for n in TDE4_PARAMETERS[:6]])
        xy = np.stack([q[:, 0] + ax @ k, q[:, 1] + ay @ k], axis=1)
        M = _cylindric(c["Phi - Cylindric Direction"], c["B - Cylindric Bending"])
        return (xy @ M.T) * r_fb

    def lens_parameters(self) -> dict:
        """3DE4's built-in lens parameters (its identifiers; lengths in cm as 3DE4 takes them)."""
        return tde4_lens_parameters(self, self.sensor_mm[0])

    def to_dict(self) -> dict:
        d = super().to_dict()
        d["lens_parameters"] = self.lens_parameters()
        return d


def tde4_lens_parameters(fit: FittedDistortion, filmback_width_mm: float) -> dict:
    """3DE4's built-in lens parameters of a 3DE4 fit (its identifiers; lengths in cm as 3DE4 takes
    them): the focal length, the filmback (``filmback_width_mm`` wide: the anamorphic model's is the
    desqueezed one), the lens centre on the axis, the pixel aspect and the focus distance (from the film)."""
    c = fit.coefficients
    return {
        "tde4_focal_length_cm": c["focal_length_mm"] / 10.0,
        "tde4_filmback_width_cm": filmback_width_mm / 10.0,
        "tde4_filmback_height_cm": fit.sensor_mm[1] / 10.0,
        "tde4_lens_center_offset_x_cm": 0.0,
        "tde4_lens_center_offset_y_cm": 0.0,
        "tde4_pixel_aspect": c["pixel_aspect"],
        "tde4_custom_focus_distance_cm": None if math.isinf(fit.focus_from_film_mm) else fit.focus_from_film_mm / 10.0,
    }


def _tde4_linear(q, t, M, wpx):
    """Six linear coefficients for a fixed cylindric matrix M; returns (coefficients, residual px (n,))."""
    ax, ay = _tde4_terms(q[:, 0], q[:, 1])
    # residual in pixels: M (q + A k) - t; linear in k with rows M applied
    Ax = M[0, 0] * ax + M[0, 1] * ay
    Ay = M[1, 0] * ax + M[1, 1] * ay
    base = q @ M.T - t
    A = np.concatenate([Ax * wpx[0], Ay * wpx[1]])
    b = -np.concatenate([base[:, 0] * wpx[0], base[:, 1] * wpx[1]])
    k = _lstsq(A, b)
    res = np.hypot((base[:, 0] + Ax @ k) * wpx[0], (base[:, 1] + Ay @ k) * wpx[1])
    return k, res


def _nelder_mead(fun, x0, step, iters=200):
    """Minimise ``fun`` over a small vector by Nelder and Mead's simplex (Nelder & Mead 1965)."""
    pts = [np.array(x0, float)] + [np.array(x0, float) + np.eye(len(x0))[i] * step[i] for i in range(len(x0))]
    vals = [fun(p) for p in pts]
    for _ in range(iters):
        order = np.argsort(vals)
        pts, vals = [pts[i] for i in order], [vals[i] for i in order]
        if abs(vals[-1] - vals[0]) <= 1e-12 * (abs(vals[0]) + 1e-30):
            break
        centre = np.mean(pts[:-1], axis=0)
        refl = centre + (centre - pts[-1])
        fr = fun(refl)
        if fr < vals[0]:
            exp = centre + 2 * (centre - pts[-1])
            fe = fun(exp)
            pts[-1], vals[-1] = (exp, fe) if fe < fr else (refl, fr)
        elif fr < vals[-2]:
            pts[-1], vals[-1] = refl, fr
        else:
            con = centre + 0.5 * (pts[-1] - centre)
            fc = fun(con)
            if fc < vals[-1]:
                pts[-1], vals[-1] = con, fc
            else:
                pts = [pts[0] + 0.5 * (p - pts[0]) for p in pts]
                vals = [fun(p) for p in pts]
    i = int(np.argmin(vals))
    return pts[i], vals[i]


def fit_tde4_radial(samples: DistortionSamples, *, cylindric: bool | None = None,
                    max_residual_px: float = DEFAULT_MAX_RESIDUAL_PX) -> TDE4RadialStandard:
    """Least-squares "3DE4 Radial - Standard, Degree 4" (distorted to undistorted; module notes).

    ``cylindric``: fit Phi and B (default: when the lens is anamorphic, f_x != f_y); else both 0.
    """
    _check(samples)
    allowed = _allowed(max_residual_px)
    fx, fy = samples.pinhole_focal_length_mm
    if cylindric is None:
        cylindric = abs(fx / fy - 1.0) > 1e-6
    r_fb = 0.5 * math.hypot(*samples.sensor_mm)
    q, t = samples.distorted_mm / r_fb, samples.undistorted_mm / r_fb
    wpx = r_fb * samples.px_per_mm
    phi, b = 0.0, 0.0
    k, _ = _tde4_linear(q, t, np.eye(2), wpx)
    if cylindric:
        def cost(v):
            if not v[1] > -0.9:
                return 1e30
            _, r = _tde4_linear(q, t, _cylindric(v[0], v[1]), wpx)
            return float(np.mean(r * r))

        best = None
        for phi0 in (0.0, 45.0, 90.0, 135.0):
            v, c = _nelder_mead(cost, [phi0, 0.01], [20.0, 0.02])
            if best is None or c < best[1]:
                best = (v, c)
        phi, b = float(best[0][0]), float(best[0][1])
        phi = (phi + 90.0) % 180.0 - 90.0  # the matrix has period 180 in phi
        k, _ = _tde4_linear(q, t, _cylindric(phi, b), wpx)
    coeffs = {n: float(v) for n, v in zip(TDE4_PARAMETERS[:6], k)}
    coeffs["Phi - Cylindric Direction"] = phi
    coeffs["B - Cylindric Bending"] = b
    coeffs["focal_length_mm"] = float(fy)
    coeffs["pixel_aspect"] = float(fy / fx)
    notes = ["diagonally normalised: x / r_fb, r_fb = half the filmback diagonal "
             f"({r_fb:.4f} mm); lens centre offset 0"]
    if cylindric:
        notes.append("anamorphic: focal length = the Y pinhole, pixel aspect = f_y / f_x; cylindric terms fitted")
    fit = TDE4RadialStandard(TDE4_MODEL, "D-U", coeffs, math.nan, math.nan, allowed, samples.size_px,
                             samples.sensor_mm, samples.focus_from_film_mm, notes)
    return _finish(fit, samples)


# ---------------------------------------------------------------------------------------- USD


@dataclass
class USDStandard(FittedDistortion):
    """Hydra ``lensDistortion`` "standard" in physcam's convention (module notes)."""

    def formula(self, p_mm):
        c = self.coefficients
        u = np.atleast_2d(p_mm)
        rho2 = np.sum(u * u, axis=1) / (self.sensor_mm[0] / 2.0) ** 2
        return u * (1.0 + c["k1"] * rho2 + c["k2"] * rho2 * rho2)[:, None]

    def usd_attributes(self) -> dict:
        c = self.coefficients
        return {"lensDistortion:type": "standard", "lensDistortion:k1": c["k1"], "lensDistortion:k2": c["k2"],
                "lensDistortion:center": (0.0, 0.0), "lensDistortion:anaSq": 1.0,
                "lensDistortion:asym": (0.0, 0.0), "lensDistortion:scale": 1.0}

    def to_dict(self) -> dict:
        d = super().to_dict()
        d["usd"] = {k: list(v) if isinstance(v, tuple) else v for k, v in self.usd_attributes().items()}
        return d


def fit_usd_standard(samples: DistortionSamples, *,
                     max_residual_px: float = DEFAULT_MAX_RESIDUAL_PX) -> USDStandard:
    """Least-squares k1, k2 of the USD "standard" lensDistortion over the frame (module notes)."""
    _check(samples)
    allowed = _allowed(max_residual_px)
    u, d = samples.undistorted_mm, samples.distorted_mm
    rho2 = np.sum(u * u, axis=1) / (samples.sensor_mm[0] / 2.0) ** 2
    w = samples.px_per_mm
    A = np.concatenate([np.stack([u[:, 0] * rho2, u[:, 0] * rho2 ** 2], axis=1) * w[0],
                        np.stack([u[:, 1] * rho2, u[:, 1] * rho2 ** 2], axis=1) * w[1]])
    b = np.concatenate([(d[:, 0] - u[:, 0]) * w[0], (d[:, 1] - u[:, 1]) * w[1]])
    k1, k2 = (float(v) for v in _lstsq(A, b))
    notes = ["rho = r_undistorted / (gate width / 2); anaSq 1, center (0, 0), asym (0, 0), scale 1"]
    fx, fy = samples.pinhole_focal_length_mm
    if abs(fx / fy - 1.0) > 1e-6:
        notes.append("anamorphic lens: one radial model for both meridians (anaSq left at 1)")
    fit = USDStandard("USD lensDistortion standard", "U-D", dict(k1=k1, k2=k2), math.nan, math.nan, allowed,
                      samples.size_px, samples.sensor_mm, samples.focus_from_film_mm, notes)
    return _finish(fit, samples)


def fit_models(samples: DistortionSamples, names=("brown", "3de4", "usd"), *,
               max_residual_px: float = DEFAULT_MAX_RESIDUAL_PX) -> list[FittedDistortion]:
    """Fit each named model (``brown`` gives both directions; ``nuke`` fits nothing: it uses ST-maps)."""
    _check(samples)
    out: list[FittedDistortion] = []
    for name in dict.fromkeys(names):
        if name == "brown":
            out.append(fit_brown_conrady(samples, "D-U", max_residual_px=max_residual_px))
            out.append(fit_brown_conrady(samples, "U-D", max_residual_px=max_residual_px))
        elif name == "3de4":
            out.append(fit_tde4_radial(samples, max_residual_px=max_residual_px))
        elif name == "usd":
            out.append(fit_usd_standard(samples, max_residual_px=max_residual_px))
        elif name != "nuke":
            raise InputError(f"unknown distortion model {name!r}: choose from {', '.join(MODEL_CHOICES)}")
    return out
