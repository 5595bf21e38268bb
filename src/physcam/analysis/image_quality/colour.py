"""Longitudinal and lateral colour (chromatic aberration) of a lens, object at infinity.

- **Longitudinal colour** (axial colour): the image plane moves with wavelength. Paraxial: the
  rear focal point z_F'(lambda) from the Gaussian engine (:func:`physcam.optics.paraxial.gaussian`);
  real: where a real ray parallel to the axis at ``zone`` x the entrance-pupil radius crosses
  the axis after the lens. Reported relative to the reference wavelength (d line by default)
  and as the F-C difference z(C) - z(F) (positive: red focuses farther from the lens). For a
  thin lens it is f / Vd to first order (Smith, *Modern Optical Engineering*, 4th ed., 10.4;
  Kingslake & Johnson, *Lens Design Fundamentals*, 5.3).
- **Lateral colour** (transverse colour, chromatic difference of magnification): the height of
  the real chief ray (aimed through the stop centre per wavelength) on the film plane
  ``film_z`` (default: paraxial focus at the reference wavelength), h_F - h_C, in micrometres.

Indices per wavelength come from :func:`physcam.optics.glass.dispersion`: a catalogue glass's
Sellmeier formula when the medium names or matches one, else the normal-line model from (nd, Vd);
a lens file with Vd = 0 everywhere shows no colour at all. ``media`` lists, per distinct medium,
which model was used. Fraunhofer lines: F 486.1327 nm, d 587.5618 nm, C 656.2725 nm.

**Uncertainty.** A normal-line glass's nF - nC is fixed by its Vd, but its partial dispersion is
not known: real glasses scatter about SCHOTT's normal line by about +-0.01 in P_gF (one sigma;
derived from SCHOTT's catalogue in :mod:`physcam.optics.glass`). For each distinct normal-line
medium the analysis refits it with P_gF +- 0.01, traces the paraxial rear focus again (a y-nu
paraxial trace, Smith *Modern Optical Engineering* ch. 3) and takes half the spread; the glasses
are independent, so the effects add in quadrature: ``longitudinal_uncertainty_mm`` (on C - F) and
``curve_uncertainty_mm`` (largest over the 400-700 nm focus-shift curve). Catalogue glasses
count as exact (their makers' formulas; melt-to-melt variation is not modelled).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, OpticsError, require_finite, require_positive
from ...figures import styled
from ...lens.prescription import Prescription
from ...optics.glass import LINE_C_NM, LINE_D_NM, LINE_F_NM, PGF_UNCERTAINTY
from ...optics.state import CameraState, takes_camera

__all__ = ["LateralColourPoint", "ColourResult", "chromatic_aberration"]


@dataclass(frozen=True)
class LateralColourPoint:
    field_deg: float
    heights_mm: dict  # wavelength (nm, as text) -> chief ray height on the film
    lateral_colour_um: float  # h(F) - h(C)

    def to_dict(self) -> dict:
        return {"field_deg": self.field_deg, "heights_mm": dict(self.heights_mm),
                "lateral_colour_um": self.lateral_colour_um}


@dataclass
class ColourResult:
    lens_name: str
    reference_nm: float
    film_z_mm: float
    zone: float
    wavelengths_nm: list[float]
    paraxial_focus_z_mm: list[float]  # rear focal point per wavelength (lens space)
    real_focus_z_mm: list[float]  # zone ray's axis crossing per wavelength
    longitudinal_paraxial_mm: float  # z(C) - z(F), paraxial
    longitudinal_real_mm: float  # z(C) - z(F), real zone ray
    curve_nm: list[float]
    curve_shift_mm: list[float]  # paraxial focus relative to the reference wavelength
    lateral: list[LateralColourPoint]
    efl_mm: float
    notes: list[str] = field(default_factory=list)
    media: list[dict] = field(default_factory=list)  # per distinct dispersive medium: its model
    longitudinal_uncertainty_mm: float = 0.0  # one sigma on C - F from the normal-line glasses' P_gF
    curve_uncertainty_mm: float = 0.0  # one sigma, largest over the focus-shift curve

    def to_dict(self) -> dict:
        return {
            "lens": self.lens_name, "reference_nm": self.reference_nm, "film_z_mm": self.film_z_mm,
            "zone": self.zone, "wavelengths_nm": self.wavelengths_nm,
            "paraxial_focus_z_mm": self.paraxial_focus_z_mm, "real_focus_z_mm": self.real_focus_z_mm,
            "longitudinal_paraxial_mm": self.longitudinal_paraxial_mm,
            "longitudinal_real_mm": self.longitudinal_real_mm, "efl_mm": self.efl_mm,
            "curve": {"wavelength_nm": self.curve_nm, "focus_shift_mm": self.curve_shift_mm},
            "lateral": [p.to_dict() for p in self.lateral],
            "media": list(self.media),
            "uncertainty": {
                "longitudinal_paraxial_mm": self.longitudinal_uncertainty_mm,
                "curve_shift_mm": self.curve_uncertainty_mm,
                "method": f"normal-line glasses refitted with P_gF +- {PGF_UNCERTAINTY} (one sigma of real glasses "
                          "about SCHOTT's normal line), paraxial focus again, effects in quadrature; "
                          "catalogue glasses exact",
            },
            "conventions": "z in lens space (mm from the first vertex, + toward the film); longitudinal = z(C) - z(F); "
                           "lateral = h(F) - h(C) on the film",
            "notes": list(self.notes),
        }

    @styled
    def plot(self, path=None, *, force: bool = False):
        from .._plot import figure, save

        fig, (a1, a2) = figure(9.0, 3.6, ncols=2)
        a1.plot(self.curve_shift_mm, self.curve_nm, "-")
        a1.axvline(0.0, color="0.6", lw=0.6)
        a1.set_xlabel(f"paraxial focus shift from {self.reference_nm:g} nm (mm)")
        a1.set_ylabel("wavelength (nm)")
        a1.set_title(f"longitudinal colour: C - F = {self.longitudinal_paraxial_mm * 1e3:.1f} µm (paraxial)", fontsize=8)
        if self.lateral:
            a2.plot([p.field_deg for p in self.lateral], [p.lateral_colour_um for p in self.lateral], "o-", ms=3)
        a2.axhline(0.0, color="0.6", lw=0.6)
        a2.set_xlabel("field angle (deg)")
        a2.set_ylabel("lateral colour F - C (µm)")
        a2.set_title("lateral colour on the film", fontsize=8)
        fig.suptitle(self.lens_name, fontsize=9)
        return save(fig, path, force)


def _media(lens):
    """Distinct dispersive media of ``lens``, in order: (key, Dispersion)."""
    from ...optics.glass import medium_dispersion

    out = {}
    for s in lens.surfaces:
        m = s.medium
        d = medium_dispersion(m)
        if d.kind != "constant":
            out.setdefault((m.nd, m.vd, m.glass), d)
    return out


def _rear_focus_z(lens, wavelength_nm, models):
    """Paraxial rear focal point z (lens space) by a y-nu trace (Y meridian), indices from
    ``models[(nd, vd, glass)]`` where given, else each medium's own model."""
    from ...optics.glass import medium_index

    y, nu, n = 1.0, 0.0, 1.0
    for s in lens.surfaces:
        key = (s.medium.nd, s.medium.vd, s.medium.glass)
        n2 = float(models[key].index(wavelength_nm)) if key in models else float(medium_index(s.medium, wavelength_nm))
        c = 0.0 if s.kind in ("stop", "flat", "cylindrical_x") or s.radius == 0 else 1.0 / s.radius
        nu = nu - y * (n2 - n) * c
        n = n2
        y = y + s.thickness * nu / n
    # y and nu after the last surface were advanced by its thickness: back up to the last vertex,
    # then on to the axis crossing
    y_last = y - lens.surfaces[-1].thickness * nu / n
    return lens.vertex_z[-1] + (-y_last * n / nu)


def _pgf_uncertainty(lens, wavelengths):
    """One-sigma focus uncertainty (mm) per wavelength from the normal-line glasses' P_gF."""
    from ...optics.glass import normal_line

    wl = list(wavelengths)
    var = np.zeros(len(wl))
    for key, d in _media(lens).items():
        if d.kind != "normal-line":
            continue
        p0 = float(d.pgf)
        plus = {key: normal_line(d.nd, d.vd, p0 + PGF_UNCERTAINTY)}
        minus = {key: normal_line(d.nd, d.vd, p0 - PGF_UNCERTAINTY)}
        dz = np.array([0.5 * (_rear_focus_z(lens, w, plus) - _rear_focus_z(lens, w, minus)) for w in wl])
        var += dz * dz
    return np.sqrt(var)


def _zone_focus(lens, height, wls, stop_sd, backend):
    """Axis crossing z of the zone ray at ``height`` for each wavelength: one ray per wavelength, all
    in one tracer call (a mixed-wavelength batch gives each ray the indices of its own wavelength,
    bit for bit those of a one-wavelength trace)."""
    from ...trace import RayBatch, trace_through

    wl = np.asarray(wls, dtype=float)
    rays = RayBatch.collimated(np.zeros(wl.size), np.full(wl.size, height), -1.0)
    rays.wavelength_nm[:] = wl
    out = trace_through(lens, rays, stop_semi_diameter=stop_sd, backend=backend)
    zs = []
    for k, w in enumerate(wls):
        if not out.ok[k] or out.M[k] >= 0:
            raise OpticsError(
                f"the zone ray at {height:.3g} mm does not reach a real focus through {lens.name!r} at {w:g} nm; "
                "use a smaller zone"
            )
        zs.append(float(out.z[k] - out.y[k] * out.N[k] / out.M[k]))
    return zs


def _chief_heights(lens: Prescription, fields, wls, film_z: float, backend: str):
    """Film heights of the chief rays per wavelength, or (field, wavelength) of the first that does not pass."""
    from ...trace import RayBatch, trace_through
    from .._chief import aim_from_infinity, field_direction

    dirs = field_direction(np.radians(fields), "y")
    aims = [aim_from_infinity(lens, dirs, wavelength_nm=w, backend=backend) for w in wls]
    n = len(dirs)
    # every wavelength's chief rays to the film in one call (per-ray indices: module notes of _zone_focus)
    out = trace_through(lens, RayBatch.from_arrays(np.concatenate([a.start for a in aims]),
                                                   np.concatenate([a.direction for a in aims]),
                                                   np.repeat(np.asarray(wls, dtype=float), n)),
                        end_z=film_z, backend=backend)
    found = {}
    for k, (w, aimed) in enumerate(zip(wls, aims)):
        part = slice(k * n, (k + 1) * n)
        ok = aimed.ok & out.ok[part]
        if not ok.all():
            return float(np.asarray(fields)[~ok][0]), w
        found[w] = out.y[part].copy()
    return found


def _lateral_colour(lens: Prescription, fields, wls, film_z: float, backend: str, *, clamp: bool, n_fields: int):
    """Lateral colour at the fields (chief-ray heights per wavelength, F - C in um) and the clamp note or None.

    ``clamp``: the fields are the default range to the sensor corner, so clamp it to the field every
    wavelength's chief ray passes instead of refusing.
    """
    from .._chief import field_angles_deg

    clamped = None
    heights = _chief_heights(lens, fields, wls, film_z, backend)
    if isinstance(heights, tuple) and clamp and heights[0] > 0:
        from .._chief import clamp_note, widest_passing_deg

        good = max([0.0] + [f for f in fields if f < heights[0]])
        top = widest_passing_deg(lambda f: not isinstance(_chief_heights(lens, [f], wls, film_z, backend), tuple),
                                 good, heights[0])
        clamped = clamp_note("y", "chief rays at every wavelength", top, float(fields[-1]))
        fields = field_angles_deg(None, top, n_fields, 0.0, 1.0)
        heights = _chief_heights(lens, fields, wls, film_z, backend)
    if isinstance(heights, tuple):
        bad, w = heights
        raise OpticsError(f"the chief ray at {bad:g} deg ({w:g} nm) does not pass {lens.name!r}; "
                          "choose smaller fields (--max-field)")
    lateral = [
        LateralColourPoint(float(f), {f"{w:g}": float(heights[w][i]) for w in wls},
                           float((heights[LINE_F_NM][i] - heights[LINE_C_NM][i]) * 1e3))
        for i, f in enumerate(fields)
    ]
    return lateral, clamped


def _glass_model_uncertainty(result: ColourResult, lens: Prescription, media: dict, curve) -> None:
    """Set the longitudinal and curve uncertainties from the normal-line glasses' P_gF +- PGF_UNCERTAINTY."""
    from ...optics.glass import normal_line

    fc = _pgf_uncertainty(lens, [LINE_F_NM, LINE_C_NM] + list(curve))
    # C - F: the perturbation moves F and C foci together; the uncertainty of their difference
    # is computed per glass, not from the two RSS figures
    dl = 0.0
    for key, d in media.items():
        if d.kind != "normal-line":
            continue
        p0 = float(d.pgf)
        zs = []
        for sign in (1.0, -1.0):
            mod = {key: normal_line(d.nd, d.vd, p0 + sign * PGF_UNCERTAINTY)}
            zs.append(_rear_focus_z(lens, LINE_C_NM, mod) - _rear_focus_z(lens, LINE_F_NM, mod))
        dl += (0.5 * (zs[0] - zs[1])) ** 2
    result.longitudinal_uncertainty_mm = float(math.sqrt(dl))
    result.curve_uncertainty_mm = float(fc[2:].max())


@takes_camera
def chromatic_aberration(
    camera: CameraState,
    fields_deg=None,
    *,
    wavelengths_nm=(LINE_F_NM, LINE_D_NM, LINE_C_NM),
    reference_nm: float = LINE_D_NM,
    zone: float = math.sqrt(0.5),
    max_field_deg: float | None = None,
    n_fields: int = 8,
    backend: str = "auto",
) -> ColourResult:
    """Longitudinal and lateral colour of ``camera`` (module notes).

    ``camera``: a :class:`~physcam.optics.state.CameraState` (its focused lens, film plane, iris and
    sensor; the object stays at infinity and the wavelengths are this function's; a camera built from a
    bare lens leaves the film at the paraxial focus at ``reference_nm``).
    ``wavelengths_nm`` are reported; F and C are always added for the F-C figures. ``zone``
    (0-1] is the real ray's height as a fraction of the entrance-pupil radius. Fields in degrees
    (default: ``n_fields`` up to the sensor corner or ``max_field_deg``).
    The sensor is the camera's, else Super 35, 24.89 x 18.66 mm
    (:data:`physcam.data.default_sensor.DEFAULT_SENSOR`, the CLI's default too).
    """
    from ...optics.paraxial import gaussian
    from ...trace import paraxial_image_z
    from .._camera import ray_view, sensor_or_default
    from .._chief import field_angles_deg

    lens, _, film_z, stop, _, _, _ = ray_view(camera.with_aperture(None))  # Gaussian colour: the round iris of the f-number
    sensor_width_mm, sensor_height_mm = sensor_or_default(camera)

    ref = require_positive("reference wavelength", reference_nm, unit="nm")
    zone = require_finite("zone", zone)
    if not 0 < zone <= 1:
        raise InputError(f"zone must be a fraction of the pupil radius in (0, 1], got {zone:g}")
    wls = sorted({float(require_positive("wavelength", w, unit="nm")) for w in wavelengths_nm} | {LINE_F_NM, LINE_C_NM})
    if min(wls) < 300 or max(wls) > 1100:
        raise InputError("wavelengths must lie between 300 and 1100 nm (the glass model is fitted to the visible)")
    g_ref = gaussian(lens, wavelength_nm=ref, stop_semi_diameter=stop)
    if g_ref.efl <= 0:
        raise OpticsError(f"lens {lens.name!r} has no positive focal length: no real image")
    if film_z is None:
        film_z = paraxial_image_z(lens, ref)
    film_z = require_finite("film_z", film_z)
    par = [gaussian(lens, wavelength_nm=w).z_rear_focal_point for w in wls]
    r_ep = 0.5 * g_ref.entrance_pupil_diameter
    real = _zone_focus(lens, zone * r_ep, wls, stop, backend)
    iF, iC = wls.index(LINE_F_NM), wls.index(LINE_C_NM)
    curve = list(np.arange(400.0, 701.0, 10.0))
    z_ref = g_ref.z_rear_focal_point
    shift = [gaussian(lens, wavelength_nm=w).z_rear_focal_point - z_ref for w in curve]

    fields = field_angles_deg(fields_deg, max_field_deg, n_fields,
                              0.5 * math.hypot(sensor_width_mm, sensor_height_mm), g_ref.efl)
    lateral, clamped = _lateral_colour(lens, fields, wls, film_z, backend,
                                       clamp=fields_deg is None and max_field_deg is None, n_fields=n_fields)
    result = ColourResult(
        lens.name, ref, float(film_z), zone, wls, [float(v) for v in par], real,
        float(par[iC] - par[iF]), float(real[iC] - real[iF]),
        [float(v) for v in curve], [float(v) for v in shift], lateral, float(g_ref.efl),
    )
    media = _media(lens)
    result.media = [{"surfaces": [i for i, s in enumerate(lens.surfaces)
                                  if (s.medium.nd, s.medium.vd, s.medium.glass) == k], **d.to_dict()}
                    for k, d in media.items()]
    if any(d.kind == "normal-line" for d in media.values()):
        _glass_model_uncertainty(result, lens, media, curve)
    if clamped:
        result.notes.append(clamped)
    if all(s.medium.vd == 0.0 for s in lens.surfaces):
        # pbrt and ISET files carry no Abbe numbers: every medium is non-dispersive, so zero colour
        # says nothing about the real lens
        result.notes.append("no glass in this lens file has an Abbe number (Vd = 0 everywhere): it is traced "
                            "without dispersion, so the colour figures are zero by construction, not measured")
    return result
