"""Relative illumination against field: the irradiance on the film relative to the centre.

An object at infinity of uniform radiance L sends, from a small solid angle d(omega) about the
direction theta, a collimated beam; the part that passes every real aperture (element rims and
the stop: vignetting) carries the flux dPhi = L d(omega) A(theta), with A(theta) the beam's
cross-section perpendicular to its direction. That flux lands on the film area dA that the lens
maps d(omega) onto, so the irradiance is E = L A(theta) d(omega)/dA (Slater, *Photographic
Systems for Engineers*, ch. 6; Kingslake & Johnson, *Lens Design Fundamentals*, 7.7;
Siew, *Breaking down the cosine fourth power law*, 2019). Relative illumination
RI(theta) = E(theta) / E(0). No cos^4 is put in: it emerges from the real rays.

- A(theta): collimated rays on a fine square grid on a plane in front of the whole front element,
  over the part that a pilot grid found to pass (the pilot grid covers the projection of the
  front element's clear aperture along the beam, so an oblique beam through a curved front
  surface is sampled whole), traced to the film with clipping at every clear semi-diameter and
  the stop; each passing ray stands for its grid cell's area times cos(theta) (the cell
  foreshortened as seen along the beam), times its Fresnel transmission when ``fresnel``.
- d(omega)/dA: the real chief rays (aimed through the stop centre) of the direction cosines
  (l, m) and of (l + e, m), (l, m + e); their film positions give the Jacobian J = d(x, y)/d(l, m),
  and d(omega) = dl dm / n, so dA/d(omega) = |J| n with n = cos(theta). This includes the
  lens's distortion (and anamorphic mapping).

For a distortion-free lens whose pupil stays a circle of fixed size (a small stop at the centre
of curvature of a single refracting surface), A = A0 cos(theta) and dA/d(omega) = f^2 / cos^3
give the cos^4 law (tests/analysis). Fields in degrees, areas in mm^2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, OpticsError, require_finite, require_positive
from ...optics.state import CameraState, takes_camera
from ...figures import styled

__all__ = ["IlluminationPoint", "IlluminationResult", "relative_illumination"]


@dataclass(frozen=True)
class IlluminationPoint:
    axis: str
    field_deg: float
    relative_illumination: float  # E(theta) / E(0)
    cos4: float
    beam_area_mm2: float  # A(theta): passing beam cross-section perpendicular to the beam
    vignetting_factor: float  # A(theta) / (A(0) cos theta): 1 when the pupil is only foreshortened
    mapping_mm2_per_sr: float  # dA / d(omega) on the film
    film_height_mm: float  # chief ray height on the film

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


@dataclass
class IlluminationResult:
    lens_name: str
    wavelength_nm: float
    film_z_mm: float
    fresnel: bool
    grid: int
    points: list[IlluminationPoint]
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"lens": self.lens_name, "wavelength_nm": self.wavelength_nm, "film_z_mm": self.film_z_mm,
                "fresnel": self.fresnel, "grid": self.grid, "points": [p.to_dict() for p in self.points],
                "definition": "irradiance on the film relative to the centre, object of uniform radiance at infinity",
                "notes": list(self.notes)}

    @styled
    def plot(self, path=None, *, force: bool = False):
        from .._plot import figure, save

        fig, ax = figure(5.2, 3.6)
        for axis, style in (("y", "o-"), ("x", "s--")):
            pts = [p for p in self.points if p.axis == axis]
            if pts:
                f = [p.field_deg for p in pts]
                ax.plot(f, [p.relative_illumination for p in pts], style, ms=3,
                        label=f"relative illumination ({axis.upper()})")
                ax.plot(f, [p.vignetting_factor for p in pts], ":", label=f"vignetting factor ({axis.upper()})")
        pts = [p for p in self.points if p.axis == "y"]
        ax.plot([p.field_deg for p in pts], [p.cos4 for p in pts], "-", color="0.5", lw=0.8, label="cos^4")
        ax.set_ylim(0, 1.1)
        ax.set_xlabel("field angle (deg)")
        ax.set_ylabel("relative to the centre")
        ax.set_title(f"{self.lens_name}: relative illumination at {self.wavelength_nm:g} nm", fontsize=8)
        ax.legend(fontsize=7)
        return save(fig, path, force)


#: Largest ``grid`` (rays per side of the fine sampling grid); the grid is traced in row chunks.
MAX_GRID = 2000
_CHUNK_RAYS = 1 << 18


def _launch_window(lens, direction):
    """Start plane z0 and the rectangle on it that holds every ray of ``direction`` that can meet
    the front surface inside its clear aperture: the aperture's projection along the beam."""
    from ...lens.geometry import sag
    from .._chief import start_plane_z

    s = lens.surfaces[0]
    sd = s.semi_diameter
    hs = np.linspace(0.0, sd, 33)
    zs = [sag(s, float(hh), ax) for hh in hs for ax in ("x", "y")]
    zmin, zmax = min(zs), max(zs)
    z0 = start_plane_z(lens)
    tx, ty = direction[0] / direction[2], direction[1] / direction[2]
    margin = 0.02 * sd
    sx = [-(z - z0) * tx for z in (zmin, zmax)]
    sy = [-(z - z0) * ty for z in (zmin, zmax)]
    return z0, (-sd + min(sx) - margin, sd + max(sx) + margin, -sd + min(sy) - margin, sd + max(sy) + margin)


def _beam_areas(lens, directions, wl, film_z, grid, fresnel, stop_sd, aperture, backend):
    """Cross-section (mm^2, perpendicular to the beam) of each collimated beam (one per direction)
    that reaches the film (weighted by the ``aperture`` shape's density at the stop, if any).

    Rays start on a plane in front of the whole front element, over the projection of its clear
    aperture along the beam (every ray that can pass starts there); pilot grids zoom onto the
    part that passes, then a ``grid`` x ``grid`` midpoint grid (traced in row chunks) sums it.
    Every beam still zooming is traced in the same tracer call, and the fine grids of several
    beams share a call too; each beam's rays and sums are those it would get alone.
    """
    from ...trace import RayBatch, trace_to_film

    nb = len(directions)
    z0s, boxes = [], []
    for d in directions:
        z0, box = _launch_window(lens, d)
        z0s.append(z0)
        boxes.append(box)

    def grid_points(k, box, n, rows=None):
        x0, x1, y0, y1 = box
        xs = x0 + (np.arange(n) + 0.5) * (x1 - x0) / n
        ys = y0 + (np.arange(n) + 0.5) * (y1 - y0) / n
        if rows is not None:
            ys = ys[rows]
        X, Y = np.meshgrid(xs, ys)
        return X.ravel(), Y.ravel()

    def passing(jobs):
        """jobs: (beam k, X, Y); one tracer call for all; per job (ok, weight)."""
        pos = np.concatenate([np.stack([X, Y, np.full(X.size, z0s[k])], axis=1) for k, X, Y in jobs])
        dirs = np.concatenate([np.broadcast_to(directions[k], (X.size, 3)) for k, X, _ in jobs])
        out = trace_to_film(lens, RayBatch.from_arrays(pos, dirs, wl), film_z, clip=True,
                            fresnel=fresnel, stop_semi_diameter=stop_sd, aperture=aperture, backend=backend)
        res, a = [], 0
        for _k, X, _ in jobs:
            res.append((out.ok[a:a + X.size], out.weight[a:a + X.size]))
            a += X.size
        return res

    # pilot grids: the whole projected front aperture, then zoom on what passed until the box
    # is tight (it shrinks by less than 10 %), so the fine grid spends its rays on the beam
    npil = 64
    area = [None] * nb
    zooming = list(range(nb))
    for _ in range(8):
        if not zooming:
            break
        jobs = [(k, *grid_points(k, boxes[k], npil)) for k in zooming]
        still = []
        for (k, X, Y), (ok, _w) in zip(jobs, passing(jobs)):
            if not ok.any():
                area[k] = 0.0
                continue
            x0, x1, y0, y1 = boxes[k]
            cx, cy = (x1 - x0) / npil, (y1 - y0) / npil
            nx0, nx1 = X[ok].min() - 2 * cx, X[ok].max() + 2 * cx
            ny0, ny1 = Y[ok].min() - 2 * cy, Y[ok].max() + 2 * cy
            tight = (nx1 - nx0) > 0.9 * (x1 - x0) and (ny1 - ny0) > 0.9 * (y1 - y0)
            boxes[k] = (nx0, nx1, ny0, ny1)
            if not (tight and ok.sum() >= 400):
                still.append(k)
        zooming = still
    # fine grids in row chunks of about _CHUNK_RAYS rays, as many beams' chunks per call as fit
    step = max(1, _CHUNK_RAYS // grid)
    chunks = [(k, a) for k in range(nb) if area[k] is None for a in range(0, grid, step)]
    total = {k: 0.0 for k in range(nb) if area[k] is None}
    per_call = max(1, _CHUNK_RAYS // (step * grid))
    for c in range(0, len(chunks), per_call):
        jobs = [(k, *grid_points(k, boxes[k], grid, slice(a, min(grid, a + step)))) for k, a in chunks[c:c + per_call]]
        for (k, _X, _Y), (ok, w) in zip(jobs, passing(jobs)):
            total[k] += float(w[ok].sum())
    for k, tot in total.items():
        x0, x1, y0, y1 = boxes[k]
        dA = (x1 - x0) * (y1 - y0) / grid**2
        area[k] = tot * dA * directions[k][2]
    return area


def _mappings(lens, lm, wl, film_z, backend, eps=1e-5):
    """Per chief ray of direction cosines (l, m): its film position and dA/d(omega) there (mm^2/sr),
    or None where it (or a neighbour of the finite-difference stencil) does not pass. All the
    stencils are aimed and traced in one batch (each ray is aimed independently)."""
    from ...trace import RayBatch, trace_through
    from .._chief import aim_from_infinity

    n = len(lm)
    L = np.concatenate([np.array([l, l + eps, l - eps, l, l]) for l, _m in lm])
    M = np.concatenate([np.array([m, m, m, m + eps, m - eps]) for _l, m in lm])
    d = np.stack([L, M, np.sqrt(1.0 - L * L - M * M)], axis=1)
    aimed = aim_from_infinity(lens, d, wavelength_nm=wl, backend=backend)
    out = trace_through(lens, RayBatch.from_arrays(aimed.start, aimed.direction, wl), end_z=film_z, clip=False,
                        backend=backend)
    res = []
    for k in range(n):
        s = slice(5 * k, 5 * k + 5)
        if not (aimed.ok[s].all() and out.ok[s].all()):
            res.append(None)
            continue
        x, y = out.x[s], out.y[s]
        jxl, jyl = (x[1] - x[2]) / (2 * eps), (y[1] - y[2]) / (2 * eps)
        jxm, jym = (x[3] - x[4]) / (2 * eps), (y[3] - y[4]) / (2 * eps)
        det = abs(jxl * jym - jxm * jyl)
        res.append((float(x[0]), float(y[0]), det * d[5 * k, 2]))
    return res


@takes_camera
def relative_illumination(
    camera: CameraState,
    fields_deg=None,
    *,
    max_field_deg: float | None = None,
    n_fields: int = 10,
    grid: int = 200,
    fresnel: bool = False,
    wavelength_nm: float | None = None,
    backend: str = "auto",
) -> IlluminationResult:
    """Relative illumination of ``camera`` at field angles in degrees (module notes).

    ``camera``: a :class:`~physcam.optics.state.CameraState` (its focused lens, film plane, iris, iris
    shape, primary wavelength and sensor; the light still comes from infinity; a camera built from a
    bare lens leaves the film at the paraxial image at the wavelength). Default fields: ``n_fields``
    from 0 to the sensor corner (``max_field_deg`` overrides).
    Anamorphic lenses are evaluated in both meridians. ``grid``: rays per side of the sampling
    grid (``grid``^2 per field). A field where no ray passes, or whose chief ray does not, raises
    :class:`OpticsError`. The sensor is the camera's, else Super 35, 24.89 x 18.66 mm
    (:data:`physcam.data.default_sensor.DEFAULT_SENSOR`, the CLI's default too).
    """
    from ...optics.paraxial import gaussian_xy
    from ...trace import paraxial_image_z
    from .._camera import ray_view, sensor_or_default
    from .._chief import field_angles_deg, field_direction

    lens, _, film_z, stop_semi_diameter, aperture, wl, _ = ray_view(camera, wavelength_nm=wavelength_nm)
    sensor_width_mm, sensor_height_mm = sensor_or_default(camera)
    wl = require_positive("wavelength", wl, unit="nm")
    if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or not 16 <= grid <= MAX_GRID:
        raise InputError(f"grid must be a whole number from 16 to {MAX_GRID} (rays per side), got {grid!r}")
    if isinstance(n_fields, bool) or not isinstance(n_fields, (int, np.integer)) or not 2 <= n_fields <= 200:
        raise InputError(f"n_fields must be a whole number from 2 to 200, got {n_fields!r}")
    if film_z is None:
        film_z = paraxial_image_z(lens, wl)
    film_z = require_finite("film_z", film_z)
    g = gaussian_xy(lens, wavelength_nm=wl)
    axes = ("y", "x") if lens.is_anamorphic else ("y",)
    w, h = require_positive("sensor width", sensor_width_mm), require_positive("sensor height", sensor_height_mm)
    d0 = np.array([0.0, 0.0, 1.0])
    # every field's beam and chief-ray stencil traced together (module notes: each is computed as alone)
    todo = [(axis, float(fd)) for axis in axes
            for fd in field_angles_deg(fields_deg, max_field_deg, n_fields, 0.5 * math.hypot(w, h), g[axis].efl)]
    off = [(axis, fd) for axis, fd in todo if fd != 0]
    dirs = [d0] + [field_direction(math.radians(fd), axis)[0] for axis, fd in off]
    areas = _beam_areas(lens, dirs, wl, film_z, grid, fresnel, stop_semi_diameter, aperture, backend)
    maps = _mappings(lens, [(d[0], d[1]) if k else (0.0, 0.0) for k, d in enumerate(dirs)], wl, film_z, backend)
    a0, m0 = areas[0], maps[0]
    if a0 <= 0 or m0 is None:
        raise OpticsError(f"no on-axis light passes {lens.name!r}")
    e0 = a0 / m0[2]
    found = {key: (areas[k + 1], maps[k + 1]) for k, key in enumerate(off)}

    def measure(pairs):
        """(beam area, mapping) of more (axis, field) pairs, traced together."""
        ds = [field_direction(math.radians(fd), axis)[0] for axis, fd in pairs]
        ar = _beam_areas(lens, ds, wl, film_z, grid, fresnel, stop_semi_diameter, aperture, backend)
        mps = _mappings(lens, [(d[0], d[1]) for d in ds], wl, film_z, backend)
        return {key: (ar[k], mps[k]) for k, key in enumerate(pairs)}

    def point(axis, fd, a, mp):
        """The illumination point at field ``fd``, or the reason no light reaches the film there."""
        if a <= 0 or mp is None:
            return "no light" if a <= 0 else "no chief ray"
        c = math.cos(math.radians(fd))
        return IlluminationPoint(axis, float(fd), float((a / mp[2]) / e0), c**4, a, a / (a0 * c), mp[2],
                                 mp[0] if axis == "x" else mp[1])

    from .._chief import clamp_note, widest_passing_deg

    default_range = fields_deg is None and max_field_deg is None
    points, notes = [], []
    for axis in axes:
        fields = [fd for ax, fd in todo if ax == axis]
        got = []
        for i, fd in enumerate(fields):
            p = point(axis, fd, *(found[axis, fd] if fd != 0 else (a0, m0)))
            if isinstance(p, str) and default_range and i > 0:
                # the default range reaches the sensor corner; clamp it to what the lens images
                def passes(f, axis=axis):
                    return not isinstance(point(axis, f, *measure([(axis, f)])[axis, f]), str)

                top = widest_passing_deg(passes, fields[i - 1], fd)
                notes.append(clamp_note(axis, "light and chief rays", top, float(fields[-1])))
                new = [float(f) for f in field_angles_deg(None, top, n_fields, 0.0, 1.0)]
                more = measure([(axis, f) for f in new if f != 0])
                got = [point(axis, f, *(more[axis, f] if f != 0 else (a0, m0))) for f in new]
                p = next((q for q in got if isinstance(q, str)), None)
                if p is None:
                    break
            if isinstance(p, str):
                raise OpticsError(f"at {fd:g} deg ({axis.upper()} meridian) {p} passes {lens.name!r}; "
                                  "choose a smaller field (max_field_deg)")
            got.append(p)
        points += got
    return IlluminationResult(lens.name, float(wl), float(film_z), bool(fresnel), int(grid), points, notes)
