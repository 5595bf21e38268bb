"""Ghosts: light reflected twice inside the lens (double-bounce paths) and its image on the film.

A ghost path (i, j), j < i, is: forward through surfaces 0..i-1, reflected at surface i, back
through i-1..j+1, reflected at surface j, forward through j+1..N-1 to the film. Only surfaces
with a change of index reflect (the stop and index-matched surfaces do not). Each reflection
weighs the ray by the Fresnel reflectances R_s = 1 - T_s and R_p = 1 - T_p of that surface at
the ray's angle (Hecht, *Optics*, 5th ed., 4.6.2; beyond the critical angle R = 1), scaled by
the coating model of :mod:`physcam.trace.fresnel` (``none``, ``single`` quarter-wave MgF2,
``multi``); every refraction weighs it by T_s and T_p, as in the direct image. The s and p
halves of the unpolarised light are carried separately along the whole path (``RayBatch.weight``
= (s + p) / 2, ``weight_sp`` = (s - p) / 2), so a ghost's flux is (prod s + prod p) / 2.

What is reused: the tracer's kernels (:mod:`physcam.trace.kernels`) trace each leg, on slices
of the packed surface table (:func:`physcam.trace.surfaces.surface_table`, forward for legs 1
and 3, reverse for leg 2): intersection (spheres, conics, cylinders, even aspheres), clipping at
every clear semi-diameter and the stop, Snell refraction and Fresnel transmission. The
surface where a leg ends is given the same index on both sides, so the kernel leaves the ray on
that surface without refracting it; this module then reflects it: the unit normal from the
same quadric/asphere gradient as the kernels, d' = d - 2 (d . n) n, and the Fresnel reflectances
from :func:`physcam.trace.fresnel.fresnel_transmittances`. All arrays are structure-of-arrays
(:class:`physcam.trace.RayBatch`), traced in chunks.

The light is a point at infinity at field angle ``field_deg`` (Y meridian), filling the front
element with a collimated beam. ``relative_flux`` of a path is its flux on the film divided by
the flux of the direct image (same beam, Fresnel losses included). Ghost images are histograms
of ghost irradiance over the sensor (relative units: direct-image flux = 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, OpticsError, require_finite, require_positive
from ...figures import styled
from ...lens.prescription import Prescription, takes_prescription
from ...optics.state import CameraState, takes_camera

__all__ = ["GhostPath", "GhostResult", "ghost_pairs", "ghost_analysis", "trace_ghost"]


@dataclass(frozen=True)
class GhostPath:
    i: int  # first reflection (the later surface), prescription index
    j: int  # second reflection (the earlier surface)
    relative_flux: float  # ghost flux on the film / direct flux
    on_sensor_fraction: float  # part of the ghost's flux that lands on the sensor
    centroid_x_mm: float | None
    centroid_y_mm: float | None
    rms_radius_mm: float | None

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


@dataclass
class GhostResult:
    lens_name: str
    field_deg: float
    coating: str
    wavelength_nm: float
    film_z_mm: float
    sensor_mm: tuple[float, float]
    direct_centroid_mm: tuple[float, float]
    paths: list[GhostPath]
    image: np.ndarray | None = field(default=None, repr=False)  # (ny, nx) ghost irradiance, relative
    image_paths: int = 0
    image_rays: int = 0
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        d = {"lens": self.lens_name, "field_deg": self.field_deg, "coating": self.coating,
             "wavelength_nm": self.wavelength_nm, "film_z_mm": self.film_z_mm, "sensor_mm": list(self.sensor_mm),
             "direct_centroid_mm": list(self.direct_centroid_mm), "paths": [p.to_dict() for p in self.paths],
             "total_relative_flux": float(sum(p.relative_flux for p in self.paths)),
             "definition": "path (i, j): reflect at surface i, then at surface j < i; flux relative to the direct image",
             "notes": list(self.notes)}
        if self.image is not None:
            d["image"] = {"pixels": list(self.image.shape), "paths": self.image_paths,
                          "rays_per_path": self.image_rays, "peak": float(self.image.max())}
        return d

    @styled
    def plot(self, path=None, *, force: bool = False):
        """The ghost image on the sensor (log scale), direct image marked; PNG if ``path``."""
        from .._plot import figure, save

        if self.image is None:
            raise InputError("this ghost result has no image; run ghost_analysis with image_rays > 0")
        fig, ax = figure(6.0, 4.4)
        w, h = self.sensor_mm
        img = self.image
        pos = img[img > 0]
        lo = np.log10(pos.max()) - 5 if pos.size else -12
        shown = np.log10(np.where(img > 0, img, 10.0 ** (lo - 1)))
        im = ax.imshow(shown, origin="lower", extent=(-w / 2, w / 2, -h / 2, h / 2), vmin=lo, cmap="inferno",
                       interpolation="nearest")
        ax.plot(*self.direct_centroid_mm, "c+", ms=10, label="direct image")
        ax.set_xlabel("film x (mm)")
        ax.set_ylabel("film y (mm)")
        ax.legend(fontsize=7, loc="upper right")
        fig.colorbar(im, ax=ax, label="log10 ghost irradiance (direct flux = 1 per mm^2)")
        ax.set_title(f"{self.lens_name}\nghosts of a light at {self.field_deg:g} deg, coating {self.coating}",
                     fontsize=8)
        return save(fig, path, force)


@takes_prescription
def ghost_pairs(lens: Prescription) -> list[tuple[int, int]]:
    """All (i, j), j < i, of surfaces that reflect (index changes across them), grouped by i in order."""
    media = [(1.0, 0.0)] + [(s.medium.nd, s.medium.vd) for s in lens.surfaces]
    refl = [k for k, s in enumerate(lens.surfaces) if not s.is_stop and media[k] != media[k + 1]]
    return [(i, j) for a, i in enumerate(refl) for j in refl[:a]]


class _Tables:
    """Forward and reverse packed surface tables of one lens (the tracer's cached tables), and
    their index columns per wavelength."""

    def __init__(self, lens, coating, stop_sd):
        from ...trace.tables import packed_table

        self.n = len(lens.surfaces)
        self.pf = packed_table(lens, coating=coating, stop_semi_diameter=stop_sd)
        self.pr = packed_table(lens, reverse=True, coating=coating, stop_semi_diameter=stop_sd)
        self.fwd, self.rev = self.pf.table, self.pr.table
        self.Sf, self.kf = self.pf.S, self.pf.kinds
        self.Sr, self.kr = self.pr.S, self.pr.kinds

    def indexed(self, wl, one: bool):
        """The forward and reverse tables for a batch of wavelengths ``wl``: with its index columns
        at the batch's one wavelength where ``one``, else the tables of every wavelength."""
        if one:
            return self.pf.at_wavelength(float(wl[0])), self.pr.at_wavelength(float(wl[0]))
        return self.Sf, self.Sr

    @staticmethod
    def _ending(S, kinds, a, b):
        """Rows a..b-1 of a packed table; the last row keeps the ray on its surface (no refraction).
        Where ``S`` holds one wavelength's indices, the last row's index after is its index before."""
        from ...trace.kernels._layout import ETA, N1, N2, NA, NB, SA, SB

        s = np.array(S[a:b], copy=True)
        s[-1, NA:NA + 9] = s[-1, NB:NB + 9]
        s[-1, SA] = s[-1, SB]
        s[-1, N2] = s[-1, N1]
        s[-1, ETA] = 1.0
        return np.ascontiguousarray(s), np.ascontiguousarray(kinds[a:b])


def _normal(t, row, x, y, z):
    """Unit surface normal (not oriented) of row ``row`` of SurfaceTable ``t`` at points on it."""
    from ...trace.surfaces import KIND_ASPHERE, KIND_QUADRIC

    kind = int(t.kind[row])
    if kind == KIND_QUADRIC:
        gx, gy, gz = t.ax[row] * x, t.ay[row] * y, t.az[row] * (z - t.vertex_z[row]) - 1.0
    elif kind == KIND_ASPHERE:
        c, k = t.curvature[row], t.conic[row]
        r2 = x * x + y * y
        dsr = c / np.sqrt(np.maximum(1.0 - (1.0 + k) * c * c * r2, 1e-300))
        q = r2
        for m, a in enumerate(t.aspheric[row]):
            dsr = dsr + (2.0 * m + 4.0) * a * q
            q = q * r2
        gx, gy, gz = dsr * x, dsr * y, -np.ones_like(x)
    else:
        gx, gy, gz = np.zeros_like(x), np.zeros_like(x), -np.ones_like(x)
    inv = 1.0 / np.sqrt(gx * gx + gy * gy + gz * gz)
    return gx * inv, gy * inv, gz * inv


def _reflect(rays, t, row, forward: bool):
    """Reflect live rays at row ``row`` of table ``t``, weighing their s and p halves by R_s and R_p."""
    from ...trace.fresnel import fresnel_transmittances

    live = rays.ok
    if not live.any():
        return
    x, y, z = rays.x[live], rays.y[live], rays.z[live]
    L, M, N = rays.L[live], rays.M[live], rays.N[live]
    nx, ny, nz = _normal(t, row, x, y, z)
    dn = L * nx + M * ny + N * nz
    from ...optics.glass import evaluate

    wl = rays.wavelength_nm[live]
    n1 = evaluate(t.disp_before[row], wl)  # the medium the ray travels in (table order)
    n2 = evaluate(t.disp_after[row], wl)
    ts, tp = fresnel_transmittances(n1, n2, dn, t.r_scale[row])
    hsum = 1.0 - 0.5 * (ts + tp)  # (R_s + R_p) / 2
    hdif = 0.5 * (tp - ts)  # (R_s - R_p) / 2
    rays.L[live], rays.M[live], rays.N[live] = L - 2 * dn * nx, M - 2 * dn * ny, N - 2 * dn * nz
    w, d = rays.weight[live], rays.weight_sp[live]
    rays.weight[live] = w * hsum + d * hdif
    rays.weight_sp[live] = w * hdif + d * hsum


def _round_iris(aperture) -> None:
    if aperture is not None:
        raise InputError("the ghost tracer models a round iris: give a CameraState without an aperture shape")


@takes_camera
def trace_ghost(lens: Prescription, rays, i: int, j: int, film_z: float | None = None, *, coating: str = "none",
                stop_semi_diameter=None, backend: str = "auto", _tables=None):
    """Trace object-space ``rays`` (a RayBatch, copied) along ghost path (i, j) to the film plane ``film_z``.

    ``lens``: a :class:`~physcam.optics.state.CameraState` (its focused lens, film plane and iris) or, as a
    ray-level tracer keeps, a Prescription with the film plane ``film_z`` (lens space, mm; required) and
    ``stop_semi_diameter``."""
    if isinstance(lens, CameraState):  # (a ray-level tracer: its film plane and stop may be given by hand)
        if film_z is not None or stop_semi_diameter is not None:
            raise InputError("a CameraState carries its own film plane and stop: give them to camera_state(), "
                             "not here")
        _round_iris(lens.aperture)
        lens, film_z, stop_semi_diameter = (lens.focused, lens.film_z,
                                            lens.stop_semi_diameter if lens.iris_set else None)
    elif film_z is None:
        raise InputError("give the film plane: film_z (mm, lens space), or a CameraState")
    return _ghost_path(lens, rays, i, j, film_z, coating, stop_semi_diameter, backend, _tables)


def _ghost_path(lens, rays, i, j, film_z, coating, stop_semi_diameter, backend, _tables, first=None):
    """:func:`trace_ghost` of a prescription, its film plane and stop. ``first``: the rays after
    :func:`_first_bounce` of ``rays`` at ``i`` if already traced (copied here, not changed)."""
    n = len(lens.surfaces)
    if not (0 <= j < i < n):
        raise InputError(f"a ghost path needs 0 <= j < i < {n} surfaces, got i={i}, j={j}")
    T = _tables or _Tables(lens, coating, stop_semi_diameter)
    r = (first if first is not None else _first_bounce(lens, rays, i, T, backend)).copy()
    run, one = _leg_runner(T, r, backend)
    Sf, Sr = T.indexed(r.wavelength_nm, one)
    # leg 2: backward through i-1..j+1 (reverse table rows n-i .. n-1-j), stop on surface j; reflect
    run(*T._ending(Sr, T.kr, n - i, n - j))
    _reflect(r, T.rev, n - 1 - j, False)
    # leg 3: forward through j+1..n-1 to the film
    run(Sf[j + 1:], T.kf[j + 1:], float(film_z))
    return r


def _leg_runner(T, r, backend):
    """``run(S, kinds, end_z=None)``: one leg of a ghost path traced in place on ``r``; and whether the
    batch has one wavelength (the tables' index columns for it then computed once per lens)."""
    from ...trace.kernels import get_kernel
    from ...trace.trace import DEFAULT_CHUNK, trace_packed

    kern = get_kernel(backend)
    wl = r.wavelength_nm
    one = wl.size > 0 and bool(wl.min() == wl.max()) and 1e-100 < float(wl[0]) < 1e100
    return (lambda S, K, end=None: trace_packed(kern, r, S, K, clip=True, fresnel=True, end_z=end,
                                                 chunk_size=DEFAULT_CHUNK, indexed=one)), one


def _first_bounce(lens, rays, i, T, backend):
    """Leg 1 of every ghost path (i, j): a copy of ``rays`` traced forward through surfaces 0..i-1,
    stopped on surface i and reflected there. It does not depend on j, so the paths that share i
    share it (ghost_analysis traces it once per i: issue 47)."""
    r = rays.copy()
    run, one = _leg_runner(T, r, backend)
    Sf, _ = T.indexed(r.wavelength_nm, one)
    run(*T._ending(Sf, T.kf, 0, i + 1))
    _reflect(r, T.fwd, i, True)
    return r


def _beam(lens, field_deg, wl, n, rng=None):
    """Collimated rays at ``field_deg`` (Y meridian) over the front element; each stands for an equal area."""
    from ...trace import RayBatch
    from .._chief import field_direction

    r = lens.surfaces[0].semi_diameter
    if rng is None:  # a deterministic grid inside the disk
        m = max(4, int(math.sqrt(n * 4 / math.pi)))
        xs = -r + (np.arange(m) + 0.5) * 2 * r / m
        X, Y = np.meshgrid(xs, xs)
        keep = X * X + Y * Y <= r * r
        X, Y = X[keep], Y[keep]
        area = (2 * r / m) ** 2
    else:
        u = rng.random((n, 2))
        rho, phi = r * np.sqrt(u[:, 0]), 2 * np.pi * u[:, 1]
        X, Y = rho * np.cos(phi), rho * np.sin(phi)
        area = math.pi * r * r / n
    d = field_direction(math.radians(field_deg), "y")[0]
    pos = np.stack([X, Y, np.zeros(X.size)], axis=1)
    return RayBatch.from_arrays(pos, d[None, :], wl, area * d[2])


#: The light's field angle when none is given (degrees): clamped to what the lens lets through.
DEFAULT_FIELD_DEG = 10.0


@takes_camera
def ghost_analysis(
    camera: CameraState,
    field_deg: float | None = None,
    *,
    coating: str | None = None,
    wavelength_nm: float | None = None,
    rank_rays: int = 4000,
    image_rays: int = 0,
    image_paths: int = 20,
    pixels: int = 256,
    chunk: int = 250_000,
    seed: int = 0,
    backend: str = "auto",
) -> GhostResult:
    """Rank every double-bounce path of ``camera`` for a light at ``field_deg`` (module notes).

    ``camera``: a :class:`~physcam.optics.state.CameraState` (its focused lens, film plane, round iris,
    primary wavelength and sensor; the light stays at infinity; a camera built from a bare lens leaves
    the film at the paraxial image at the wavelength).

    ``rank_rays`` rays (a deterministic grid over the front element) rank the paths; with
    ``image_rays`` > 0, the ``image_paths`` strongest paths are traced again with that many
    random rays each (in chunks of ``chunk``) and binned into a ``pixels``-wide image of the sensor.
    ``coating``: "none", "single", "multi", or None for the lens file's coating (else "none").
    ``field_deg`` None: :data:`DEFAULT_FIELD_DEG`, or the widest field below it that light passes
    (with a note in the result) when none passes there.
    The sensor is the camera's, else Super 35, 24.89 x 18.66 mm
    (:data:`physcam.data.default_sensor.DEFAULT_SENSOR`, the CLI's default too).
    """
    from ...trace import paraxial_image_z, trace_to_film
    from .._camera import ray_view, sensor_or_default

    lens, _, film_z, stop_semi_diameter, aperture, wavelength_nm, _ = ray_view(camera, wavelength_nm=wavelength_nm)
    _round_iris(aperture)
    sensor_width_mm, sensor_height_mm = sensor_or_default(camera)

    default_field = field_deg is None
    fd = require_finite("field angle", DEFAULT_FIELD_DEG if default_field else field_deg)
    if not -89 < fd < 89:
        raise InputError(f"field angle must lie between -89 and 89 degrees, got {fd:g}")
    if coating is None:
        coating = lens.metadata.coating if lens.metadata.coating in ("none", "single", "multi") else "none"
    wl = lens.wavelength_nm if wavelength_nm is None else require_positive("wavelength", wavelength_nm, unit="nm")
    from ...optics.sensors import custom_sensor

    sensor = custom_sensor(sensor_width_mm, sensor_height_mm)  # bounded size and aspect: the image stays small
    w, h = sensor.width_mm, sensor.height_mm
    for name, v in (("rank_rays", rank_rays), ("image_rays", image_rays), ("image_paths", image_paths),
                    ("pixels", pixels), ("chunk", chunk)):
        if isinstance(v, bool) or not isinstance(v, int):
            raise InputError(f"{name} must be a whole number, got {v!r}")
    if not (100 <= rank_rays <= 10**7 and 0 <= image_rays <= 10**10 and 1 <= image_paths <= 1000
            and 8 <= pixels <= 4096 and 1000 <= chunk <= 10**7):
        raise InputError("ghosts need 100 <= rank_rays <= 1e7, 0 <= image_rays <= 1e10, 1 <= image_paths <= 1000, "
                         "8 <= pixels <= 4096 and 1000 <= chunk <= 1e7")
    if film_z is None:
        film_z = paraxial_image_z(lens, wl)
    film_z = require_finite("film_z", film_z)
    pairs = ghost_pairs(lens)
    T = _Tables(lens, coating, stop_semi_diameter)
    if image_rays == 0:
        backend = _ranking_backend(backend, len(lens.surfaces), pairs, rank_rays)
    def direct_image(f):
        b = _beam(lens, f, wl, rank_rays)
        return b, trace_to_film(lens, b, film_z, fresnel=True, coating=coating, stop_semi_diameter=stop_semi_diameter,
                                backend=backend)

    notes = []
    beam, direct = direct_image(fd)
    flux0 = float(direct.weight[direct.ok].sum())
    if flux0 <= 0 and default_field:
        from .._chief import widest_passing_deg

        def passes(f):
            d = direct_image(f)[1]
            return float(d.weight[d.ok].sum()) > 0

        top = widest_passing_deg(passes, 0.0, fd)
        notes.append(f"no light passes at the default {fd:g} deg: the light is at {top:.2f} deg, the widest field "
                     "the lens lets through")
        fd = top
        beam, direct = direct_image(fd)
        flux0 = float(direct.weight[direct.ok].sum())
    if flux0 <= 0:
        raise OpticsError(f"no light at {fd:g} deg passes {lens.name!r}; choose a smaller field angle")
    wd = direct.weight[direct.ok]
    dc = (float((direct.x[direct.ok] * wd).sum() / wd.sum()), float((direct.y[direct.ok] * wd).sum() / wd.sum()))
    paths = []
    first_i, first = None, None  # the beam after leg 1 of the paths that reflect first at first_i
    for i, j in pairs:  # (grouped by i: one first leg in memory at a time, each traced once)
        if i != first_i:
            first_i, first = i, _first_bounce(lens, beam, i, T, backend)
        g = _ghost_path(lens, beam, i, j, film_z, coating, stop_semi_diameter, backend, T, first)
        ok = g.ok & (g.weight > 0)
        wt = g.weight[ok]
        flux = float(wt.sum())
        if flux <= 0:
            paths.append(GhostPath(i, j, 0.0, 0.0, None, None, None))
            continue
        x, y = g.x[ok], g.y[ok]
        cx, cy = float((x * wt).sum() / flux), float((y * wt).sum() / flux)
        rms = float(math.sqrt(((x - cx) ** 2 + (y - cy) ** 2) @ wt / flux))
        on = (np.abs(x) <= w / 2) & (np.abs(y) <= h / 2)
        paths.append(GhostPath(i, j, flux / flux0, float(wt[on].sum() / flux), cx, cy, rms))
    paths.sort(key=lambda p: -p.relative_flux)
    res = GhostResult(lens.name, fd, coating, float(wl), float(film_z), (w, h), dc, paths, notes=notes)
    if image_rays > 0:
        chosen = [p for p in paths if p.relative_flux > 0][:image_paths]
        img, pix_area = _ghost_image(lens, chosen, fd, wl, film_z, T, (w, h), pixels, image_rays, chunk, seed, backend)
        res.image = img / (flux0 * pix_area)
        res.image_paths, res.image_rays = len(chosen), int(image_rays)
    return res


def _ranking_backend(backend, n, pairs, rays):
    """The backend for ranking ``pairs`` of an ``n``-surface lens with ``rays`` rays, decided for the
    whole job at once (:func:`physcam.trace.kernels.backend_for_job`): numpy when the direct image,
    each surface's first bounce and every path's last two legs together cost the numpy kernel less
    than loading numba (dgauss_50mm: 45 paths of 4000 rays, issue 47); each leg's calls counted
    as rays (the kernel's per-surface cost, :data:`~physcam.trace.kernels.NUMPY_SURFACE_S`)."""
    from ...trace.kernels import NUMPY_RAY_SURFACE_S, NUMPY_SURFACE_S, backend_for_job

    rows = (n + 1) + sum(i + 1 for i in {i for i, _ in pairs}) + sum((i - j) + (n - j) for i, j in pairs)
    return backend_for_job(backend, rows * (rays + NUMPY_SURFACE_S / NUMPY_RAY_SURFACE_S))


def _ghost_image(lens, chosen, fd, wl, film_z, T, sensor, pixels, image_rays, chunk, seed, backend):
    """The ``chosen`` paths' flux binned over the sensor, ``pixels`` wide, and a pixel's area (mm^2): each
    path traced with ``image_rays`` random rays, in chunks (module notes)."""
    w, h = sensor
    nx = int(pixels)
    ny = max(8, int(round(pixels * h / w)))
    img = np.zeros(nx * ny)
    rng = np.random.default_rng(seed)
    for p in chosen:
        done = 0
        while done < image_rays:
            m = min(chunk, image_rays - done)
            b = _beam(lens, fd, wl, m, rng)
            g = _ghost_path(lens, b, p.i, p.j, film_z, None, None, backend, T)
            ix = np.floor((g.x + w / 2) / w * nx).astype(np.int64)
            iy = np.floor((g.y + h / 2) / h * ny).astype(np.int64)
            inside = g.ok & (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
            img += np.bincount(iy[inside] * nx + ix[inside], weights=g.weight[inside], minlength=img.size)
            done += m
    return img.reshape(ny, nx), (w / nx) * (h / ny)
