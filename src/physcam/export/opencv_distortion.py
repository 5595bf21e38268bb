"""An OpenCV pinhole camera (intrinsics and distortion) fitted to a lens's real chief rays.

Omniverse RTX reads this model from the ``OmniLensDistortionOpenCvPinholeAPI`` schema on a
camera (``omni:lensdistortion:opencvPinhole:*``, docs/unreal-omniverse.md), Unreal's Camera
Calibration plugin from its spherical lens model, and OpenCV itself from ``K`` and ``distCoeffs``.

The model (OpenCV, ``calib3d``: "Camera Calibration and 3D Reconstruction")::

    x' = X / Z,  y' = Y / Z,  r^2 = x'^2 + y'^2                      (camera frame: X right, Y down, Z forward)
    g  = (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6)
    x'' = x' g + 2 p1 x' y' + p2 (r^2 + 2 x'^2),   y'' = y' g + p1 (r^2 + 2 y'^2) + 2 p2 x' y'
    u = fx x'' + cx,   v = fy y'' + cy                                (pixels)

physcam's choices (docs/unreal-omniverse.md):

* The camera centre is the **entrance pupil** (the companion camera's centre of projection,
  docs/conventions.md) and ``fx = f_pin * image_width_px / sensor_width_mm``, ``fy = f_pin_y *
  image_height_px / sensor_height_mm`` with ``f_pin`` physcam's best-match pinhole at that focus
  (:attr:`physcam.optics.paraxial.GaussianData.pinhole_focal_length`, per meridian), so the
  undistorted camera is physcam's pinhole companion and only the k's carry the distortion.
* The optical axis meets the sensor centre: ``cx = image_width_px / 2``, ``cy = image_height_px / 2``
  (pixel edges at whole numbers, as Omniverse's documented example, 2048 x 1024 with cx 1024).
* physcam's prescriptions are symmetric about both meridians (no decentring or tilt), so the
  tangential terms vanish by symmetry: ``p1 = p2 = 0`` (and the thin-prism ``s1..s4 = 0``).

The fit: film points on a grid over the whole sensor are traced backward as real chief rays (aimed
through the centre of the stop, :func:`physcam.analysis._chief.aim_from_film`) out of the lens
focused at the mark (:func:`physcam.optics.focusing.focus`). At infinity focus the ray's direction
gives (x', y'); at a finite mark the ray is followed to the plane of sharp focus and the point seen
from the entrance pupil. The sensor image is read upright (the real image is inverted: a film point
(h_x, h_y) mm, y up, is the pixel ``u = cx - h_x px/mm``, ``v = cy + h_y px/mm``). The k's are
least-squares in pixels (linear for ``k1k2k3``; linearised then Gauss-Newton for ``rational``);
``max_residual_px`` is the largest distance between a traced point and the model over the grid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, OpticsError, renamed_parameter, require_positive
from ..lens.prescription import Prescription
from ..optics.state import CameraState, takes_camera

__all__ = ["TERMS", "OMNI_API_SCHEMA", "OMNI_PREFIX", "OpenCvPinhole", "fit_opencv_pinhole", "film_to_pixels"]

#: Distortion terms a fit may use: radial k1 only, k1 k2, k1 k2 k3 (Brown-Conrady, as Unreal's
#: spherical model), or the rational model k1..k6.
TERMS = ("k1", "k1k2", "k1k2k3", "rational")
_N_RADIAL = {"k1": 1, "k1k2": 2, "k1k2k3": 3, "rational": 3}

#: The Omniverse API schema and attribute namespace (docs/unreal-omniverse.md).
OMNI_API_SCHEMA = "OmniLensDistortionOpenCvPinholeAPI"
OMNI_PREFIX = "omni:lensdistortion:opencvPinhole:"

#: Film grid of the fit (points across the width and the height, sensor edges included).
GRID = (17, 13)
MIN_PIXELS, MAX_PIXELS = 16, 65536


def _pixels(name: str, value) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not MIN_PIXELS <= value <= MAX_PIXELS:
        raise InputError(f"{name} must be a whole number of pixels from {MIN_PIXELS} to {MAX_PIXELS}, got {value!r}")
    return int(value)


def _sensor(name: str, value) -> float:
    v = require_positive(name, value)
    if not 0.5 <= v <= 1000.0:
        raise InputError(f"{name} must lie between 0.5 and 1000 mm, got {v:g}")
    return v


def film_to_pixels(film_xy_mm, sensor_width_mm, sensor_height_mm, image_width_px, image_height_px) -> np.ndarray:
    """Film points (n, 2) in mm (lens space, y up) as pixels (n, 2) of the upright image (module notes)."""
    p = np.atleast_2d(np.asarray(film_xy_mm, dtype=float))
    if p.ndim != 2 or p.shape[1] != 2:
        raise InputError(f"film points must have shape (n, 2) in mm, got {p.shape}")
    sx, sy = image_width_px / sensor_width_mm, image_height_px / sensor_height_mm
    return np.stack([image_width_px / 2.0 - p[:, 0] * sx, image_height_px / 2.0 + p[:, 1] * sy], axis=1)


@dataclass(frozen=True)
class OpenCvPinhole:
    """OpenCV pinhole intrinsics (pixels) and distortion coefficients (module notes)."""

    fx: float
    fy: float
    cx: float
    cy: float
    k1: float
    k2: float
    k3: float
    k4: float
    k5: float
    k6: float
    p1: float
    p2: float
    image_width_px: int
    image_height_px: int
    max_residual_px: float
    rms_residual_px: float
    n_points: int
    terms: str
    lens_name: str
    sensor_width_mm: float
    sensor_height_mm: float
    focus_from_film_mm: float
    pinhole_focal_length_x_mm: float
    pinhole_focal_length_y_mm: float
    entrance_pupil_from_film_mm: float
    wavelength_nm: float
    notes: tuple[str, ...] = field(default_factory=tuple)

    def camera_matrix(self) -> np.ndarray:
        """The 3 x 3 camera matrix K of OpenCV."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def distortion_coefficients(self) -> np.ndarray:
        """OpenCV's ``distCoeffs`` order: (k1, k2, p1, p2, k3, k4, k5, k6)."""
        return np.array([self.k1, self.k2, self.p1, self.p2, self.k3, self.k4, self.k5, self.k6])

    def project(self, x_norm, y_norm) -> np.ndarray:
        """Pixels (n, 2) of undistorted normalised points (x' = X/Z, y' = Y/Z; module notes)."""
        x = np.asarray(x_norm, dtype=float)
        y = np.asarray(y_norm, dtype=float)
        r2 = x * x + y * y
        g = (1 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3))) / (1 + r2 * (self.k4 + r2 * (self.k5 + r2 * self.k6)))
        xd = x * g + 2 * self.p1 * x * y + self.p2 * (r2 + 2 * x * x)
        yd = y * g + self.p1 * (r2 + 2 * y * y) + 2 * self.p2 * x * y
        return np.stack([self.fx * xd + self.cx, self.fy * yd + self.cy], axis=-1)

    def usd_attributes(self) -> dict:
        """``OmniLensDistortionOpenCvPinholeAPI`` attribute names and values.

        Types (USD): ``omni:lensdistortion:model`` token; ``imageSize`` int2; every other one float.
        """
        out = {"omni:lensdistortion:model": "opencvPinhole"}
        for k in ("cx", "cy", "fx", "fy"):
            out[OMNI_PREFIX + k] = float(getattr(self, k))
        out[OMNI_PREFIX + "imageSize"] = (int(self.image_width_px), int(self.image_height_px))
        for k in ("k1", "k2", "k3", "k4", "k5", "k6", "p1", "p2"):
            out[OMNI_PREFIX + k] = float(getattr(self, k))
        for k in ("s1", "s2", "s3", "s4"):
            out[OMNI_PREFIX + k] = 0.0
        return out

    def to_dict(self) -> dict:
        d = {k: getattr(self, k) for k in self.__dataclass_fields__ if k != "notes"}
        if math.isinf(d["focus_from_film_mm"]):
            d["focus_from_film_mm"] = None
        d["notes"] = list(self.notes)
        d["camera_matrix"] = self.camera_matrix().tolist()
        d["dist_coeffs_opencv_order"] = self.distortion_coefficients().tolist()
        d["omniverse"] = {"apiSchemas": [OMNI_API_SCHEMA], "attributes": {
            k: (list(v) if isinstance(v, tuple) else v) for k, v in self.usd_attributes().items()}}
        d["conventions"] = ("pixels of the upright image, edges at whole numbers; camera centre at the entrance pupil; "
                            "fx, fy from physcam's best-match pinhole; focus mark mm from the film plane (null = infinity)")
        return d


def _traced_points(lens, focus_mm, w, h, method, wl, backend):
    """Film points (n, 2) mm, undistorted normalised (x', y') (n, 2), notes, focus state."""
    from ..analysis._chief import aim_from_film
    from ..optics import paraxial
    from ..optics.focusing import focus
    from ..trace import RayBatch, trace_through

    st = focus(lens, focus_mm, method=method, axis="y", wavelength_nm=wl)
    q = st.prescription
    gx, gy = np.meshgrid(np.linspace(-w / 2, w / 2, GRID[0]), np.linspace(-h / 2, h / 2, GRID[1]))
    film = np.stack([gx.ravel(), gy.ravel()], axis=1)
    aimed = aim_from_film(q, film, st.film_z, wavelength_nm=wl, backend=backend)
    out = trace_through(q, RayBatch.from_arrays(aimed.start, aimed.direction, wl), reverse=True, backend=backend)
    ok = aimed.ok & out.ok & (out.N < -1e-9)
    notes = []
    if not ok.all():
        notes.append(f"{int((~ok).sum())} of {ok.size} film points have no chief ray into the scene in front of the "
                     "lens (the lens does not cover them as a pinhole can): fitted over the rest")
    if ok.sum() < 8:
        raise OpticsError(f"lens {lens.name!r} covers too little of a {w:g} x {h:g} mm sensor for an OpenCV fit")
    pos = np.stack([out.x, out.y, out.z], axis=1)[ok]
    d = np.stack([out.L, out.M, out.N], axis=1)[ok]
    if math.isinf(st.focus_from_film_mm):
        rel = d  # the scene point lies along the ray, toward -z
    else:
        z_ep = paraxial.gaussian(q, axis="y", wavelength_nm=wl, object_z=st.object_z, film_z=st.film_z).z_entrance_pupil
        t = (st.object_z - pos[:, 2]) / d[:, 2]
        p = pos + t[:, None] * d
        rel = p - np.array([0.0, 0.0, z_ep])
    # OpenCV camera frame: X = x, Y = -y, Z = -z (lens space has y up, +z toward the film)
    xn = rel[:, 0] / (-rel[:, 2])
    yn = rel[:, 1] / rel[:, 2]
    return film[ok], np.stack([xn, yn], axis=1), notes, st


def _fit(xn, yn, xd, yd, fx, fy, terms):
    """k1..k6 (p's zero) minimising pixel residuals of the model to distorted normalised points."""
    r2 = xn * xn + yn * yn
    powers = np.stack([r2, r2 * r2, r2 ** 3], axis=1)
    nr = _N_RADIAL[terms]
    px = np.concatenate([fx * xn[:, None] * powers[:, :nr], fy * yn[:, None] * powers[:, :nr]])
    rhs = np.concatenate([fx * (xd - xn), fy * (yd - yn)])
    if terms != "rational":
        k, *_ = np.linalg.lstsq(px, rhs, rcond=None)
        return np.concatenate([k, np.zeros(6 - nr)])
    # linearised: x'(1 + num) - x_d (1 + den) = 0, then Gauss-Newton on the pixel residuals
    qx = np.concatenate([-fx * xd[:, None] * powers, -fy * yd[:, None] * powers])
    k, *_ = np.linalg.lstsq(np.hstack([px, qx]), rhs, rcond=None)
    sx = np.concatenate([fx * xn, fy * yn])
    target = np.concatenate([fx * xd, fy * yd])
    pw = np.concatenate([powers, powers])
    for _ in range(20):
        num = 1 + pw @ k[:3]
        den = 1 + pw @ k[3:]
        res = sx * num / den - target
        jac = np.hstack([sx[:, None] * pw / den[:, None], -(sx * num / den ** 2)[:, None] * pw])
        step, *_ = np.linalg.lstsq(jac, -res, rcond=None)
        k = k + step
        if np.abs(step).max() < 1e-14:
            break
    return k


def _unpack(lens, sensor_width_mm, sensor_height_mm, focus_mm, method, wavelength_nm):
    """(Prescription, sensor width, height, mark, wavelength) of a CameraState or of the arguments as given."""
    if not isinstance(lens, CameraState):
        return lens, sensor_width_mm, sensor_height_mm, math.inf if focus_mm is None else focus_mm, wavelength_nm
    given = [k for k, v in (("sensor_width_mm", sensor_width_mm), ("sensor_height_mm", sensor_height_mm),
                            ("focus_mm", focus_mm), ("wavelength_nm", wavelength_nm)) if v is not None]
    if given or method != "auto":
        raise InputError(f"a CameraState carries its own focus, sensor and wavelength (focused by the lens's own "
                         f"method): give {', '.join(given) or 'method'} to camera_state(), not here")
    if lens.sensor_mm is None:
        raise InputError("the OpenCV fit needs a sensor: camera_state(lens, ..., sensor_mm=(width, height))")
    return lens.lens, *lens.sensor_mm, lens.focus_from_film_mm, lens.wavelengths_nm[0]


@renamed_parameter("focus_from_film_mm", "focus_mm")
@takes_camera
def fit_opencv_pinhole(
    lens: CameraState | Prescription,
    sensor_width_mm: float | None = None,
    sensor_height_mm: float | None = None,
    image_width_px: int | None = None,
    image_height_px: int | None = None,
    *,
    focus_mm: float | None = None,
    terms: str = "k1k2k3",
    method: str = "auto",
    wavelength_nm: float | None = None,
    backend: str = "auto",
) -> OpenCvPinhole:
    """Fit OpenCV pinhole intrinsics and distortion to ``lens`` focused at ``focus_mm``.

    ``lens``: a :class:`~physcam.optics.state.CameraState` with a sensor (its lens, mark, sensor and
    primary wavelength; leave the sensor, ``focus_mm`` and ``wavelength_nm`` out, ``method`` "auto"),
    or a Prescription with the sensor and ``focus_mm`` (None: infinity). ``terms``: one of
    :data:`TERMS`. Sensor in mm (0.5 to 1000), image in whole pixels (16 to 65536). The focus mark is
    mm in front of the film plane (inf allowed; closer than the lens's closest focus raises
    :class:`OpticsError`). See the module notes for the model and conventions. ``focus_from_film_mm``:
    the old name of ``focus_mm`` (deprecated).
    """
    from ..optics.focusing import focus_method, gaussian_at_focus

    lens, sensor_width_mm, sensor_height_mm, focus_mm, wavelength_nm = _unpack(
        lens, sensor_width_mm, sensor_height_mm, focus_mm, method, wavelength_nm)
    w = _sensor("sensor width", sensor_width_mm)
    h = _sensor("sensor height", sensor_height_mm)
    W = _pixels("image width", image_width_px)
    H = _pixels("image height", image_height_px)
    if terms not in TERMS:
        raise InputError(f"terms must be one of {', '.join(TERMS)}, got {terms!r}")
    wl = lens.wavelength_nm if wavelength_nm is None else require_positive("wavelength", wavelength_nm, unit="nm")
    method = focus_method(lens, method)
    film, xy, notes, st = _traced_points(lens, focus_mm, w, h, method, wl, backend)
    g = {a: gaussian_at_focus(lens, st.focus_from_film_mm, axis=a, focus_axis="y", method=method, wavelength_nm=wl)
         for a in ("x", "y")}
    f_pin = {a: g[a].pinhole_focal_length for a in g}
    if any(v is None or not v > 0 for v in f_pin.values()):
        raise OpticsError(f"lens {lens.name!r} has no best-match pinhole at this focus (film on the exit pupil)")
    fx, fy = f_pin["x"] * W / w, f_pin["y"] * H / h
    cx, cy = W / 2.0, H / 2.0
    pix = film_to_pixels(film, w, h, W, H)
    xd, yd = (pix[:, 0] - cx) / fx, (pix[:, 1] - cy) / fy
    k = _fit(xy[:, 0], xy[:, 1], xd, yd, fx, fy, terms)
    if not np.isfinite(k).all():
        raise OpticsError(f"the OpenCV {terms} fit of {lens.name!r} did not converge; try terms='k1k2k3'")
    ep = g["y"].in_front_of("entrance_pupil")
    cam = OpenCvPinhole(fx, fy, cx, cy, *map(float, k), 0.0, 0.0, W, H, 0.0, 0.0, int(len(film)), terms, lens.name,
                        w, h, float(st.focus_from_film_mm), float(f_pin["x"]), float(f_pin["y"]), float(ep), float(wl),
                        tuple(notes))
    err = np.hypot(*(cam.project(xy[:, 0], xy[:, 1]) - pix).T)
    notes = list(notes)
    if lens.is_anamorphic:
        notes.append("anamorphic: one radial model in normalised coordinates with fx != fy; max_residual_px says how "
                     "well it fits")
    from dataclasses import replace

    return replace(cam, max_residual_px=float(err.max()), rms_residual_px=float(np.sqrt(np.mean(err ** 2))),
                   notes=tuple(notes))
