"""A microlens array in front of the sensor: a light-field (plenoptic) camera as a traceable system.

Geometry (lens space, mm, +z toward the film; docs/conventions.md; docs/microlens.md), in ISET3D's
terms (pbrt-v4 ``omni`` camera, isetlens ``lenstool insertmicrolens``, seed 004):

* the **main lens** is a :class:`~physcam.lens.prescription.Prescription` (its focused gaps), stopped
  to ``stop_semi_diameter``;
* the **sensor** (ISET's film) is the plane ``z_sensor``; ``film_to_lens`` = ``z_sensor`` minus the
  main lens's rear vertex (lenstool ``--filmtolens``, omni ``filmdistance``);
* the **array** is ``count_x`` by ``count_y`` identical lenslets tiling the film rectangle
  ``film_width`` by ``film_height`` centred on the axis (omni: the lattice spans the film's physical
  extent), pitch ``film_width / count_x`` by ``film_height / count_y``; lenslet (i, j) is centred at
  ``(-W/2 + (i + 1/2) p_x, -H/2 + (j + 1/2) p_y)`` plus its ISET offset. The array plane is the
  lenslets' rear vertex (the lens plane of a thin lenslet); the sensor lies ``sensor_offset`` behind
  it (omni ``microlensSensorOffset``).

A lenslet is an ideal thin lens of focal length ``focal_length_mm`` (a ray at height h from the
lenslet centre leaves with slope dx/dz reduced by h / f: the perfect lens of first-order optics,
Hecht *Optics* 5.2) or a prescription, traced with physcam's tracer in the lenslet's own frame.
A ray belongs to the lenslet whose cell it crosses on the array's front plane (the lattice lookup is
two floors, vectorised), and the cell walls are opaque: a ray leaving its cell inside a lenslet
prescription is clipped. Rays outside the array are clipped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, OpticsError, require_positive, require_type
from ..lens.prescription import Prescription
from ..optics.state import CameraState, camera_state
from .rays import CLIPPED, MISSED, OK, RayBatch
from .trace import trace_through

__all__ = ["MicrolensArray", "PlenopticCamera", "microlens_array", "main_lens_state", "plenoptic_camera",
           "refract_through_array", "trace_to_sensor", "trace_from_sensor", "subimage_centres"]

#: most lenslets along one side and in all (a Lytro Illum has about 540 x 430; 500000 zero offsets
#: in ISET JSON stay under the 10 MB lens file limit), and pixels under one lenslet along one side
MAX_LENSLETS = 4096
MAX_LENSLETS_TOTAL = 500_000
MAX_PIXELS_PER_LENSLET = 64


@dataclass(frozen=True)
class MicrolensArray:
    """A lattice of identical lenslets (module notes). Lengths in mm.

    ``focal_length_mm`` (an ideal thin lenslet) or ``lenslet`` (a prescription), not both.
    ``offsets_mm`` (count_y * count_x rows of dx, dy, row-major in y then x as in ISET's JSON) moves
    each lenslet's optical centre; None means a regular lattice.
    """

    count_x: int
    count_y: int
    film_width_mm: float
    film_height_mm: float
    sensor_offset_mm: float
    focal_length_mm: float | None = None
    lenslet: Prescription | None = None
    offsets_mm: tuple[tuple[float, float], ...] | None = None

    @property
    def pitch_x(self) -> float:
        return self.film_width_mm / self.count_x

    @property
    def pitch_y(self) -> float:
        return self.film_height_mm / self.count_y

    @property
    def thickness_mm(self) -> float:
        """Front vertex to rear vertex of a lenslet (0 for a thin lenslet)."""
        return 0.0 if self.lenslet is None else float(self.lenslet.total_track)

    def index_at(self, x, y):
        """(ix, iy, inside) of the cells containing the points (x, y) on the array."""
        fx = (np.asarray(x, dtype=np.float64) + self.film_width_mm / 2.0) / self.pitch_x
        fy = (np.asarray(y, dtype=np.float64) + self.film_height_mm / 2.0) / self.pitch_y
        inside = (fx >= 0) & (fx < self.count_x) & (fy >= 0) & (fy < self.count_y)
        ix = np.clip(np.floor(np.where(np.isfinite(fx), fx, -1.0)), 0, self.count_x - 1).astype(np.int64)
        iy = np.clip(np.floor(np.where(np.isfinite(fy), fy, -1.0)), 0, self.count_y - 1).astype(np.int64)
        return ix, iy, inside

    def cell_centres(self, ix, iy):
        """Centres (x, y) of the cells (ix, iy), without the offsets."""
        cx = -self.film_width_mm / 2.0 + (np.asarray(ix) + 0.5) * self.pitch_x
        cy = -self.film_height_mm / 2.0 + (np.asarray(iy) + 0.5) * self.pitch_y
        return cx, cy

    def centres(self, ix, iy):
        """Optical centres (x, y) of the lenslets (ix, iy): the cell centre plus the ISET offset."""
        cx, cy = self.cell_centres(ix, iy)
        if self.offsets_mm is not None:
            off = np.asarray(self.offsets_mm, dtype=np.float64)
            k = np.asarray(iy) * self.count_x + np.asarray(ix)
            cx, cy = cx + off[k, 0], cy + off[k, 1]
        return cx, cy


def microlens_array(count_x: int, count_y: int, film_width_mm: float, film_height_mm: float, *,
                    focal_length_mm: float | None = None, lenslet: Prescription | None = None,
                    sensor_offset_mm: float | None = None, offsets_mm=None) -> MicrolensArray:
    """A validated :class:`MicrolensArray`. ``sensor_offset_mm`` defaults to the lenslet's focal
    length (thin) or its paraxial back focal distance (prescription): the sensor in the lenslets'
    focal plane, the plenoptic 1.0 camera (Ng et al. 2005)."""
    for name, v in (("count_x", count_x), ("count_y", count_y)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 1 <= v <= MAX_LENSLETS:
            raise InputError(f"{name} must be a whole number of lenslets from 1 to {MAX_LENSLETS}, got {v!r}")
    if count_x * count_y > MAX_LENSLETS_TOTAL:
        raise InputError(f"{count_x} x {count_y} lenslets is more than {MAX_LENSLETS_TOTAL}")
    w = require_positive("film width", film_width_mm)
    h = require_positive("film height", film_height_mm)
    if (focal_length_mm is None) == (lenslet is None):
        raise InputError("give the lenslet either as a thin lens (focal_length_mm) or as a prescription (lenslet)")
    if lenslet is not None:
        require_type("lenslet", lenslet, Prescription, "load one with physcam.lens.library.load_lens")
        if lenslet.is_anamorphic:
            raise InputError(f"lenslet {lenslet.name!r} is anamorphic; physcam's lenslets are rotationally symmetric")
        from ..optics.paraxial import gaussian

        g = gaussian(lenslet)
        if not g.efl > 0:
            raise OpticsError(f"lenslet {lenslet.name!r} has no positive focal length ({g.efl:g} mm)")
        default_offset = g.bfl
    else:
        f = require_positive("lenslet focal length", focal_length_mm)
        if f > 1e5:
            raise InputError(f"lenslet focal length {f:g} mm is beyond any microlens")
        focal_length_mm = f
        default_offset = f
    b = default_offset if sensor_offset_mm is None else require_positive("sensor offset", sensor_offset_mm)
    if not (math.isfinite(b) and b > 0):
        raise OpticsError(f"the lenslet's back focal distance is {b:g} mm: give the sensor offset")
    offs = None
    if offsets_mm is not None:
        a = np.asarray(offsets_mm, dtype=np.float64)
        if a.shape != (count_x * count_y, 2) or not np.isfinite(a).all():
            raise InputError(f"offsets must be {count_x * count_y} finite (dx, dy) pairs in mm, got shape {a.shape}")
        if (np.abs(a[:, 0]) > w / count_x).any() or (np.abs(a[:, 1]) > h / count_y).any():
            raise InputError("a lenslet offset moves its centre by more than one pitch")
        offs = tuple((float(u), float(v)) for u, v in a) if a.any() else None
    return MicrolensArray(int(count_x), int(count_y), w, h, float(b), focal_length_mm, lenslet, offs)


@dataclass(frozen=True)
class PlenopticCamera:
    """Main lens, microlens array and sensor (module notes). ``z_*`` are lens-space z (mm) of the
    main lens's first vertex frame; the sensor has ``pixels_per_lenslet`` square pixels per pitch."""

    main: Prescription
    stop_semi_diameter: float
    array: MicrolensArray
    z_sensor: float
    pixels_per_lenslet: int = 9

    @property
    def z_array(self) -> float:
        """The array plane: the lenslets' rear vertex (a thin lenslet's lens plane)."""
        return self.z_sensor - self.array.sensor_offset_mm

    @property
    def z_array_front(self) -> float:
        """The lenslets' front vertex plane, where a ray's lenslet is looked up."""
        return self.z_array - self.array.thickness_mm

    @property
    def film_to_lens_mm(self) -> float:
        """Main lens rear vertex to the sensor (lenstool ``--filmtolens``)."""
        return self.z_sensor - self.main.vertex_z[-1]

    @property
    def resolution(self) -> tuple[int, int]:
        """(width, height) of the raw sensor image in pixels."""
        return self.array.count_x * self.pixels_per_lenslet, self.array.count_y * self.pixels_per_lenslet

    @property
    def pixel_size(self) -> tuple[float, float]:
        """(x, y) pixel pitch on the sensor, mm."""
        return self.array.pitch_x / self.pixels_per_lenslet, self.array.pitch_y / self.pixels_per_lenslet


def main_lens_state(main: Prescription, array: MicrolensArray, *, focus_mm: float,
                    fstop: float | None = None) -> CameraState:
    """The main lens's :class:`~physcam.optics.state.CameraState` focused (unit or internal) so that a
    subject ``focus_mm`` in front of the **sensor** is imaged on the array plane, its film (plenoptic
    1.0); its iris at ``fstop`` (None: the stop as in its file)."""
    require_type("main", main, Prescription, "load one with physcam.lens.library.load_lens")
    require_type("array", array, MicrolensArray, "build one with physcam.trace.microlens.microlens_array")
    b = array.sensor_offset_mm
    d = require_positive("focus distance", focus_mm)
    if not d > b + main.total_track:
        raise InputError(f"focus distance {d:g} mm is inside the camera (sensor offset {b:g} mm)")
    return camera_state(main, focus_mm=d - b, fstop=fstop)  # the mark from the array, the main lens's film


def plenoptic_camera(main, array: MicrolensArray, *, focus_mm: float | None = None,
                     film_to_lens_mm: float | None = None, fstop: float | None = None,
                     pixels_per_lenslet: int = 9) -> PlenopticCamera:
    """Put ``array`` in front of the sensor behind ``main``.

    ``main``: a :class:`~physcam.optics.state.CameraState` whose film plane is the array's (see
    :func:`main_lens_state`), or a Prescription placed either by ``focus_mm``: focused so that a
    subject ``focus_mm`` in front of the **sensor** is imaged on the array plane (plenoptic 1.0);
    or by ``film_to_lens_mm``: the sensor lies this far behind the main lens's rear vertex, as
    lenstool and ISET3D set it. ``fstop`` stops a Prescription down (default: the stop as in its file).
    """
    if not isinstance(main, CameraState):
        require_type("main", main, Prescription, "load one with physcam.lens.library.load_lens, or a CameraState "
                     "(physcam.trace.microlens.main_lens_state)")
    require_type("array", array, MicrolensArray, "build one with physcam.trace.microlens.microlens_array")
    if isinstance(pixels_per_lenslet, bool) or not isinstance(pixels_per_lenslet, (int, np.integer)) \
            or not 1 <= pixels_per_lenslet <= MAX_PIXELS_PER_LENSLET:
        raise InputError(f"pixels per lenslet must be a whole number from 1 to {MAX_PIXELS_PER_LENSLET}, "
                         f"got {pixels_per_lenslet!r}")
    lens = main.lens if isinstance(main, CameraState) else main
    if lens.is_anamorphic:
        raise InputError(f"main lens {lens.name!r} is anamorphic; the light-field camera takes a spherical lens")
    b = array.sensor_offset_mm
    if isinstance(main, CameraState):
        if not (focus_mm is None and film_to_lens_mm is None and fstop is None):
            raise InputError("a CameraState carries its own focus and f-stop: the array lies on its film plane")
        cam = main
    elif (focus_mm is None) == (film_to_lens_mm is None):
        raise InputError("place the sensor either by a focus distance or by the film-to-lens distance, not both")
    elif focus_mm is not None:
        cam = main_lens_state(main, array, focus_mm=focus_mm, fstop=fstop)
    else:
        cam = None
    if cam is not None:
        return PlenopticCamera(cam.focused, float(cam.stop_semi_diameter), array, float(cam.film_z + b),
                               int(pixels_per_lenslet))
    stop = camera_state(main, fstop=fstop).stop_semi_diameter
    z_sensor = main.vertex_z[-1] + require_positive("film-to-lens distance", film_to_lens_mm)
    if z_sensor - b - array.thickness_mm <= main.vertex_z[-1]:
        raise InputError(f"film-to-lens distance {film_to_lens_mm:g} mm leaves no room for the array "
                         f"({b + array.thickness_mm:g} mm in front of the sensor)")
    return PlenopticCamera(main, float(stop), array, float(z_sensor), int(pixels_per_lenslet))


def _propagate(rays: RayBatch, z: float) -> None:
    """Move the live rays along their directions to the plane ``z`` (in place); a ray parallel to
    it is MISSED."""
    live = rays.flag == OK
    n = rays.N[live]
    bad = n == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (z - rays.z[live]) / n
    rays.x[live] += np.where(bad, 0.0, t * rays.L[live])
    rays.y[live] += np.where(bad, 0.0, t * rays.M[live])
    rays.z[live] = np.where(bad, rays.z[live], z)
    idx = np.flatnonzero(live)[bad]
    _lose(rays, idx, MISSED)


def _lose(rays: RayBatch, idx, flag: int) -> None:
    if np.size(idx):
        rays.flag[idx] = flag
        rays.weight[idx] = 0.0
        if rays.weight_sp is not None:
            rays.weight_sp[idx] = 0.0


def refract_through_array(camera: PlenopticCamera, rays: RayBatch, *, reverse: bool = False) -> RayBatch:
    """Carry ``rays`` (in place) through the lenslets of ``camera.array``.

    Forward: rays travelling toward +z anywhere in front of the array end on the array's rear plane.
    ``reverse``: rays travelling toward -z from behind it end on its front plane. Each ray is refracted
    by the lenslet whose cell it crosses (module notes); rays outside the array or leaving their cell
    are CLIPPED.
    """
    require_type("camera", camera, PlenopticCamera, "build one with plenoptic_camera")
    require_type("rays", rays, RayBatch, "build them with physcam.trace.RayBatch.from_arrays")
    a = camera.array
    z_in = camera.z_array if reverse else camera.z_array_front
    _propagate(rays, z_in)
    live = np.flatnonzero(rays.flag == OK)
    ix, iy, inside = a.index_at(rays.x[live], rays.y[live])
    _lose(rays, live[~inside], CLIPPED)
    live, ix, iy = live[inside], ix[inside], iy[inside]
    cx, cy = a.centres(ix, iy)
    if a.lenslet is None:
        # the ideal thin lens: slope dx/dz of the line changes by -(x - c)/f (forward sense)
        n = rays.N[live]
        sx, sy = rays.L[live] / n, rays.M[live] / n
        k = 1.0 if reverse else -1.0
        sx = sx + k * (rays.x[live] - cx) / a.focal_length_mm
        sy = sy + k * (rays.y[live] - cy) / a.focal_length_mm
        norm = np.sqrt(1.0 + sx * sx + sy * sy) * (-1.0 if reverse else 1.0)
        rays.L[live], rays.M[live], rays.N[live] = sx / norm, sy / norm, 1.0 / norm
        return rays
    # a prescription: trace the rays of every lenslet in one batch, each in its lenslet's frame
    z0 = camera.z_array_front
    sub = rays.take(live)
    sub.x -= cx
    sub.y -= cy
    sub.z -= z0
    trace_through(a.lenslet, sub, reverse=reverse, in_place=True)
    sub.x += cx
    sub.y += cy
    sub.z += z0
    for name in ("x", "y", "z", "L", "M", "N", "weight", "flag"):
        getattr(rays, name)[live] = getattr(sub, name)
    if sub.weight_sp is not None and rays.weight_sp is not None:
        rays.weight_sp[live] = sub.weight_sp
    # end every ray on the array's far plane (a curved last surface ends short of it), so both
    # directions judge the cell at the same two planes and a ray reverses exactly
    sub_end = rays.take(live)
    _propagate(sub_end, camera.z_array_front if reverse else camera.z_array)
    for name in ("x", "y", "z", "flag"):
        getattr(rays, name)[live] = getattr(sub_end, name)
    # opaque cell walls: a ray that left its cell inside the lenslet is clipped; one that ends on its own
    # cell's wall (to rounding: a ray that entered on the wall, reversed) is still inside it
    ok = rays.flag[live] == OK
    cx0, cy0 = a.cell_centres(ix, iy)
    tol = 1e-9 * max(a.pitch_x, a.pitch_y, 1.0)
    own = ((np.abs(rays.x[live] - cx0) <= 0.5 * a.pitch_x + tol)
           & (np.abs(rays.y[live] - cy0) <= 0.5 * a.pitch_y + tol))
    _lose(rays, live[ok & ~own], CLIPPED)
    return rays


def trace_to_sensor(camera: PlenopticCamera, rays: RayBatch, **kwargs) -> RayBatch:
    """Trace object-space ``rays`` (a copy) through the main lens, the array and on to the sensor.
    Keyword arguments go to :func:`~physcam.trace.trace_through` for the main lens (``backend``...)."""
    require_type("camera", camera, PlenopticCamera, "build one with plenoptic_camera")
    out = trace_through(camera.main, rays, end_z=camera.z_array_front, stop_semi_diameter=camera.stop_semi_diameter,
                        **kwargs)
    refract_through_array(camera, out)
    _propagate(out, camera.z_sensor)
    return out


def trace_from_sensor(camera: PlenopticCamera, rays: RayBatch, **kwargs) -> RayBatch:
    """Trace ``rays`` leaving the sensor toward -z (a copy) back through the array and the main lens;
    they end after its first surface, travelling into the scene."""
    require_type("camera", camera, PlenopticCamera, "build one with plenoptic_camera")
    out = rays.copy()
    refract_through_array(camera, out, reverse=True)
    return trace_through(camera.main, out, reverse=True, stop_semi_diameter=camera.stop_semi_diameter,
                         in_place=True, **kwargs)


def subimage_centres(camera: PlenopticCamera):
    """(cx, cy), each (count_y, count_x): where the ray from the centre of the main lens's exit pupil
    through each lenslet's optical centre (its entrance pupil centre) meets the sensor, mm. The
    sub-image of a lenslet is the exit pupil seen through it; for a thin lenslet at distance D from
    the exit pupil this is c (1 + b / D), b the sensor offset."""
    require_type("camera", camera, PlenopticCamera, "build one with plenoptic_camera")
    from ..optics.paraxial import gaussian

    a = camera.array
    g = gaussian(camera.main, object_z=-math.inf, film_z=camera.z_array)
    z_xp = g.z_exit_pupil
    iy, ix = np.mgrid[0:a.count_y, 0:a.count_x]
    cx, cy = a.centres(ix.ravel(), iy.ravel())
    if a.lenslet is None:
        z_aim = camera.z_array
    else:
        gl = gaussian(a.lenslet)
        z_aim = camera.z_array_front + gl.z_entrance_pupil
    if not z_aim - z_xp > 0:
        raise OpticsError("the main lens's exit pupil lies behind the microlens array; the sub-images have no centre")
    start = np.stack([np.zeros_like(cx), np.zeros_like(cx), np.full_like(cx, z_xp)], axis=1)
    d = np.stack([cx, cy, np.full_like(cx, z_aim - z_xp)], axis=1)
    rays = RayBatch.from_arrays(start, d, camera.main.wavelength_nm)
    refract_through_array(camera, rays)
    _propagate(rays, camera.z_sensor)
    if not rays.ok.all():
        # a lenslet whose centre ray is clipped (vignetted at a cell wall): use the thin-lens estimate
        b = a.sensor_offset_mm
        m = 1.0 + b / (camera.z_array - z_xp)
        lost = ~rays.ok
        rays.x[lost], rays.y[lost] = cx[lost] * m, cy[lost] * m
    return rays.x.reshape(a.count_y, a.count_x), rays.y.reshape(a.count_y, a.count_x)

