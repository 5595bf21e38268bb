"""Spot diagram: where rays from one field point land on the film, and how spread they are.

For each field angle (degrees, in the Y-Z meridian) a collimated beam fills a disk on the
paraxial entrance-pupil plane: the paraxial entrance pupil overfilled by ``overfill`` so real
pupil shifts are covered (the stop and element rims clip what does not pass), or ``pupil_radius``.
It is traced to the film plane (``film_z``, mm in lens space; default the paraxial image plane
at the design wavelength). From a :class:`~physcam.optics.state.CameraState` focused closer than
infinity the rays come instead from the object point at its focus, aimed at the same disk, and land
on the state's film plane. RMS radius is about the centroid, sqrt(mean(dx^2 + dy^2)); geometric
radius the largest distance from the centroid. Both in micrometres.

Sampling (area-weighted, deterministic): the disk is cut into equal-area cells on a regular grid
in (rho^2, phi) -- ``rings`` divisions of rho^2 by about 3 ``rings`` of phi -- each traced at its
area-median point. A beam clipped by a rim or the stop has an edge that crosses these cells; the
RMS of an aberrated beam is dominated by its rim, so the edge is refined: a cell whose ray passes
while a neighbour's does not (or the reverse) is split 2 x 2, for ``refine`` levels, each child
weighing a quarter of its parent. The edge is thus resolved 2^refine times finer than the base
grid (32 x by default), for a few times the base count of rays. The means above are weighted by
cell area. Rays are counted by what stopped them: clipped by an aperture (a rim or the stop),
missed a surface, or totally reflected (``physcam.trace`` flags). ``clip=False`` lets every ray
that meets the surfaces through (no rim or stop clips): the beam is then the launched disk,
by default the paraxial entrance pupil itself. When no ray reaches the film the spot is
*undefined*: centroid and radii are ``None`` (``null`` in JSON) with a ``reason``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, require_finite
from ...optics.state import CameraState, takes_camera
from ...figures import styled

__all__ = ["equal_area_disk", "SpotField", "SpotDiagram", "spot_diagram", "MAX_RINGS", "MAX_REFINE"]

#: Largest ``rings`` (about 3 rings^2 base rays per field) and ``refine`` (levels of edge refinement).
MAX_RINGS = 500
MAX_REFINE = 8


def equal_area_disk(radius: float, n_rings: int):
    """Deterministic equal-area samples of a disk: ring j holds 6 j cells of equal area,
    each represented by its area-median radius and mid angle (3 n (n + 1) points)."""
    counts = 6 * np.arange(1, n_rings + 1)
    cum = np.concatenate([[0], np.cumsum(counts)])
    total = cum[-1]
    xs, ys = [], []
    for j, m in enumerate(counts, start=1):
        r_mid = radius * np.sqrt((cum[j - 1] + m / 2) / total)
        phi = (np.arange(m) + 0.5) * 2 * np.pi / m + (0.5 * np.pi / m if j % 2 else 0.0)
        xs.append(r_mid * np.cos(phi))
        ys.append(r_mid * np.sin(phi))
    return np.concatenate(xs), np.concatenate(ys)


@dataclass
class SpotField:
    """One field's spot: counts of rays by fate, and the area-weighted centroid and radii
    (``None`` when no ray reaches the film: ``reason`` says why)."""

    field_deg: float
    rays_launched: int
    rays_passed: int
    rays_clipped: int  # stopped by a clear aperture (element rim) or the stop
    rays_missed: int  # did not meet a surface
    rays_tir: int  # totally reflected
    passed_area_fraction: float  # area of the launched disk whose rays reach the film, 0..1
    centroid_x_mm: float | None
    centroid_y_mm: float | None
    rms_radius_um: float | None
    geometric_radius_um: float | None
    x_mm: np.ndarray = field(repr=False)
    y_mm: np.ndarray = field(repr=False)
    weight: np.ndarray = field(repr=False)  # each passing ray's share of the launched disk's area
    reason: str | None = None

    @property
    def defined(self) -> bool:
        return self.rms_radius_um is not None

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in (
            "field_deg", "rays_launched", "rays_passed", "rays_clipped", "rays_missed", "rays_tir",
            "passed_area_fraction", "centroid_x_mm", "centroid_y_mm", "rms_radius_um", "geometric_radius_um",
            "reason")}


#: Margins (inches: left, right, bottom, top) and ``wspace`` where ``tight_layout``'s two passes end for a
#: spot figure (dgauss_50mm's two fields); :meth:`SpotDiagram.plot` starts its one pass there.
CONVERGED_MARGINS = (0.606, 0.127, 0.684, 0.707, 0.232)


@dataclass
class SpotDiagram:
    lens_name: str
    wavelength_nm: float
    film_z_mm: float
    fields: list[SpotField]
    clip: bool = True

    def to_dict(self) -> dict:
        return {"lens": self.lens_name, "wavelength_nm": self.wavelength_nm, "film_z_mm": self.film_z_mm,
                "film_z_reference": "lens space: mm from the first vertex, +z toward the film",
                "clip": self.clip,
                "definition": "area-weighted RMS and largest radius about the centroid, um; null = undefined "
                              "(no ray reaches the film)",
                "fields": [f.to_dict() for f in self.fields]}

    @styled
    def plot(self, path=None, *, force: bool = False, context: str = ""):
        """Draw one panel per field (positions relative to the centroid, um); write it to ``path`` (PNG/SVG/PDF)
        and return the path, else return the figure. ``context`` (the shot: f-stop, focus) is a line under
        the panels, laid out with them in one pass (:meth:`_lay_out`)."""
        from ...figures import dots, fit_title, pyplot, title_y

        plt = pyplot()

        n = len(self.fields)
        fig, axes = plt.subplots(1, n, figsize=(3.2 * n, 3.4), squeeze=False)
        for ax, f in zip(axes[0], self.fields):
            ax.set_aspect("equal")
            ax.set_xlabel("x from the centroid (µm)")
            ax.set_ylabel("y from the centroid (µm)")
            if not f.defined:
                ax.text(0.5, 0.5, "undefined:\nno ray reaches the film", ha="center", va="center",
                        transform=ax.transAxes, fontsize=8)
                ax.set_title(f"{f.field_deg:g} deg\nRMS undefined", fontsize=8, y=title_y(ax))
                continue
            size = 0.3 * f.weight / f.weight.max()  # refined rim rays weigh less: drawn smaller
            dots(ax, (f.x_mm - f.centroid_x_mm) * 1e3, (f.y_mm - f.centroid_y_mm) * 1e3, size, "k")
            ax.set_title(f"{f.field_deg:g}°: RMS {f.rms_radius_um:.2f} µm,\nGEO {f.geometric_radius_um:.2f} µm",
                         fontsize=8, y=title_y(ax))  # (placed once where matplotlib would leave it)
        fig.suptitle(fit_title(f"{self.lens_name}: spot diagram at {self.wavelength_nm:g} nm", 3.0 * n), fontsize=9)
        self._lay_out(fig, context)
        if path is None:
            return fig
        from ...figures import save_figure

        return save_figure(fig, path, force=force)

    @staticmethod
    def _lay_out(fig, context: str) -> None:
        """One ``tight_layout`` pass, started from :data:`CONVERGED_MARGINS`; a ``context`` line under the panels.

        ``tight_layout`` is one step of an iteration: it measures the panels' text where they stand and
        moves the margins to fit. Equal-aspect panels then shrink inside their new slots, so one step from
        matplotlib's default margins lands short (issue 47, round 21; five lenses at one to four fields). Without
        a context line (the library's ``plot()`` on main) the x labels reached 2-6 px below the figure's edge in
        19 of the 20 cases of two to four fields (``figure_problems`` flags them) and the figure's title came
        within 0-4 px of the panels' titles; with it (``physcam spot -o``) the line lay 1-6 px into the x labels,
        so the command laid the figure out twice (without the line, then with it: 25-40 ms of a cold run).
        Started where two passes end, one step lands where two do, in all 25 cases: the x labels 13 px inside
        the figure, or the line 16 px clear of them, and the titles 19 px apart
        (tests/analysis/image_quality/test_spot_figure.py checks the clearances)."""
        from ...figures import CONTEXT_RECT, context_line

        if context:
            context_line(fig, context)
        width, height = fig.get_size_inches()
        left, right, bottom, top, wspace = CONVERGED_MARGINS
        fig.subplots_adjust(left=left / width, right=1.0 - right / width, bottom=bottom / height,
                            top=1.0 - top / height, wspace=wspace)
        fig.tight_layout(**({"rect": CONTEXT_RECT} if context else {}))


def _whole(name: str, value, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not lo <= value <= hi:
        raise InputError(f"{name} must be a whole number from {lo} to {hi}, got {value!r}")
    return int(value)


#: Largest fine grid (fields x rings x angles at a level) whose cells' pass/fail is looked up in a dense table
#: (one byte a cell, -1 where not traced at that level) rather than by binary search of sorted keys: the
#: default spot's finest looked-up level is 6.3 million cells (two fields), 6 MB (issue 47, round 21).
DENSE_CELLS = 1 << 24


def _refined_samples(trace, rings: int, refine: int, n_fields: int = 1, dense_cells: int = DENSE_CELLS):
    """Equal-area cells on the unit disk's (rho^2, phi) grid, refined at the edge of what passes.

    ``trace(f, u, v)`` takes field indices and points on the unit disk (all fields in one call,
    one call per refinement level) and returns their tracer flags and film x, y. Returns, per
    field, the leaf cells' weights (summing to 1), flags, and film x, y.

    A cell is split when its ray passes and an 8-connected neighbour's does not, or the reverse
    (phi wraps, rho^2 does not: beyond the first and last ring the ring itself stands in). A
    neighbour at the current level that was not traced has the status of its finest traced
    ancestor. A level's cells are looked up in a dense table of its grid while that has at most
    ``dense_cells`` cells, else kept sparse (sorted integer keys), so the bookkeeping grows with the
    rays traced, not with the 4^level fine grid; both give the same answers
    (tests/analysis/image_quality/test_spot_lookup.py compares them).
    """
    from ...trace import OK

    ns, nphi = rings, 2 * math.ceil(1.5 * rings)

    def points(i, j, level):
        k = 2**level
        s = (i + 0.5) / (ns * k)
        phi = (j + 0.5) * 2.0 * np.pi / (nphi * k)
        r = np.sqrt(s)
        return r * np.cos(phi), r * np.sin(phi)

    def keys(f, i, j, level):
        ni, nj = ns << level, nphi << level
        return (f.astype(np.int64) * ni + i) * nj + j

    I, J = np.meshgrid(np.arange(ns), np.arange(nphi), indexing="ij")
    i0, j0 = I.ravel(), J.ravel()
    F = np.repeat(np.arange(n_fields), i0.size)
    I, J = np.tile(i0, n_fields), np.tile(j0, n_fields)
    flags, fx, fy = trace(F, *points(I, J, 0))
    levels = [(F, I, J, flags, fx, fy)]  # per level: the traced cells (field, i, j) and results
    lookup = []  # per level: a dense table of the grid (-1: not traced), or the traced cells' sorted keys and status
    orders = []  # per level: the traced cells' order by key (the sparse lookup's), None for a dense one
    refined = []  # per level: which traced cells were split

    def remember(f, i, j, level, st):
        k = keys(f, i, j, level)
        size = n_fields * (ns << level) * (nphi << level)
        if size <= dense_cells:
            lookup.append(np.full(size, -1, dtype=np.int8))
            lookup[-1][k] = st
            orders.append(None)
            return
        order = np.argsort(k, kind="stable")
        lookup.append((k[order], st[order]))
        orders.append(order)

    def status(f, i, j, level):
        """Pass/fail of cells (f, i, j) at ``level``: their own, else their finest traced ancestor's."""
        out = np.zeros(i.size, dtype=bool)
        todo = np.arange(i.size)
        for lv in range(level, -1, -1):
            sh = level - lv
            k = keys(f[todo], i[todo] >> sh, j[todo] >> sh, lv)
            if orders[lv] is None:  # dense
                got = lookup[lv][k]
                found = got >= 0
                out[todo[found]] = got[found] > 0
            else:
                ks, st = lookup[lv]
                pos = np.minimum(np.searchsorted(ks, k), ks.size - 1)
                found = ks[pos] == k
                out[todo[found]] = st[pos[found]]
            todo = todo[~found]
            if todo.size == 0:
                break
        return out

    remember(F, I, J, 0, flags == OK)
    for level in range(1, refine + 1):
        F, I, J, fl = levels[-1][:4]
        lv = level - 1
        ni, nj = ns << lv, nphi << lv
        # a sparse level's cells in key order (remember()'s): neighbour keys come nearly sorted for the search
        order = orders[lv]
        Fs, Is, Js, st = (F, I, J, fl == OK) if order is None else (F[order], I[order], J[order], (fl == OK)[order])
        diff_s = np.zeros(I.size, dtype=bool)
        rows = {di: np.clip(Is + di, 0, ni - 1) for di in (-1, 0, 1)}
        cols = {dj: (Js + dj) % nj for dj in (-1, 0, 1)}
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                if di or dj:
                    diff_s |= status(Fs, rows[di], cols[dj], lv) != st
        diff = diff_s if order is None else np.empty_like(diff_s)
        if order is not None:
            diff[order] = diff_s
        refined.append(diff)
        if not diff.any():
            break
        # split cells in raster order per field (the order a dense grid's np.nonzero gives)
        sf, si, sj = F[diff], I[diff], J[diff]
        order = np.lexsort((sj, si, sf))
        sf, si, sj = sf[order], si[order], sj[order]
        cf = np.concatenate([sf, sf, sf, sf])
        ci = np.concatenate([2 * si, 2 * si, 2 * si + 1, 2 * si + 1])
        cj = np.concatenate([2 * sj, 2 * sj + 1, 2 * sj, 2 * sj + 1])
        # per field, children in the order [top-left..., top-right..., bottom-left..., bottom-right...]
        order = np.argsort(cf, kind="stable")
        cf, ci, cj = cf[order], ci[order], cj[order]
        f, x, y = trace(cf, *points(ci, cj, level))
        levels.append((cf, ci, cj, f, x, y))
        remember(cf, ci, cj, level, f == OK)
    out = []
    for fi in range(n_fields):
        ws, fs, xs, ys = [], [], [], []
        for level, (F, _i, _j, f, x, y) in enumerate(levels):
            mine = F == fi
            leaf = mine & ~refined[level] if level < len(refined) else mine
            ws.append(np.full(int(leaf.sum()), 1.0 / (ns * nphi * 4**level)))
            fs.append(f[leaf])
            xs.append(x[leaf])
            ys.append(y[leaf])
        out.append((np.concatenate(ws), np.concatenate(fs), np.concatenate(xs), np.concatenate(ys)))
    return out


class _Beams:
    """The rays of each field aimed at points of the beam's disk on the entrance-pupil plane ``z_ep``
    (centred on the axis): at infinity a collimated beam along (0, sin theta, cos theta); at a finite
    ``object_z`` from the object point (0, -tan(theta) (z_ep - object_z), object_z), seen under theta
    from the entrance pupil (as :mod:`physcam.analysis.image_quality._pupil`). Rays start on a plane in front of the
    lens (or at the object point when it is nearer)."""

    def __init__(self, lens, object_z, z_ep, beam, fields, wl):
        from ...trace import RayBatch
        from .._chief import start_plane_z

        self.z0 = min(z_ep, start_plane_z(lens)) - 1.0
        self.object_z, self.z_ep, self.beam, self.wl = object_z, z_ep, beam, float(wl)
        th = np.radians(np.asarray(fields, dtype=float))
        self.dirs = np.stack([np.zeros(th.size), np.sin(th), np.cos(th)], axis=1)  # one beam direction per field
        self.back = (z_ep - self.z0) / self.dirs[:, 2]
        # the beams' unit directions exactly as RayBatch.from_arrays normalises them, once per field
        self.unit = RayBatch.from_arrays(np.zeros((th.size, 3)), self.dirs, wl) if th.size else None
        self.object_y = -np.tan(th) * (z_ep - object_z) if math.isfinite(object_z) else None

    def rays(self, f, u, v):
        """Rays of fields ``f`` toward points (u, v) of the unit disk, as one RayBatch."""
        from ...trace import RayBatch

        n = u.size
        if self.object_y is not None:
            return self._from_point(f, u, v)
        # built column by column: the numbers RayBatch.from_arrays(start, dirs[f], wl) would hold
        y = self.beam * v
        y -= self.back[f] * self.dirs[f, 1]
        unit = self.unit
        return RayBatch(self.beam * u, y, np.full(n, float(self.z0)), unit.L[f], unit.M[f], unit.N[f],
                        np.full(n, self.wl), np.ones(n), np.zeros(n, dtype=np.uint8))

    def _from_point(self, f, u, v):
        from ...trace import RayBatch

        n = u.size
        p = np.stack([np.zeros(n), self.object_y[f], np.full(n, self.object_z)], axis=1)
        d = np.stack([self.beam * u, self.beam * v, np.full(n, self.z_ep)], axis=1) - p
        if self.object_z < self.z0:  # start where the ray crosses the plane in front of the lens
            p = p + d * ((self.z0 - self.object_z) / d[:, 2])[:, None]
        return RayBatch.from_arrays(p, d, self.wl)


@takes_camera
def spot_diagram(
    camera: CameraState,
    fields_deg=(0.0,),
    *,
    wavelength_nm: float | None = None,
    rings: int = 64,
    refine: int = 5,
    overfill: float = 1.3,
    pupil_radius: float | None = None,
    clip: bool = True,
    backend: str = "auto",
) -> SpotDiagram:
    """Spot diagram of ``camera`` at the given field angles (see module notes).

    ``camera``: a :class:`~physcam.optics.state.CameraState` (its focused lens, film plane, iris,
    iris shape and primary wavelength; the object at its focus, the field seen from the entrance
    pupil as for the MTF); a camera built from a bare lens leaves the film at the paraxial image at
    ``wavelength_nm``.
    ``rings`` (1 to :data:`MAX_RINGS`) sets the base grid, ``refine`` (0 to :data:`MAX_REFINE`)
    the levels of edge refinement. ``pupil_radius`` (mm) replaces the overfilled entrance pupil
    by a disk of that radius on the entrance-pupil plane (e.g. to compare with a published figure
    at a given beam size). ``clip=False``: no rim or stop clips (the default beam is then the
    paraxial entrance pupil, not overfilled). A field where no ray reaches the film is undefined
    (module notes).
    """
    from ... import _program
    from ...optics.paraxial import gaussian
    from ...trace import CLIPPED, MISSED, OK, TIR, paraxial_image_z, trace_to_film
    from .._camera import ray_view

    _program.roomy_heap()  # the program's heap keeps freed pages: the levels' arrays of 1e5 rays come and go
    lens, object_z, film_z, stop, aperture, wl, _ = ray_view(camera, wavelength_nm=wavelength_nm)
    wl = require_finite("wavelength_nm", wl)
    rings = _whole("rings", rings, 1, MAX_RINGS)
    refine = _whole("refine", refine, 0, MAX_REFINE)
    film_z = paraxial_image_z(lens, wl) if film_z is None else film_z
    g = gaussian(lens, wavelength_nm=wl, stop_semi_diameter=stop, object_z=object_z)
    z_ep, r_ep = g.z_entrance_pupil, g.entrance_pupil_diameter / 2
    if pupil_radius is not None:
        beam = require_finite("pupil_radius", pupil_radius)
    else:
        beam = r_ep * (require_finite("overfill", overfill) if clip else 1.0)
    if beam <= 0:
        raise InputError(f"pupil_radius (overfill) must be > 0, got {beam:g}")
    fields = [require_finite("field angle", fd) for fd in np.atleast_1d(fields_deg)]
    for fd in fields:
        if not -89.0 < fd < 89.0:
            raise InputError(f"field angle must lie between -89 and 89 degrees, got {fd:g}")
    beams = _Beams(lens, object_z, z_ep, beam, fields, wl)

    def trace(f, u, v):
        res = trace_to_film(lens, beams.rays(f, u, v), film_z, clip=clip, stop_semi_diameter=stop,
                            aperture=aperture, backend=backend, in_place=True)
        return res.flag, res.x, res.y

    samples = _refined_samples(trace, rings, refine, len(fields)) if fields else []
    out = []
    for fd, (w, flags, fx, fy) in zip(fields, samples):
        ok = flags == OK
        counts = {k: int((flags == k).sum()) for k in (OK, CLIPPED, MISSED, TIR)}
        frac = float(w[ok].sum())
        if not ok.any():
            out.append(SpotField(float(fd), int(w.size), 0, counts[CLIPPED], counts[MISSED], counts[TIR], 0.0,
                                 None, None, None, None, np.zeros(0), np.zeros(0), np.zeros(0),
                                 f"no ray at field {fd:g} deg reaches the film through {lens.name!r} "
                                 f"(clipped {counts[CLIPPED]}, missed {counts[MISSED]}, totally reflected "
                                 f"{counts[TIR]}): the spot is undefined"))
            continue
        x, y, wk = fx[ok], fy[ok], w[ok]
        cx, cy = float(np.average(x, weights=wk)), float(np.average(y, weights=wk))
        r2 = (x - cx) ** 2 + (y - cy) ** 2
        out.append(SpotField(float(fd), int(w.size), counts[OK], counts[CLIPPED], counts[MISSED], counts[TIR], frac,
                             cx, cy, float(np.sqrt(np.average(r2, weights=wk)) * 1e3), float(np.sqrt(r2.max()) * 1e3),
                             x, y, wk))
    return SpotDiagram(lens.name, float(wl), float(film_z), out, bool(clip))
