"""Real distortion against field, and a radial model for Hydra's ``lensDistortion:*`` attributes.

For each field angle theta (object at infinity) the real chief ray -- aimed through the centre
of the stop, see :mod:`physcam.analysis._chief` -- is traced to the film plane ``film_z``
(default: the paraxial image plane at the wavelength). Its height h is compared with the
paraxial image height f tan(theta) of the same meridian (f = EFL; Smith, *Modern Optical
Engineering*, 4th ed., 3.5 and 10.5; Kingslake & Johnson, *Lens Design Fundamentals*, 12.4):

    distortion (%) = 100 (h - f tan theta) / (f tan theta)

negative is barrel, positive pincushion. Anamorphic lenses are measured in the X-Z and the
Y-Z meridians with their own EFL each. Heights are in mm on the film, field angles in degrees.

**At a focus** (``focus_mm``, infinity included): the definition of the ST-maps and of
``physcam distortion --focus`` (:mod:`physcam.analysis.distortion.stmap`). The lens is focused at the mark
(mm from the film plane); the chief ray is traced backward from the film height h through the
centre of the stop to the object plane; theta is the angle of its object point seen from the
entrance pupil, and f the best-match pinhole's focal length at that focus
(``GaussianData.pinhole_focal_length``, per meridian). At infinity f is the EFL (but for the X
meridian of an anamorphic, whose film lies where Y focuses). The lens card draws this curve.

Radial model ("standard", two coefficients)::

    r_real = r_ideal (1 + k1 rho^2 + k2 rho^4),    rho = r_ideal / (sensor width / 2)

r_ideal is the distortion-free (pinhole) image radius f tan(theta); rho is normalised so that
the edge of the film gate's width is 1 (the horizontal half-extent of a RenderMan screen window).
k1, k2 come from a linear least-squares fit to the traced distortion. This is what physcam writes
as ``lensDistortion:type = "standard"``, ``lensDistortion:k1``, ``lensDistortion:k2`` (with
``center`` (0, 0), ``anaSq`` 1, ``asym`` (0, 0), ``scale`` 1) on the UsdGeomCamera: Hydra's
camera parameters (``HdCameraTokens``) that hdPrman hands to PxrCamera's ``radial1``/``radial2``.
OpenUSD does not document the normalisation or direction of that mapping; physcam's convention
is the one above (docs/analyses.md), so the coefficients are checked against traced rays, not
against a renderer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM, DEFAULT_SENSOR_WIDTH_MM
from ...errors import InputError, OpticsError, require_finite, require_positive
from ...figures import styled
from ...lens.prescription import Prescription, takes_prescription

__all__ = ["DistortionPoint", "StandardDistortion", "DistortionResult", "real_distortion", "fit_standard_distortion"]


@dataclass(frozen=True)
class DistortionPoint:
    """One field angle in one meridian (mm, degrees, percent)."""

    axis: str
    field_deg: float
    real_height_mm: float
    paraxial_height_mm: float
    distortion_pct: float

    def to_dict(self) -> dict:
        return dict(axis=self.axis, field_deg=self.field_deg, real_height_mm=self.real_height_mm,
                    paraxial_height_mm=self.paraxial_height_mm, distortion_pct=self.distortion_pct)


@dataclass(frozen=True)
class StandardDistortion:
    """Fitted r_real = r_ideal (1 + k1 rho^2 + k2 rho^4), rho = r_ideal / ``norm_radius_mm`` (module notes)."""

    k1: float
    k2: float
    norm_radius_mm: float
    max_residual_pct: float  # largest |fitted - traced| distortion over the fitted points, percent
    center: tuple[float, float] = (0.0, 0.0)
    ana_sq: float = 1.0
    asym: tuple[float, float] = (0.0, 0.0)
    scale: float = 1.0

    def distortion_pct(self, r_ideal_mm) -> np.ndarray:
        rho2 = (np.asarray(r_ideal_mm, dtype=float) / self.norm_radius_mm) ** 2
        return 100.0 * (self.k1 * rho2 + self.k2 * rho2 * rho2)

    def usd_attributes(self) -> dict:
        """Hydra ``lensDistortion:*`` attribute names and values (type token, floats, float2s)."""
        return {
            "lensDistortion:type": "standard",
            "lensDistortion:k1": float(self.k1),
            "lensDistortion:k2": float(self.k2),
            "lensDistortion:center": tuple(map(float, self.center)),
            "lensDistortion:anaSq": float(self.ana_sq),
            "lensDistortion:asym": tuple(map(float, self.asym)),
            "lensDistortion:scale": float(self.scale),
        }

    def to_dict(self) -> dict:
        return {"type": "standard", "k1": self.k1, "k2": self.k2, "norm_radius_mm": self.norm_radius_mm,
                "max_residual_pct": self.max_residual_pct, "center": list(self.center), "anaSq": self.ana_sq,
                "asym": list(self.asym), "scale": self.scale,
                "model": "r_real = r_ideal (1 + k1 rho^2 + k2 rho^4), rho = r_ideal / norm_radius_mm"}


def fit_standard_distortion(r_ideal_mm, distortion_pct, norm_radius_mm: float) -> StandardDistortion:
    """Least-squares k1, k2 of the standard model to (ideal radius, percent distortion) samples."""
    r = np.asarray(r_ideal_mm, dtype=float).ravel()
    d = np.asarray(distortion_pct, dtype=float).ravel() / 100.0
    if r.shape != d.shape:
        raise InputError(f"give one distortion value per radius ({r.size} radii, {d.size} values)")
    if not (np.isfinite(r).all() and np.isfinite(d).all()):
        raise InputError("radii and distortion values must be finite numbers")
    norm = require_positive("normalising radius", norm_radius_mm)
    keep = r > 0
    if keep.sum() < 2:
        raise InputError("fitting the distortion model needs at least two field points off axis")
    rho2 = (r[keep] / norm) ** 2
    A = np.stack([rho2, rho2 * rho2], axis=1)
    (k1, k2), *_ = np.linalg.lstsq(A, d[keep], rcond=None)
    res = 100.0 * np.abs(A @ np.array([k1, k2]) - d[keep])
    return StandardDistortion(float(k1), float(k2), norm, float(res.max()))


@dataclass
class DistortionResult:
    lens_name: str
    wavelength_nm: float
    film_z_mm: float
    efl_x_mm: float  # the ideal's focal length per meridian: the EFL, or at a focus the pinhole's there
    efl_y_mm: float
    sensor_mm: tuple[float, float]
    points: list[DistortionPoint]
    fit: StandardDistortion | None  # None with fewer than two field points off axis
    notes: list[str] = field(default_factory=list)
    #: the focus mark (mm from the film plane) the lens was focused at; None: the legacy infinity
    #: measurement against the film at ``film_z_mm`` (module notes)
    focus_from_film_mm: float | None = None

    def meridian(self, axis: str) -> list[DistortionPoint]:
        return [p for p in self.points if p.axis == axis]

    def to_dict(self) -> dict:
        return {
            "lens": self.lens_name, "wavelength_nm": self.wavelength_nm, "film_z_mm": self.film_z_mm,
            "film_z_reference": "lens space: mm from the first vertex, +z toward the film",
            "efl_x_mm": self.efl_x_mm, "efl_y_mm": self.efl_y_mm, "sensor_mm": list(self.sensor_mm),
            "definition": "100 (h_real - f tan theta) / (f tan theta); negative = barrel",
            "focus_from_film_mm": None if self.focus_from_film_mm is None or math.isinf(self.focus_from_film_mm)
            else self.focus_from_film_mm,
            "focus_is_infinite": self.focus_from_film_mm is None or math.isinf(self.focus_from_film_mm),
            "ideal": IDEAL_AT_FOCUS if self.focus_from_film_mm is not None else
            "f = the EFL, theta the field angle of light from infinity",
            "points": [p.to_dict() for p in self.points],
            "fit": None if self.fit is None else self.fit.to_dict(),
            "usd": None if self.fit is None else self.fit.usd_attributes(), "notes": list(self.notes),
        }

    @styled
    def plot(self, path=None, *, force: bool = False):
        """Percent distortion against field angle per meridian, with the fitted model; PNG if ``path``."""
        from .._plot import figure, save

        fig, ax = figure(5.2, 3.6)
        for axis, style in (("y", "o-"), ("x", "s--")):
            pts = self.meridian(axis)
            if not pts:
                continue
            f = [p.field_deg for p in pts]
            ax.plot(f, [p.distortion_pct for p in pts], style, ms=3, label=f"traced ({axis.upper()} meridian)")
            if self.fit is not None:
                ax.plot(f, self.fit.distortion_pct([abs(p.paraxial_height_mm) for p in pts]), ":",
                        label=f"fit ({axis.upper()})")
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.set_xlabel("field angle (deg)")
        ax.set_ylabel("distortion (%)")
        fit = "" if self.fit is None else f"\nk1 = {self.fit.k1:.5f}, k2 = {self.fit.k2:.5f}"
        ax.set_title(f"{self.lens_name}: real distortion at {self.wavelength_nm:g} nm{fit}", fontsize=8)
        ax.legend(fontsize=7)
        return save(fig, path, force)


def _max_field_deg(lens, axis, wl, half_diag, efl, backend) -> float:
    """Largest field (deg) up to the sensor corner whose chief ray reaches the film unclipped (to 0.01 deg)."""
    from .._chief import field_limit_deg

    return field_limit_deg(lens, axis, max_deg=min(math.degrees(math.atan(half_diag / abs(efl))), 89.0),
                           wavelength_nm=wl, backend=backend)


def _chief_heights(lens, fields_deg, axis, wl, film_z, backend, clip=True):
    """Film heights (mm, along ``axis``) of the aimed chief rays, and which reached the film."""
    from ...trace import RayBatch, paraxial_image_z, trace_through
    from .._chief import aim_from_infinity, field_direction

    if film_z is None:
        film_z = paraxial_image_z(lens, wl)
    aimed = aim_from_infinity(lens, field_direction(np.radians(fields_deg), axis), wavelength_nm=wl, backend=backend)
    out = trace_through(lens, RayBatch.from_arrays(aimed.start, aimed.direction, wl), end_z=film_z, clip=clip,
                        backend=backend)
    ok = aimed.ok & out.ok
    h = out.x if axis == "x" else out.y
    return np.where(ok, h, 0.0), ok


@takes_prescription
def real_distortion(
    lens: Prescription,
    fields_deg=None,
    *,
    sensor_width_mm: float = DEFAULT_SENSOR_WIDTH_MM,
    sensor_height_mm: float = DEFAULT_SENSOR_HEIGHT_MM,
    n_fields: int = 15,
    wavelength_nm: float | None = None,
    film_z: float | None = None,
    focus_mm: float | None = None,
    backend: str = "auto",
) -> DistortionResult:
    """Real distortion of ``lens`` (module notes) and the fitted standard model.

    ``focus_mm``: the focus mark (mm from the film plane; ``math.inf`` allowed): the lens is focused
    there and measured as ``distortion --focus`` and the ST-maps measure it (module notes, "At a
    focus"); ``film_z`` is then not given. Without it, the legacy measurement: light from infinity on
    the film at ``film_z`` (default the paraxial image plane).

    ``fields_deg``: field angles in degrees (default ``n_fields`` angles from 0 to the field whose
    paraxial image reaches the sensor corner, or the widest field whose chief ray passes the
    lens when that is smaller). Anamorphic lenses are measured in both meridians. A field whose
    chief ray misses or is clipped raises :class:`OpticsError` naming the widest field that passes.
    The sensor is ``sensor_width_mm`` x ``sensor_height_mm`` (default Super 35, 24.89 x 18.66 mm: :data:`physcam.data.default_sensor.DEFAULT_SENSOR`, the CLI's default too).
    """
    from ...optics.paraxial import gaussian_xy
    from ...trace import paraxial_image_z

    wl = lens.wavelength_nm if wavelength_nm is None else require_positive("wavelength", wavelength_nm, unit="nm")
    if isinstance(n_fields, bool) or not isinstance(n_fields, (int, np.integer)) or not 3 <= n_fields <= 200:
        raise InputError(f"n_fields must be a whole number from 3 to 200, got {n_fields!r}")
    w = require_positive("sensor width", sensor_width_mm)
    h = require_positive("sensor height", sensor_height_mm)
    if focus_mm is not None:
        from ...units import parse_distance

        focus_mm = parse_distance(focus_mm, name="focus distance", allow_inf=True)  # "2m", "infinity" too
        if film_z is not None:
            raise InputError("give either focus_mm (the lens focused there) or film_z (light from infinity on that "
                             "film plane), not both")
        return _focused_distortion(lens, fields_deg, focus_mm, w, h, n_fields, wl, backend)
    if film_z is None:
        film_z = paraxial_image_z(lens, wl)
    film_z = require_finite("film_z", film_z)
    g = gaussian_xy(lens, wavelength_nm=wl)
    axes = ("y", "x") if lens.is_anamorphic else ("y",)
    half_diag = 0.5 * math.hypot(w, h)
    notes = []
    points: list[DistortionPoint] = []
    for axis in axes:
        efl = g[axis].efl
        if efl <= 0:
            raise OpticsError(f"lens {lens.name!r} has no positive focal length in {axis.upper()}: no real image")
        if fields_deg is None:
            corner = math.degrees(math.atan(half_diag / efl))
            top = _max_field_deg(lens, axis, wl, half_diag, efl, backend)
            if top < corner - 1e-6:
                notes.append(f"{axis.upper()} meridian: chief rays pass only up to {top:.2f} deg "
                             f"(sensor corner at {corner:.2f} deg)")
            fields = np.linspace(0.0, top, n_fields)
        else:
            fields = np.array([require_finite("field angle", f) for f in np.atleast_1d(fields_deg)], dtype=float)
            if fields.size == 0:
                raise InputError("give at least one field angle")
            if (np.abs(fields) >= 89.0).any():
                raise InputError("field angles must lie between -89 and 89 degrees (f tan theta is infinite at 90)")
        heights, ok = _chief_heights(lens, fields, axis, wl, film_z, backend)
        if not ok.all():
            bad = float(fields[~ok][0])
            top = _max_field_deg(lens, axis, wl, half_diag, efl, backend)
            raise OpticsError(
                f"the chief ray at {bad:g} deg ({axis.upper()} meridian) does not pass {lens.name!r}; "
                f"choose fields up to {top:.2f} deg"
            )
        par = efl * np.tan(np.radians(fields))
        with np.errstate(divide="ignore", invalid="ignore"):
            dist = np.where(np.abs(par) > 1e-12, 100.0 * (heights - par) / np.where(par == 0, 1.0, par), 0.0)
        for f, hr, hp, d in zip(fields, heights, par, dist):
            points.append(DistortionPoint(axis, float(f), float(hr), float(hp), float(d)))
    fit = _fit(points, w, notes)
    return DistortionResult(lens.name, float(wl), float(film_z), float(g["x"].efl), float(g["y"].efl), (w, h),
                            points, fit, notes)


def _fit(points, w, notes):
    """The standard model fitted to ``points`` (None, with a note, below two points off axis)."""
    r_ideal = np.array([abs(p.paraxial_height_mm) for p in points])
    if (r_ideal > 0).sum() >= 2:
        return fit_standard_distortion(r_ideal, [p.distortion_pct for p in points], w / 2.0)
    notes.append("fewer than two field points off axis: no distortion model fitted")
    return None


#: What the ideal image is at a focus (the ST-maps' and ``distortion --focus``'s definition).
IDEAL_AT_FOCUS = ("f = the best-match pinhole's focal length at this focus (GaussianData.pinhole_focal_length), "
                  "theta the angle of the object point seen from the entrance pupil; h_real the film height of "
                  "its chief ray, traced backward from the film through the centre of the stop")


class _AtFocus:
    """Chief rays traced backward from film heights of a lens focused at a mark, per meridian: the
    tangent of the object point's angle from the entrance pupil (the ST-maps' ``_real_to_ideal``)."""

    def __init__(self, lens, focus_mm, wl, backend):
        from ...optics.focusing import focus
        from ...optics.paraxial import gaussian

        self.st = focus(lens, focus_mm, axis="y", wavelength_nm=wl)
        q = self.st.prescription
        self.g = {a: gaussian(q, axis=a, wavelength_nm=wl, object_z=self.st.object_z, film_z=self.st.film_z)
                  for a in ("x", "y")}
        for a in ("x", "y"):
            if self.g[a].pinhole_focal_length is None or not self.g[a].efl > 0:
                raise OpticsError(f"lens {lens.name!r} has no best-match pinhole in {a.upper()} at this focus")
        self.wl, self.backend = wl, backend

    def ideal(self, axis, heights):
        """(ideal picture heights f_pin tan theta, ok) of the chief rays from film heights along ``axis``; the
        picture is the film turned by 180 degrees, so a film height +h has its ideal near -h."""
        from .stmap import _real_to_ideal

        hs = np.asarray(heights, dtype=float)
        xy = np.zeros((hs.size, 2))
        xy[:, 0 if axis == "x" else 1] = hs
        ideal, ok = _real_to_ideal(self.st.prescription, self.g["x"], self.g["y"], self.st, xy, self.wl, self.backend)
        return ideal[:, 0 if axis == "x" else 1], ok

    def widest(self, axis, top):
        """The largest film height up to ``top`` whose chief ray leaves the lens (to 1e-3 of ``top``)."""
        if self.ideal(axis, [top])[1][0]:
            return top
        lo, hi = 0.0, top
        while hi - lo > 1e-3 * top:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if self.ideal(axis, [mid])[1][0] else (lo, mid)
        return lo

    def _bracket(self, axis, want, f, reach_mm):
        """(lo, g(lo), hi, g(hi)) about the roots of g(h) = tan(angle(h)) - ``want``: the axis (g = -want) and
        ``reach_mm``, narrowed by the heights f want x 1, 1.05, 1.1, 1.2, 1.4 (a barrel's root lies below f want,
        a pincushion's above), each tried only while a root is still below it, a height whose ray does not
        leave the lens ending the tries (the far end, g NaN); g(``reach_mm``) traced only for a root still
        unbracketed after them (NaN where its ray does not leave the lens). 1903 -> 1525 aims, 191 -> 65
        continuations for the distortion at the lens cards' fields of every library lens at 1 m, 2 m, infinity."""
        lo, g_lo = np.zeros(want.shape), -want  # the axis: angle 0
        hi, g_hi = np.full(want.shape, reach_mm), np.full(want.shape, np.nan)
        open_, far = want > 0.0, want > 0.0
        for factor in (1.0, 1.05, 1.1, 1.2, 1.4):
            x = np.minimum(f * want * factor, reach_mm)
            if not open_.any():
                break
            ideal, ok = self.ideal(axis, np.where(open_, x, 0.0))
            g = np.where(ok, np.abs(ideal) / f - want, np.nan)
            end, below = open_ & ~(ok & (g <= 0.0)), open_ & ok & (g <= 0.0)
            hi, g_hi, far = np.where(end, x, hi), np.where(end, g, g_hi), far & ~end
            lo, g_lo = np.where(below, x, lo), np.where(below, g, g_lo)
            open_ &= below & (x < reach_mm)
        if far.any():
            ideal, ok = self.ideal(axis, np.where(far, hi, 0.0))
            g_hi = np.where(far & ok, np.abs(ideal) / f - want, g_hi)
        return lo, g_lo, hi, g_hi

    def heights_for(self, axis, fields_deg, reach_mm):
        """Film heights whose object points lie ``fields_deg`` off axis (seen from the entrance pupil), and
        which were found: the root of tan(angle) - tan(field) in the film height from the axis to ``reach_mm``,
        where the object angle grows with the height (a height whose chief ray does not leave the lens counts
        as too far), by the Illinois method (regula falsi kept inside its bracket; Dowell and Jarratt, BIT 11,
        1971), halving the bracket while its far end has no chief ray.

        The bracket starts about the pinhole's own height f tan(field) (:meth:`_bracket`): a chief ray traced
        from ``reach_mm``, far outside the frame, mostly does not leave the lens, and aiming it walks out from
        the axis until its branch ends (continuation), most of the time this search took."""
        fields = np.asarray(fields_deg, dtype=float)
        want = np.tan(np.radians(np.abs(fields)))
        f = self.g[axis].pinhole_focal_length
        tol = 1e-11 * want + 1e-14  # within the check below (1e-9), above the Newton aim's own noise
        lo, g_lo, hi, g_hi = self._bracket(axis, want, f, float(reach_mm))
        done, h, side = want == 0.0, np.zeros(fields.shape), np.zeros(fields.shape, int)
        for _ in range(64):
            if done.all():
                break
            falsi = np.isfinite(g_hi) & (g_hi > g_lo)
            x = np.where(falsi, (lo * g_hi - hi * g_lo) / np.where(falsi, g_hi - g_lo, 1.0), 0.5 * (lo + hi))
            x = np.where((x > lo) & (x < hi), x, 0.5 * (lo + hi))
            ideal, ok = self.ideal(axis, x)
            g = np.where(ok, np.abs(ideal) / f - want, np.nan)
            new = ~done & ok & (np.abs(g) <= tol)
            h[new], done = x[new], done | new
            below = ok & (g < 0)
            # Illinois: the end that stayed twice in a row has its value halved
            g_hi = np.where(below & (side == -1), 0.5 * g_hi, g_hi)
            g_lo = np.where(~below & (side == 1), 0.5 * g_lo, g_lo)
            lo, g_lo = np.where(below, x, lo), np.where(below, g, g_lo)
            hi, g_hi = np.where(below, hi, x), np.where(below, g_hi, g)
            side = np.where(below, -1, 1)
        h = np.where(done, h, 0.5 * (lo + hi))
        ideal, ok = self.ideal(axis, h)
        found = ok & (np.abs(np.abs(ideal) / f - want) <= 1e-9 * want + 1e-12)
        return np.sign(fields) * h, found


def _focused_distortion(lens, fields_deg, focus_mm, w, h, n_fields, wl, backend) -> DistortionResult:
    """:func:`real_distortion` of the lens focused at ``focus_mm`` (the ST-maps' definition, IDEAL_AT_FOCUS)."""
    at = _AtFocus(lens, focus_mm, wl, backend)
    axes = ("y", "x") if lens.is_anamorphic else ("y",)
    half_diag = 0.5 * math.hypot(w, h)
    notes, points = [], []
    for axis in axes:
        if fields_deg is None:
            top = at.widest(axis, half_diag)
            if top < half_diag - 1e-6:
                notes.append(f"{axis.upper()} meridian: chief rays leave the lens only from film heights up to "
                             f"{top:.2f} mm (sensor corner at {half_diag:.2f} mm)")
            heights = np.linspace(0.0, top, n_fields)
            ok = np.ones(heights.size, bool)
        else:
            fields = np.array([require_finite("field angle", f) for f in np.atleast_1d(fields_deg)], dtype=float)
            if fields.size == 0 or (np.abs(fields) >= 89.0).any():
                raise InputError("give field angles between -89 and 89 degrees")
            heights, ok = at.heights_for(axis, fields, 4.0 * half_diag)
        ideal, passed = at.ideal(axis, heights)
        keep = ok & passed
        if not keep.any() or (fields_deg is None and not keep.all()):
            raise OpticsError(f"a chief ray of {lens.name!r} focused at {focus_mm:g} mm misses the film in the "
                              f"{axis.upper()} meridian; choose smaller fields")
        if not keep.all():  # e.g. an anamorphic's X meridian covers less than its Y meridian's fields
            gone = ", ".join(f"{f:g}" for f in np.atleast_1d(fields_deg)[~keep])
            notes.append(f"{axis.upper()} meridian: no chief ray reaches the film at {gone} deg; left out")
            heights, ideal = heights[keep], ideal[keep]
        f = at.g[axis].pinhole_focal_length
        for hr, hi in zip(heights, ideal):
            real_pic = -hr  # the upright picture: the film turned by 180 degrees
            d = 0.0 if abs(hi) < 1e-12 else 100.0 * (real_pic - hi) / hi
            sign = -1.0 if hr < 0 else 1.0  # a field below the axis: negative angle and heights, as at infinity
            points.append(DistortionPoint(axis, sign * math.degrees(math.atan(abs(hi) / f)), float(hr),
                                          sign * float(abs(hi)), float(d)))
    fit = _fit(points, w, notes)
    return DistortionResult(lens.name, float(wl), float(at.st.film_z), float(at.g["x"].pinhole_focal_length),
                            float(at.g["y"].pinhole_focal_length), (w, h), points, fit, notes,
                            float(at.st.focus_from_film_mm))
