"""The Blender extension's exit-pupil table: where a ray from each film point must aim to pass the lens.

A camera ray leaves a film point toward an aim point on the rear vertex plane; it reaches the scene
only when it passes every clear aperture and the iris. The OSL camera samples aim points uniformly
over a region that holds every passing one, and weighs each ray by the region's area (physcam's
``camera_rays`` weight cos^4(theta) A / d^2): the estimate is exact whatever the region, but the
samples outside the passing set are wasted, and their share is the noise the picture pays. This
module tabulates a tight region, per film radius and per iris size, for a lens with rotational
symmetry (the passing set of film point (rho, 0) is symmetric about the meridional plane y = 0, and
that of any film point is it turned about the axis).

For each film radius rho_j (:data:`N_RADIAL` nodes from the axis to :data:`RADIAL_MAX_MM`, the
largest sensor's half diagonal), rays from (rho_j, 0) are traced through the lens with the iris
taken out (its radius recorded where each ray crosses the stop plane): a ray passes an iris of
radius s exactly when it passes every other surface and crosses the stop within s, so one trace
gives the passing set at every iris size. The passing set at iris radius s_l (:func:`iris_levels`:
the widest iris, the file's stop and :data:`LEVEL_RATIO` steps below it) is enclosed in
an ellipse with axes along the radial and tangential directions: centre (cx, 0), semi-axes
(ax, ay). The set's rim is found between grid samples: where the iris stops a ray, the stop radius
is interpolated to s along the grid line (it is smooth); where another surface clips, the edge is
found by halving the step (the rim that holds the set is put at the halving's far end, conservative;
its area takes the middle), unless the iris stops the ray first on the way (the stop radius at the
halving's last passing point already exceeds s: then the rim is interpolated there, as above). A
grid zooms in once its set spans under :data:`_ZOOM` of it across or along, so a set spans at least
about 20 of the 36 samples each way: a rim's area is a dense trace's within 0.4 % (cut by other
surfaces or not; the double Gauss and the Canon RF 85, f/2 to f/16, film radius to 22 mm).
Where the iris alone bounds a set the grids are not needed: its rim is found along 25 lines from the
film point's chief aim (the aim whose ray crosses the stop's centre: every set holds it, and a convex set
is star-shaped from it), the stop radius sampled geometrically along each line and the rim interpolated
where it reaches s (:class:`_LineSets`; about 620 rays a film point against about 3,400 in grids). The lines
serve the iris radii under every cut line's clip edge by 5 %, so no other surface reaches the set, and only
where the interpolation is sure of the rim (:data:`_LINE_DOUBT`); the wider radii (where other surfaces cut
the set: wide open, off axis) and the film points whose chief ray is cut (outside the image circle) keep the
grids. The lines' areas are a dense trace's within 0.15 % (the grids' up to 0.27 % short; the double Gauss,
a fisheye, a zoom, the Canon RF 85 and the Angenieux f/1: tests/export/test_blender_pupil_lines.py).

The shader interpolates the ellipse linearly in rho between nodes, in s between levels (below the
last level it scales the last level's axes by s / s_last: the pupil's linear regime) and between
the two focus states it blends (grown by fw (1 - fw) times the centres' shift there). The
interpolation in rho and s is checked here: the passing sets at every mid radius and mid level (and
at half the last level) are traced too, and the entries are grown until the interpolated ellipse
holds them. Stopped down the passing set is the iris's image, nearly an ellipse itself, so nearly
every sample passes (0.96-0.99 on the double Gauss from f/5.6 on); wide open and at the frame's
edge it is the iris's image cut by the other elements (cat's eye), and 0.75-0.9 pass. The passing
area (the shader then redraws missed aims) is read as a cubic in rho through four nodes
(:func:`radial_cubic`) and in s through two levels' areas and slopes (:func:`hermite`), and trusted
per cell where the mid checks agree (:func:`radial_pupil_table`): on the double Gauss focused at
2.5 m, every film radius of a full frame at f/2.8, f/5.6 and f/16 (issue 41; round 9: 0.945 at f/2.8,
where other surfaces begin to cut the set between two levels the cubic in s rounds the area's kink off,
so the focus table adds a level there, :func:`_refined_levels`; round 7's table, which never trusted a
set other surfaces cut, about 0.3). A level is added only for a miss inside the lens's image circle
(:func:`_in_circle`: the film radii where the chief ray passes at every traced focus, physcam's image
circle as the lens cards give it). Past it a stopped-down picture is black and an open one is lit only
through the pupil's edge, by a sensor the lens does not cover; there a miss leaves its cell untrusted
(more noise, no bias) instead of growing every table of the lens (round 10 counted misses to
:data:`RADIAL_MAX_MM`: 483 levels added over the 44 bundled primes, now 357).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError, require_finite, require_type

__all__ = ["RADIAL_MAX_MM", "N_RADIAL", "LEVEL_RATIO", "N_LEVEL", "radial_pupil_table", "refined_pupil_tables", "iris_levels",
           "level_bracket", "interpolated_ellipse", "interpolated_area", "cell_area", "hermite", "radial_cubic"]

#: Film radius the table reaches (mm): the half diagonal of physcam's largest sensor (IMAX 15/70).
RADIAL_MAX_MM = 44.0
#: Film radii tabulated, uniform from the axis to :data:`RADIAL_MAX_MM` (1.22 mm apart: where other
#: surfaces start to cut the passing set, the area bends in rho faster than 1.83 mm steps follow).
N_RADIAL = 37
#: Iris radius ratio between consecutive levels below the file's stop (a third of a stop in f-number).
LEVEL_RATIO = 2.0 ** (1.0 / 6.0)
#: Iris levels tabulated: the widest iris, the file's stop, and on down to 1/16 of it (eight stops).
N_LEVEL = 26
_GRID = 36  # aim samples across a grid (half as many across its y >= 0 half)
#: The largest error of the interpolated passing area that may weigh a ray (see radial_pupil_table).
AREA_TOLERANCE = 0.004
#: About the rays one table traces (2e5 on the double Gauss): what picks its tracing backend.
TABLE_RAYS = 200_000
_DS = 0.02  # the area's slope at a level: from the areas at the level and a 2 % smaller iris


def iris_levels(semi_max: float, semi_file: float) -> np.ndarray:
    """The tabulated iris radii (mm), largest first: the widest iris (``semi_max``: physcam's camera
    state opens the stop a little beyond the file's, to the lens's marked f-number), the file's stop
    (``semi_file``: on axis the other elements pass no more) and :data:`LEVEL_RATIO` steps below it."""
    if not 0 < semi_file <= semi_max:
        raise InputError(f"iris levels need 0 < file stop <= widest iris, got {semi_file!r} and {semi_max!r}")
    return np.concatenate([[float(semi_max)], float(semi_file) * LEVEL_RATIO ** -np.arange(N_LEVEL - 1, dtype=float)])


#: Iris levels that share the aims of the centre's normalisation (:func:`_centre_ellipses`)
_NORM_GROUP = 2


def _centre_ellipses(table) -> np.ndarray:
    """Per iris level of a radial pupil table (:func:`radial_pupil_table`), the film centre's ellipse
    (cx, ax, ay) whose aims weigh the centre's mean weight at that level (the shader's normalisation):
    the widest level's of each :data:`_NORM_GROUP` consecutive levels. The passing sets nest, so it
    holds the smaller ones' too; the mean weight does not depend on the region sampled, only its
    noise does, and levels that share a region share their rays."""
    table = np.asarray(table)
    return table[(np.arange(table.shape[0]) // _NORM_GROUP) * _NORM_GROUP, 0, :3]


def _levels(levels) -> np.ndarray:
    """``levels`` as iris radii (mm) that :func:`iris_levels` could have given, or InputError."""
    try:
        a = np.asarray(levels, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"iris levels must be radii in mm, largest first (iris_levels), got {levels!r:.60}") from None
    if a.ndim != 1 or a.size < 2 or not np.isfinite(a).all() or not (a > 0).all() or (np.diff(a) > 0).any():
        raise InputError(f"iris levels must be at least two radii in mm, largest first (iris_levels), got {levels!r:.60}")
    return a


def _table(table, levels) -> np.ndarray:
    require_type("table", table, np.ndarray, "a radial pupil table (radial_pupil_table)")
    if table.ndim != 3 or table.shape[2] != 5 or table.shape[1] != N_RADIAL or table.shape[0] != len(_levels(levels)):
        raise InputError(f"a radial pupil table has shape (levels, {N_RADIAL}, 5), one row per iris level; "
                         f"got {table.shape} for {len(_levels(levels))} levels")
    return table


def level_bracket(levels, s: float) -> tuple[int, float, float]:
    """(l0, lw, shrink): the shader's reading of iris radius ``s``: levels l0 and l0 + 1 mixed with
    weight lw (linear in s); below the last level, the last one's axes times ``shrink`` = s / s_last."""
    return _bracket(_levels(levels), require_finite("iris radius", s))


def _bracket(levels, s: float) -> tuple[int, float, float]:
    n = len(levels)
    if s <= levels[-1]:
        return n - 2, 1.0, s / levels[-1]
    # the last level at least s (levels descend): the shader's loop, by bisection
    l0 = min(max(int(np.searchsorted(-levels, -s, side="right")) - 1, 0), n - 2)
    gap = levels[l0] - levels[l0 + 1]
    return l0, (min(max((levels[l0] - s) / gap, 0.0), 1.0) if gap > 0 else 1.0), 1.0


class _StopCrossing:
    """Stands in for the iris shape in physcam's tracer (which calls ``density_at`` with every ray's
    place on the stop's unit disk, then traces on): keeps each ray's radius there and passes them all."""

    def __init__(self):
        self.radius = self.x = self.y = None

    def density_at(self, x, y):
        self.x, self.y, self.radius = x, y, np.hypot(x, y)
        return np.ones_like(self.radius)


def _aims(q, film_z: float, fx, px, py, big: float, backend: str):
    """(passes every surface but the stop, radius where it crosses the stop plane) of rays from film
    points (fx, 0) to aim points (px, py) on the rear vertex plane, in one trace."""
    ok, probe = _aims_probe(q, film_z, fx, px, py, big, backend)
    return ok, probe.radius * big


def _aims_probe(q, film_z: float, fx, px, py, big: float, backend: str):
    """(passes every surface but the stop, the stop crossings in units of ``big``: :class:`_StopCrossing`)
    of :func:`_aims`' rays."""
    from ..trace.rays import OK, RayBatch
    from ..trace.trace import trace_through

    fx = np.asarray(fx, dtype=float)
    # the batch built here, not by RayBatch.from_columns: every input is finite by construction, and
    # its checks and copies cost as much as the trace kernel on these short rays
    n, dz = fx.size, float(q.vertex_z[-1] - film_z)
    ux, uy = px - fx, np.asarray(py, dtype=float)
    inv = 1.0 / np.sqrt(ux * ux + uy * uy + dz * dz)
    rays = RayBatch(fx.copy(), np.zeros(n), np.full(n, film_z), ux * inv, uy * inv, dz * inv,
                    np.full(n, q.wavelength_nm), np.ones(n), np.zeros(n, dtype=np.uint8))
    probe = _StopCrossing()
    trace_through(q, rays, reverse=True, clip=True, stop_semi_diameter=big, aperture=probe, in_place=True,
                  backend=backend)
    return rays.flag == OK, probe


#: Neighbours a rim is looked for toward: +x, -x and +y (the y = 0 side mirrors itself), as the
#: sample's and the neighbour's cells of a (ny, nx) grid, and the step's direction.
_TOWARD = (((slice(None), slice(0, -1)), (slice(None), slice(1, None)), (1, 0)),
           ((slice(None), slice(1, None)), (slice(None), slice(0, -1)), (-1, 0)),
           ((slice(0, -1), slice(None)), (slice(1, None), slice(None)), (0, 1)))
_ZOOM = 0.6  # a grid zooms in once its set spans under this share of it, across or along
_HALVINGS = 4  # where another surface clips between two samples, it is found to 1/16 of a step


def _trace(q, film_z: float, fxs, boxes, radii, big: float, backend: str) -> list:
    """Rays from film points (fx, 0) to the aim grid over each one's box on the rear vertex plane, in
    one trace: per film point (x, y, passes every surface but the stop, radius where it crosses the
    stop plane, grid steps, fx, at how many of the descending iris radii ``radii`` it passes:
    :func:`_n_passing`)."""
    nx, ny = _GRID, _GRID // 2
    x0, x1, y1 = np.array(boxes, dtype=float).T
    dx, dy = (x1 - x0) / nx, y1 / ny  # a _GRID x _GRID/2 grid over each box (x0, x1, y1: the y >= 0 half)
    xs = x0[:, None] + (np.arange(nx) + 0.5)[None, :] * dx[:, None]
    ys = (np.arange(ny) + 0.5)[None, :] * dy[:, None]
    gx = np.broadcast_to(xs[:, None, :], (len(boxes), ny, nx)).reshape(len(boxes), -1)
    gy = np.broadcast_to(ys[:, :, None], (len(boxes), ny, nx)).reshape(len(boxes), -1)
    fxs = np.asarray(fxs, dtype=float)
    ok, rad = _aims(q, film_z, np.repeat(fxs, ny * nx), gx.ravel(), gy.ravel(), big, backend)
    ok, rad = ok.reshape(len(boxes), -1), rad.reshape(len(boxes), -1)
    n_in = _n_passing(radii, np.where(ok, rad, np.inf)).astype(np.int16 if radii.size < 2**15 else np.int64)
    return [(gx[i], gy[i], ok[i], rad[i], d_x, d_y, f, n_in[i])
            for i, (d_x, d_y, f) in enumerate(zip(dx.tolist(), dy.tolist(), fxs.tolist()))]


def _clip_edges(q, film_z: float, uses, radii, big: float, backend: str):
    """The clip edges of the grids in ``uses`` (grid of :func:`_trace`, first and end index into the
    descending iris radii ``radii`` it serves), all halved in one batch of traces: between a sample
    that passes at the grid's first radius and a neighbour another surface clips, the edge of what
    the other surfaces pass is found by halving (:data:`_HALVINGS`). Returns (key, lo, hi, r_lo)
    sorted by key: the pair's key (3 u + d) ny nx + j nx + i for grid u, direction d of
    :data:`_TOWARD` and the pair's cell (j, i) in that direction's view of the grid, the fractions of
    the step that pass and that do not, and the stop radius at the last passing point."""
    nx, ny = _GRID, _GRID // 2
    okg = np.stack([g[2] for g, _, _ in uses]).reshape(-1, ny, nx)
    rad = np.stack([g[3] for g, _, _ in uses])
    x0, y0, dx, dy, fx = (np.array(v) for v in zip(*((g[0][0], g[1][0], g[4], g[5], g[6]) for g, _, _ in uses)))
    # a pair matters only where its passing sample passes at the grid's first radius (it then makes rim points)
    serves = (rad <= radii[np.array([u[1] for u in uses])][:, None]).reshape(-1, ny, nx)
    parts = []  # per direction: key, x, y, step x, step y, film x, the sample's stop radius
    for d, (ca, cb, (sx, sy)) in enumerate(_TOWARD):
        g, jj, ii = np.nonzero((okg & serves)[(slice(None),) + ca] & ~okg[(slice(None),) + cb])
        ja, ia = jj + (ca[0].start or 0), ii + (ca[1].start or 0)
        parts.append(((g * 3 + d) * (ny * nx) + jj * nx + ii, x0[g] + ia * dx[g], y0[g] + ja * dy[g], sx * dx[g],
                      sy * dy[g], fx[g], rad[g, ja * nx + ia]))
    key, x, y, sx, sy, ff, r_lo = (np.concatenate([p[k] for p in parts]) for k in range(7))
    lo, hi = np.zeros(x.size), np.ones(x.size)
    for _ in range(_HALVINGS if x.size else 0):
        mid = 0.5 * (lo + hi)
        passes, r_mid = _aims(q, film_z, ff, x + mid * sx, y + mid * sy, big, backend)
        lo, hi, r_lo = np.where(passes, mid, lo), np.where(passes, hi, mid), np.where(passes, r_mid, r_lo)
    o = np.argsort(key, kind="stable")
    return key[o], lo[o], hi[o], r_lo[o]


def _rims(uses, edges, radii, wanted) -> "_RimSet":
    """The rims of the passing sets of the grids in ``uses`` (grid of :func:`_trace`, first and end
    index into the descending iris radii ``radii`` it serves), one per grid and iris radius of its
    range, numbered in that order (grid after grid), as points (x, y) (:class:`_RimSet`; a rim
    without points: nothing passes). Between a passing sample and a neighbour the iris stops,
    the rim is where the stop radius crosses s (linear between the two: the stop radius is smooth);
    toward a neighbour another surface clips it is at the halved edge (``edges``:
    :func:`_clip_edges`), past the grid's edge at the neighbour (conservative). The set is convex
    (the iris's image, cut by other round apertures), so its rim bounds it. A sample passes at
    every iris radius from its stop radius t up (t infinite where another surface clips): a sample
    and its neighbour make a rim point at the radii in [t_a, t_b), found for every grid and radius
    at once by bisection in ``radii``. ``wanted`` (grids x radii): the rims to find (the others are
    left without points)."""
    ny, nx = _GRID // 2, _GRID
    ok = np.stack([g[2] for g, _, _ in uses])  # (grids, ny nx)
    rad = np.stack([g[3] for g, _, _ in uses])
    t = np.where(ok, rad, np.inf).reshape(-1, ny, nx)
    x0, y0, dx, dy = (np.array(v) for v in zip(*((g[0][0], g[1][0], g[4], g[5]) for g, _, _ in uses)))
    e_key, e_lo, e_hi, e_rad = edges
    r0, r1 = np.array([u[1] for u in uses]), np.array([u[2] for u in uses])
    first = np.concatenate([[0], np.cumsum(r1 - r0)])  # each grid's first rim
    first_r0 = first[:-1] - r0  # a grid's rim at radius index i: first_r0 + i

    # the wanted radii grid after grid (wanted_i), and per grid how many of them lie below each radius index
    wanted = np.asarray(wanted, dtype=bool)
    below = np.concatenate([np.zeros((wanted.shape[0], 1), dtype=np.int64), np.cumsum(wanted, axis=1)], axis=1)
    below += np.concatenate([[0], np.cumsum(below[:-1, -1])])[:, None]
    wanted_i = np.nonzero(wanted)[1]

    def expand(g, lo, hi):  # (rim index, radius index, which entry) of every entry's wanted radii in [lo, hi)
        a = below[g, lo]
        n = below[g, hi] - a
        e = np.repeat(np.arange(g.size), n)
        i = wanted_i[np.arange(e.size) + np.repeat(a - (np.cumsum(n) - n), n)]
        return np.repeat(first_r0[g], n) + i, i, e

    small = np.int16 if max(int(first[-1]), radii.size) < 2**15 else np.int64
    r0_, r1_ = r0.astype(small)[:, None, None], r1.astype(small)[:, None, None]
    n_in = np.stack([g[7] for g, _, _ in uses]).reshape(-1, ny, nx).astype(small)  # per sample: it passes at radii[:n_in]
    rad, ok = rad.ravel(), ok.ravel()
    parts = []  # (rim index, x, y, xa, ya)
    # toward +x, -x and +y: the sample's (a) and its neighbour's (b) cells
    for d, ((ja, ia_), (jb, ib), (sx, sy)) in enumerate(_TOWARD):
        lo, hi = np.maximum(n_in[:, jb, ib], r0_), np.minimum(n_in[:, ja, ia_], r1_)
        # the pairs with a rim point at some radius of their grid (np.nonzero's order, from the flat index)
        h, w = hi.shape[1:]
        flat = np.flatnonzero(hi > lo)
        g, rest = np.divmod(flat, h * w)
        jj, ii = np.divmod(rest, w)
        a = (g * ny + jj + (ja.start or 0)) * nx + ii + (ia_.start or 0)  # the cells in the flat grids
        b = (g * ny + jj + (jb.start or 0)) * nx + ii + (ib.start or 0)
        ra, nb_ok = rad[a], ok[b]
        # toward a neighbour the iris stops, the rim is where the stop radius crosses s, linear from
        # the sample's (ra) to the neighbour's; toward one another surface clips, at the halved edge
        # (held: its far end e1; area: its middle), unless the iris stops the ray first: where the
        # stop radius at the halved edge's last passing point (r_e, at e0 of the step) exceeds s, the
        # rim is between the two
        r_e, rate = np.full(g.size, np.inf), np.zeros(g.size)
        e1, e_mid = np.ones(g.size), np.ones(g.size)
        cut = np.flatnonzero(~nb_ok)
        at = np.searchsorted(e_key, (g[cut] * 3 + d) * (ny * nx) + jj[cut] * nx + ii[cut])
        with np.errstate(divide="ignore", invalid="ignore"):
            rate[nb_ok] = 1.0 / (rad[b[nb_ok]] - ra[nb_ok])
            r_e[cut], rate[cut] = e_rad[at], e_lo[at] / (e_rad[at] - ra[cut])
        e1[cut], e_mid[cut] = e_hi[at], 0.5 * (e_lo[at] + e_hi[at])
        step = sx * dx[g] + sy * dy[g]  # the step's length (along x or y)
        base = (x0[g] + (ii + (ia_.start or 0)) * dx[g]) if sx else (y0[g] + (jj + (ja.start or 0)) * dy[g])
        other = (y0[g] + (jj + (ja.start or 0)) * dy[g]) if sx else (x0[g] + (ii + (ia_.start or 0)) * dx[g])
        k, ri, e = expand(g, lo[g, jj, ii].astype(np.int64), hi[g, jj, ii].astype(np.int64))
        s_ = radii[ri]
        iris = s_ < r_e[e]
        with np.errstate(invalid="ignore"):
            f_iris = np.clip((s_ - ra[e]) * rate[e], 0.0, 1.0)
        f, fa = np.where(iris, f_iris, e1[e]), np.where(iris, f_iris, e_mid[e])
        along, across = base[e], other[e]
        step = step[e]
        moved, moved_a = along + step * f, along + step * fa
        parts.append((k, moved, across, moved_a, across) if sx else (k, across, moved, across, moved_a))
    for cells, ox, oy in (((slice(None), slice(0, 1)), -1, 0), ((slice(None), slice(nx - 1, None)), 1, 0),
                          ((slice(ny - 1, None), slice(None)), 0, 1)):  # past the grid's edge: a step out
        cell = (slice(None),) + cells
        lo, hi = np.broadcast_to(r0_, t[cell].shape), np.minimum(n_in[cell], r1_)
        rim = hi > lo
        g, jj, ii = np.nonzero(rim)
        jj, ii = jj + (cells[0].start or 0), ii + (cells[1].start or 0)
        bx, by = x0[g] + ii * dx[g], y0[g] + jj * dy[g]
        ex, ey = (ox * dx[g] if ox else np.zeros(g.size)), (oy * dy[g] if oy else np.zeros(g.size))
        k, _, e = expand(g, lo[rim].astype(np.int64), hi[rim].astype(np.int64))
        bx, by, ex, ey = bx[e], by[e], ex[e], ey[e]
        parts.append((k, bx + ex, by + ey, bx + ex / 2, by + ey / 2))
    n_rims = int(first[-1])
    k = np.concatenate([p[0] for p in parts])
    order = np.argsort(k.astype(small), kind="stable")  # a radix sort on 16-bit integers
    k = k[order]
    x, y, xa, ya = (np.concatenate([p[c] for p in parts])[order] for c in range(1, 5))
    cuts = np.searchsorted(k, np.arange(n_rims + 1))
    return _RimSet(x, y, cuts, _polygon_areas(k, xa, ya, cuts))


def _rims_compiled(uses, edges, radii, wanted, kernel) -> "_RimSet":
    """:func:`_rims` by the compiled rim pass ``kernel`` (:func:`~physcam.trace.kernels.rim_pass`): the same
    points in the same order, bit for bit, so the same rims and areas, without the numpy pass's gathers and sort."""
    ny, nx = _GRID // 2, _GRID
    ok = np.stack([g[2] for g, _, _ in uses]).reshape(-1, ny, nx)
    rad = np.stack([g[3] for g, _, _ in uses]).reshape(-1, ny, nx)
    n_in = np.stack([g[7] for g, _, _ in uses]).reshape(-1, ny, nx).astype(np.int64)
    x0, y0, dx, dy = (np.array(v, dtype=float) for v in zip(*((g[0][0], g[1][0], g[4], g[5]) for g, _, _ in uses)))
    r0, r1 = np.array([u[1] for u in uses], dtype=np.int64), np.array([u[2] for u in uses], dtype=np.int64)
    first = np.concatenate([[0], np.cumsum(r1 - r0)])
    e_key, e_lo, e_hi, e_rad = edges
    # C-ordered arrays of these types: the one signature scripts/compile_jit.py compiles
    c = np.ascontiguousarray
    pts, cuts = kernel(ok, rad, n_in, x0, y0, dx, dy, r0, r1, first[:-1] - r0, c(wanted, dtype=bool), c(radii, dtype=float),
                       c(e_key, dtype=np.int64), c(e_lo, dtype=float), c(e_hi, dtype=float), c(e_rad, dtype=float),
                       int(first[-1]))
    k = np.repeat(np.arange(cuts.size - 1), np.diff(cuts))
    x, y, xa, ya = (c(pts[:, j]) for j in range(4))
    return _RimSet(x, y, cuts, _polygon_areas(k, xa, ya, cuts))


def _polygon_areas(k, xa, ya, cuts) -> np.ndarray:
    """Per rim (points ``k`` sorted, rim i's from ``cuts[i]`` to ``cuts[i + 1]``): the set's area (mm^2,
    both halves), the polygon through its edge points (xa, ya >= 0) and their mirror images, taken in
    angle order about their middle (the set is convex); 0 for a rim without points. With the points
    U_1..U_m of the half y >= 0 in angle order, the shoelace sum over the whole polygon is twice
    sum_i (x_i y_i+1 - x_i+1 y_i) + x_1 y_1 - x_m y_m (the mirror half adds as much, and the two
    closing edges cross the axis)."""
    n = cuts.size - 1
    out = np.zeros(n)
    if k.size == 0:
        return out
    starts = cuts[:-1][cuts[1:] > cuts[:-1]]
    mid = 0.5 * (np.minimum.reduceat(xa, starts) + np.maximum.reduceat(xa, starts))
    mids = np.zeros(n)
    mids[k[starts]] = mid
    # in angle order within each rim (the angle, in [0, pi], plus 4 k: each rim's points stay in its span)
    o = np.argsort(np.arctan2(ya, xa - mids[k]) + 4.0 * k)
    x, y = xa[o], ya[o]
    cross = np.append(x[:-1] * y[1:] - x[1:] * y[:-1], 0.0)
    ends = np.append(starts[1:], k.size) - 1
    cross[ends] = 0.0  # no edge from one rim to the next
    total = np.add.reduceat(cross, starts) + x[starts] * y[starts] - x[ends] * y[ends]
    out[k[starts]] = np.abs(total)
    return out


class _RimSet:
    """Rims of passing sets (:func:`_rims`): rim i holds points (x, y >= 0) rows ``cuts[i]`` to
    ``cuts[i + 1]`` (where another surface clips, a step out: they hold the set), and ``area[i]``, the
    set's area (mm^2, both halves, :func:`_polygon_areas`: from points at the best estimate of its edge)."""

    __slots__ = ("x", "y", "cuts", "area")

    def __init__(self, x, y, cuts, area):
        self.x, self.y, self.cuts, self.area = x, y, cuts, area

    def points(self, which) -> tuple:
        """(x, y, count): the points of the rims ``which`` (indices), rim after rim, and each one's count."""
        a, n = self.cuts[which], self.cuts[np.asarray(which) + 1] - self.cuts[which]
        idx = np.repeat(a - (np.cumsum(n) - n), n) + np.arange(int(n.sum()))
        return self.x[idx], self.y[idx], n


def _rear_boxes(q, film_z: float, fxs, r_rear: float) -> list:
    """Per film point (fx, 0): the box (x0, x1, y1) on the rear vertex plane that holds the rear element's
    rim as the point sees it (:func:`_first_grids`)."""
    from ..lens.geometry import sag

    rear, d = q.surfaces[-1], film_z - q.vertex_z[-1]
    ks = [d / (d - sag(rear, r_rear, ax)) for ax in ("x", "y")] + [1.0]
    return [(min(f * (1 - k) - k * r_rear for k in ks), max(f * (1 - k) + k * r_rear for k in ks), max(ks) * r_rear)
            for f in np.asarray(fxs, dtype=float).tolist()]


def _first_grids(q, film_z: float, fxs, radii, r_rear: float, big: float, backend: str) -> tuple[list, list]:
    """Per film point (fx, 0): the box (x0, x1, y1) of its first grid and the grid (:func:`_trace`).
    The rear element's square on the rear vertex plane, and its rim seen from the film point there
    (the rim lies sag off that plane: a ray the rim passes crosses the plane up to d / (d - sag) of the
    way from the film point toward it, d the film's distance from the rear vertex; where the rear
    surface bows toward the film the passing aims of a point far off axis reach past the square), unless
    fewer than :data:`~physcam.trace.pupil_bounds.MIN_HITS` of its
    aims pass at the widest iris radius (``radii[0]``; a cover glass close to the film: the spot is under one grid
    step); then a window about the point straight ahead, half as wide as the film's distance from
    the rear vertex, doubled while the passing aims touch its edge or none pass."""
    from ..trace.pupil_bounds import MIN_HITS

    s_max = radii[0]
    boxes = _rear_boxes(q, film_z, fxs, r_rear)
    outer = list(boxes)  # the windows below stay inside each point's box
    grids = _trace(q, film_z, fxs, boxes, radii, big, backend)
    pending = [p for p, g in enumerate(grids) if (g[2] & (g[3] <= s_max)).sum() < MIN_HITS]
    h = 0.5 * (film_z - q.vertex_z[-1])
    while pending and h < 2 * r_rear:
        wins = {p: (max(fxs[p] - h, outer[p][0]), min(fxs[p] + h, outer[p][1]), min(h, outer[p][2])) for p in pending}
        wins = {p: w for p, w in wins.items() if w[1] > w[0]}
        done = set()
        for p, g in zip(wins, _trace(q, film_z, [fxs[p] for p in wins], list(wins.values()), radii, big, backend) if wins else []):
            w, sel, o = wins[p], g[2] & (g[3] <= s_max), outer[p]
            if sel.any():
                x, y = g[0][sel], g[1][sel]
                edge = ((w[0] > o[0] and x.min() < w[0] + g[4]) or (w[1] < o[1] and x.max() > w[1] - g[4])
                        or (w[2] < o[2] and y.max() > w[2] - g[5]))
                if not edge:
                    boxes[p], grids[p] = w, g
                    done.add(p)
        pending = [p for p in pending if p not in done]
        h *= 2
    return boxes, grids


def _passing_grids(q, film_z: float, fxs, radii, r_rear: float, big: float, backend: str, ends=None) -> tuple:
    """(used, p, r0, r1, edges): the grids traced for film points (fx, 0) (:func:`_trace`), each with the
    first and end index into the descending iris radii ``radii`` it serves, the film point it serves (p) and
    those indices again as arrays, and their clip edges (:func:`_clip_edges`). A point's grid zooms in on
    its passing set once that has shrunk under :data:`_ZOOM` of the grid. ``ends``: per film point, the
    radius index its grids stop at (the radii from there on are found along lines, :class:`_LineSets`;
    None: every radius)."""
    ends = [radii.size] * len(fxs) if ends is None else [int(e) for e in ends]
    boxes, grids = _first_grids(q, film_z, fxs, radii, r_rear, big, backend)
    start = [0] * len(fxs)  # the first radius each point's current grid serves
    uses = [[] for _ in fxs]  # per film point: (grid, the first and end index of the radii it serves)
    pending = list(range(len(fxs)))
    while pending:
        first, (xmin, xmax, ymax) = _shrunk(radii, [grids[p] for p in pending], [boxes[p] for p in pending],
                                            [start[p] for p in pending])
        zoom = {}
        for i, p in enumerate(pending):
            f, dx, dy = min(int(first[i]), ends[p]), grids[p][4], grids[p][5]
            uses[p].append((grids[p], start[p], f))
            if f < ends[p]:
                zoom[p] = (xmin[i, f] - 2 * dx, xmax[i, f] + 2 * dx, ymax[i, f] + 2 * dy)
                start[p] = f
        for p, g in zip(zoom, _trace(q, film_z, [fxs[p] for p in zoom], list(zoom.values()), radii, big, backend)
                        if zoom else []):
            grids[p], boxes[p] = g, zoom[p]
        pending = list(zoom)
    flat = [(p, use) for p, u in enumerate(uses) for use in u if use[2] > use[1]]
    if not flat:
        return [], np.zeros(0, dtype=int), np.zeros(0, dtype=int), np.zeros(0, dtype=int), None
    used = [use for _, use in flat]
    p, r0, r1 = (np.array(v) for v in zip(*((p, use[1], use[2]) for p, use in flat)))
    return used, p, r0, r1, _clip_edges(q, film_z, used, radii, big, backend)


def _grid_rims(grids, radii, wanted, n_points: int, backend: str = "numpy") -> tuple:
    """(index, rims): the rims (:class:`_RimSet`, :func:`_rims`) of the grids of :func:`_passing_grids`
    (``grids``) at the ``wanted`` (film points x ``radii``) iris radii, and per film point and iris radius the
    index of its rim there, -1 where nothing passes (or the rim is not wanted). With numba (``backend``,
    :func:`~physcam.trace.kernels.rim_pass`) the compiled pass finds the same rims."""
    from ..trace.kernels import rim_pass

    used, p, r0, r1, edges = grids
    index = np.full((n_points, radii.size), -1)
    if not used:
        return index, _RimSet(np.zeros(0), np.zeros(0), np.zeros(1, dtype=int), np.zeros(0))
    kernel = rim_pass(backend)
    rims = (_rims(used, edges, radii, np.asarray(wanted)[p]) if kernel is None
            else _rims_compiled(used, edges, radii, np.asarray(wanted)[p], kernel))
    n = r1 - r0
    k = np.arange(int(n.sum()))  # the rims in their order: grid after grid, radius after radius
    index[np.repeat(p, n), np.repeat(r0 - (np.cumsum(n) - n), n) + k] = np.where(rims.cuts[k + 1] > rims.cuts[k], k, -1)
    return index, rims


class _PassingSets:
    """The passing sets of one focused lens's film points (the film radii of :func:`_check_axes`), traced
    once at every iris radius a table at ``levels`` reads (with ``finer``: also at those of a table whose
    levels add any of the geometric middles between them, :func:`_refined_levels`), their rims found as
    tables ask for them (:meth:`table`): a radius more costs its rims, not a trace. With ``lines``, the film
    points whose sets are star-shaped from their chief aim are sampled along lines from it (:class:`_LineSets`)
    and only the others on aim grids (:func:`_passing_grids`, the dense search)."""

    def __init__(self, q, film_z: float, levels, backend: str, *, finer: bool = False, lines: bool = False):
        levels = _levels(levels)
        fine = np.sort(np.concatenate([levels, np.sqrt(levels[:-1] * levels[1:])]))[::-1] if finer else levels
        rhos, checked = _check_axes(fine)
        self.film_z, self.rhos, self.backend = film_z, rhos, backend
        self.radii = np.unique(np.concatenate([checked, fine * (1 - _DS)]))[::-1]
        self.big = 20.0 * max(levels[0], q.surfaces[q.stop_index].semi_diameter)
        r_rear = q.surfaces[-1].semi_diameter
        self.lines = (_LineSets(q, film_z, rhos, self.radii, _rear_boxes(q, film_z, rhos, r_rear), self.big, backend)
                      if lines else None)
        # per film point, the radius index from which its rims are found along lines (none: radii.size)
        self.line_from = np.full(rhos.size, self.radii.size)
        if lines:
            self.line_from[self.lines.points] = self.lines.first
        self.on_grid = np.flatnonzero(self.line_from > 0)
        self.grids = (_passing_grids(q, film_z, rhos[self.on_grid].tolist(), self.radii, r_rear, self.big, backend,
                                     self.line_from[self.on_grid])
                      if self.on_grid.size else ([], None, None, None, None))
        self.index = np.full((rhos.size, self.radii.size), -1)
        self.have = np.zeros((rhos.size, self.radii.size), dtype=bool)
        self.rims = _RimSet(np.zeros(0), np.zeros(0), np.zeros(1, dtype=int), np.zeros(0))

    def need(self, levels) -> None:
        """Find the rims a table at ``levels`` reads that are not found yet: at the nodes every level, its
        slope's radius (:data:`_DS`) and the checks, between them only the checks."""
        _, checked = _check_axes(levels)
        wanted = np.zeros_like(self.have)
        wanted[:N_RADIAL] = np.isin(self.radii, np.concatenate([checked, np.asarray(levels) * (1 - _DS)]))
        wanted[N_RADIAL:] = np.isin(self.radii, checked)
        wanted &= ~self.have
        if not wanted.any():
            return
        if self.on_grid.size:
            index, rims = _grid_rims(self.grids, self.radii, wanted[self.on_grid], self.on_grid.size, self.backend)
            self._add(self.on_grid, index, rims)
        if self.lines is not None and self.lines.points.size:
            p = self.lines.points
            on = wanted[p] & (np.arange(self.radii.size)[None, :] >= self.lines.first[:, None])
            cols = np.flatnonzero(on.any(axis=0))
            x, y, area = self.lines.rims(self.radii[cols])
            sel = on[:, cols]
            n = int(sel.sum())
            index = np.full((p.size, self.radii.size), -1)
            gi, ci = np.nonzero(sel)
            index[gi, cols[ci]] = np.arange(n)
            self._add(p, index, _RimSet(x[sel].ravel(), y[sel].ravel(), np.arange(n + 1) * _LINES, area[sel]))
        self.have |= wanted

    def _add(self, points, index, rims) -> None:
        """Keep ``rims`` (indexed per film point of ``points`` and radius by ``index``, -1: none) with the found ones."""
        n, old = self.rims.area.size, self.rims
        self.index[points] = np.where(index >= 0, index + n, self.index[points])
        self.rims = _RimSet(np.concatenate([old.x, rims.x]), np.concatenate([old.y, rims.y]),
                            np.concatenate([old.cuts, rims.cuts[1:] + old.x.size]), np.concatenate([old.area, rims.area]))

#: Lines from a film point's chief aim, over the y >= 0 half (both ends on the meridional axis), along
#: which :class:`_LineSets` finds each iris radius's rim
_LINES = 25
_LINE_STEP = 1.35  # the samples along a line: geometric, this ratio apart
_LINE_SPAN = 1.6  # from this times the widest iris's rim (the linear estimate) in to the smallest's over it
_LINE_HALVINGS = 6  # a clip edge on a line is found to 1/64 of its sample step
_FAN = 41  # meridional aims across a film point's box where its chief aim is looked for
#: The lines serve an iris radius only where it is under every cut line's edge (in stop radius) by this
#: share: there the iris alone bounds the set (module notes); the wider radii take the aim grids
_LINE_MARGIN = 0.05
#: ... and only where the rim's place on every line is the same, to this share of its distance from the chief aim,
#: by the quadratics through the samples about it and the next one in or out (:meth:`_LineSets._rim_t`): at most
#: 0.2 % of the area, half AREA_TOLERANCE (the lines' areas measured within 0.15 % of a dense trace, docs/performance.md)
_LINE_DOUBT = 1e-3
_BAND = 400.0  # :meth:`_LineSets._rim_t`'s search: each line's log stop radii in a band this wide


def _chief_aims(q, film_z: float, fxs, boxes, big: float, backend: str) -> tuple[np.ndarray, np.ndarray]:
    """Per film point (fx, 0): (the aim x on the rear vertex plane of its ray through the stop's centre, the
    rate d x_stop / d aim x there), nan where none is found: no passing pair of :data:`_FAN` meridional aims
    across the point's box (:func:`_rear_boxes`) brackets it (the chief ray is cut), or a Newton step fails."""
    fxs = np.asarray(fxs, dtype=float)
    b = np.asarray(boxes, dtype=float).reshape(-1, 3)
    px = b[:, :1] + (np.arange(_FAN) + 0.5)[None, :] / _FAN * (b[:, 1:2] - b[:, :1])
    ok, probe = _aims_probe(q, film_z, np.repeat(fxs, _FAN), px.ravel(), np.zeros(px.size), big, backend)
    ok, xs = ok.reshape(px.shape), (probe.x * big).reshape(px.shape)
    pair = ok[:, :-1] & ok[:, 1:] & ((xs[:, :-1] <= 0) != (xs[:, 1:] <= 0))
    i, j = np.arange(fxs.size), np.argmax(pair, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(pair.any(axis=1), px[i, j] + (px[i, j + 1] - px[i, j]) * xs[i, j] / (xs[i, j] - xs[i, j + 1]), np.nan)
    rate = np.full(fxs.size, np.nan)
    h = 1e-4 * (b[:, 1] - b[:, 0])
    for _ in range(3):  # Newton's steps, the rate by a forward difference
        g = np.flatnonzero(np.isfinite(c))
        if not g.size:
            break
        ok, probe = _aims_probe(q, film_z, np.tile(fxs[g], 2), np.concatenate([c[g], c[g] + h[g]]), np.zeros(2 * g.size),
                                big, backend)
        x = probe.x * big
        with np.errstate(divide="ignore", invalid="ignore"):
            d = (x[g.size:] - x[:g.size]) / h[g]
            good = ok[:g.size] & ok[g.size:] & np.isfinite(d) & (d != 0)
            c[g] = np.where(good, c[g] - x[:g.size] / np.where(good, d, 1.0), np.nan)
        rate[g] = d
    return c, rate


class _LineSets:
    """The passing sets of film points (fx, 0) sampled along :data:`_LINES` lines from each one's chief aim c
    (:func:`_chief_aims`; module notes): a ray through c crosses the stop at its centre, so c passes at every
    iris radius, and where the sets are star-shaped from c (convex sets that hold it are: the iris's image cut
    by other round apertures) each iris radius's rim crosses each line once. Along a line the stop radius r(t)
    rises from 0 at c; the samples are geometric in t (:data:`_LINE_STEP` apart, from the smallest iris's rim
    over :data:`_LINE_SPAN` out past the widest's, extended while the last one passes inside the widest
    iris), and where another surface cuts the line its edge is halved :data:`_LINE_HALVINGS` times. The rim of
    iris radius s on a line is where r = s, interpolated in log t against log r between the two samples
    about it and the next (Lagrange's quadratic in log r; from c to the first sample r ~ t), or the clip edge where
    the line is cut before r reaches s (held at the halving's far end, its area at the middle). The set's
    area is the polar integral of t(theta)^2 by the trapezoid rule over the lines (t(theta)^2 is periodic
    and even in theta: the rule converges faster than any power of the step where the rim is smooth), and its
    rim points are pushed out by 1 / cos(half the lines' angle) from c (a circle about c is then held
    between lines). ``star``: per film point, whether its chief aim was found and every line showed a
    star-shaped set (its innermost sample passes, nothing passes past a cut, r rises along it, and it
    reaches the widest iris or is cut): the film points without it take the aim grids."""

    def __init__(self, q, film_z: float, fxs, radii, boxes, big: float, backend: str):
        fxs = np.asarray(fxs, dtype=float)
        c, rate = _chief_aims(q, film_z, fxs, boxes, big, backend)
        g = np.flatnonzero(np.isfinite(c) & np.isfinite(rate) & (rate != 0))
        theta = np.linspace(0.0, math.pi, _LINES)
        ux, uy = np.cos(theta), np.sin(theta)
        m = int(math.ceil(math.log(_LINE_SPAN**2 * radii[0] / radii[-1]) / math.log(_LINE_STEP))) + 1
        t0 = radii[-1] / (_LINE_SPAN * np.abs(rate[g]))
        t = np.broadcast_to((t0[:, None] * _LINE_STEP ** np.arange(m))[:, None, :], (g.size, _LINES, m))
        fx, cx = fxs[g], c[g]

        def trace(gi, ki, tt):  # (passes, stop radius) of the samples at t = tt on lines ki of points gi
            return _aims(q, film_z, fx[gi], cx[gi] + tt * ux[ki], tt * uy[ki], big, backend)

        gg, kk = (a.ravel() for a in np.meshgrid(np.arange(g.size), np.arange(_LINES), indexing="ij"))
        ok, r = trace(np.repeat(gg, m), np.repeat(kk, m), t.reshape(-1))
        ts, oks, rs = [t], [ok.reshape(t.shape)], [r.reshape(t.shape)]
        for _ in range(8):  # on out while the last sample passes inside the widest iris
            more = oks[-1][..., -1] & (rs[-1][..., -1] < radii[0])
            if not more.any():
                break
            gi, ki = np.nonzero(more)
            tn = ts[-1][gi, ki, -1] * _LINE_STEP
            okn, rn = trace(gi, ki, tn)
            col_t, col_ok, col_r = np.full(more.shape, np.nan), np.zeros(more.shape, dtype=bool), np.full(more.shape, np.inf)
            col_t[gi, ki], col_ok[gi, ki], col_r[gi, ki] = tn, okn, rn
            ts, oks, rs = ts + [col_t[..., None]], oks + [col_ok[..., None]], rs + [col_r[..., None]]
        t, ok, r = (np.concatenate(a, axis=2) for a in (ts, oks, rs))
        traced = np.isfinite(t)
        fail = traced & ~ok
        n_in = np.where(fail.any(axis=2), np.argmax(fail, axis=2), traced.sum(axis=2))  # the passing samples before a cut
        inside = np.arange(t.shape[2]) < n_in[..., None]
        cut = fail.any(axis=2)
        last = np.take_along_axis(np.where(inside, r, -np.inf), np.maximum(n_in - 1, 0)[..., None], 2)[..., 0]
        star = ((n_in > 0) & ~(ok & traced & ~inside).any(axis=2) & (cut | (last >= radii[0]))).all(axis=1)
        # the clip edges, halved: the passing middles join the samples
        lo = np.take_along_axis(t, np.maximum(n_in - 1, 0)[..., None], 2)[..., 0]
        hi = np.take_along_axis(t, np.minimum(n_in, t.shape[2] - 1)[..., None], 2)[..., 0]
        gi, ki = np.nonzero(cut & (n_in > 0))
        extra_t, extra_r = [], []
        for _ in range(_LINE_HALVINGS if gi.size else 0):
            mid = 0.5 * (lo[gi, ki] + hi[gi, ki])
            okm, rm = trace(gi, ki, mid)
            lo[gi, ki], hi[gi, ki] = np.where(okm, mid, lo[gi, ki]), np.where(okm, hi[gi, ki], mid)
            col_t, col_r = np.full(lo.shape, np.nan), np.full(lo.shape, np.inf)
            col_t[gi[okm], ki[okm]], col_r[gi[okm], ki[okm]] = mid[okm], rm[okm]
            extra_t.append(col_t[..., None])
            extra_r.append(col_r[..., None])
        t = np.concatenate([np.where(inside, t, np.nan)] + extra_t, axis=2)
        r = np.concatenate([np.where(inside, r, np.inf)] + extra_r, axis=2)
        o = np.argsort(np.where(np.isnan(t), np.inf, t), axis=2, kind="stable")  # each line's samples outward
        t, r = np.take_along_axis(t, o, 2), np.take_along_axis(r, o, 2)
        valid = np.isfinite(t)
        with np.errstate(invalid="ignore"):
            star &= ~(valid[..., 1:] & ~(np.diff(r, axis=2) > 0)).any(axis=(1, 2))  # r rises along every line
        star &= (valid.sum(axis=2) >= 3).all(axis=1)  # three samples a line at least (the rim's quadratic)
        n = valid.sum(axis=2)
        # the stop radius at each cut line's last passing point (r rises along it): an iris radius s with
        # s (1 + _LINE_MARGIN) under every one of them is the iris's alone on every line
        edge = np.where(cut, np.take_along_axis(r, np.maximum(n - 1, 0)[..., None], 2)[..., 0], np.inf).min(axis=1)
        self.points = g[star]  # the film points (indices into fxs) the lines serve
        self.first = np.searchsorted(-radii, -(edge[star] / (1 + _LINE_MARGIN)), side="left")
        self.c, self.t, self.r, self.n = cx[star], t[star], r[star], n[star]
        self.lo, self.hi, self.cut = lo[star], hi[star], cut[star]
        self.theta = theta
        # every rim's place on every line, once; the lines serve no radius at or above one whose interpolation
        # they doubt (the grids take those)
        self.radii = radii
        self.held, self.mean, doubt = self._rim_t(radii)
        doubt = (doubt > _LINE_DOUBT).any(axis=1)  # (points, radii)
        self.first = np.maximum(self.first, np.where(doubt.any(axis=1), radii.size - np.argmax(doubt[:, ::-1], axis=1), 0))

    def _rim_t(self, s) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(held t, mean t, doubt): per film point, line and iris radius of ``s``, where the rim crosses the line
        (held: a cut line's far end; mean: its middle) and the interpolation's doubt (relative, in t)."""
        s = np.asarray(s, dtype=float)
        n_points, n_lines, n_samples = self.t.shape
        lines = n_points * n_lines
        if not lines:  # no film point on lines
            return (np.zeros((n_points, n_lines, s.size)),) * 3
        with np.errstate(divide="ignore", invalid="ignore"):
            lt, lr = np.log(self.t).reshape(lines, -1), np.log(self.r).reshape(lines, -1)
            # Newton's divided differences of log t in log r of every three samples in a row (empty slots: nan)
            d01 = np.diff(lt, axis=1) / np.diff(lr, axis=1)
            d012 = (np.diff(d01, axis=1) / (lr[:, 2:] - lr[:, :-2])).ravel()
        d01 = d01.ravel()
        # the samples under s per line (r rises along it; an empty slot's is inf): one search over every line's
        # log r, each line in its own band (log r spans far less than _BAND)
        line = np.arange(lines)[:, None]
        band = line * _BAND
        ls = np.log(s)[None, :]
        j = np.searchsorted((band + np.minimum(lr, _BAND / 4)).ravel(), (band + ls).ravel(), side="left").reshape(lines, -1)
        j -= line * n_samples
        n = self.n.reshape(lines, 1)
        beyond = j >= n  # past the last passing sample: the clip edge (every line is cut or reaches s)
        lt, lr = lt.ravel(), lr.ravel()

        def quad(a):  # Lagrange's quadratic of log t in log r through the samples a, a + 1, a + 2 of each line
            i, k = line * n_samples + a, line * (n_samples - 2) + a
            return lt[i] + (ls - lr[i]) * (d01[i - line] + (ls - lr[i + 1]) * d012[k])

        with np.errstate(invalid="ignore", over="ignore"):
            # the two samples about s and the next one out (in at the line's last), and the one in instead: where
            # the two quadratics differ the curve bends too fast for the samples (r flattens toward a clip)
            q1, q2 = quad(np.clip(j - 1, 0, n - 3)), quad(np.clip(j - 2, 0, n - 3))
            first = line * n_samples
            t_iris = np.where(j == 0, np.exp(lt[first] + ls - lr[first]), np.exp(q1))  # under the first: r ~ t
            doubt = np.where((j == 0) | beyond, 0.0, np.abs(np.expm1(q2 - q1)))
        shape = (n_points, n_lines, s.size)
        t_iris, doubt, beyond = t_iris.reshape(shape), doubt.reshape(shape), beyond.reshape(shape)
        held = np.where(beyond, self.hi[..., None], t_iris)
        mean = np.where(beyond, 0.5 * (self.lo[..., None] + self.hi[..., None]), t_iris)
        return held, mean, np.where(np.isfinite(doubt), doubt, np.inf)

    def rims(self, s) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x, y, area): per film point served and iris radius of ``s`` (radii the sets were traced for), the rim's
        points held out (x, y: points x radii x lines) and the passing set's area (mm^2, both halves)."""
        at = np.searchsorted(-self.radii, -np.asarray(s, dtype=float))  # the radii of s among those traced for
        held, mean = self.held[:, :, at], self.mean[:, :, at]
        step = self.theta[1] - self.theta[0]
        w = np.full(self.theta.size, step)
        w[[0, -1]] *= 0.5
        area = np.einsum("k,pkr->pr", w, mean * mean)  # both halves: 2 x the half's integral of t^2 / 2
        out = held / math.cos(step / 2)
        x = self.c[:, None, None] + out.transpose(0, 2, 1) * np.cos(self.theta)
        y = out.transpose(0, 2, 1) * np.sin(self.theta)
        return x, y, area


def _n_passing(radii, t) -> np.ndarray:
    """Per sample of stop radius ``t`` (inf where another surface clips): how many of the descending
    iris radii ``radii`` it passes at (those at least t: ``radii[:n]``)."""
    return radii.size - np.searchsorted(radii[::-1], t, side="left")


def _shrunk(radii, grids, boxes, start):
    """Per grid (of :func:`_trace`, over its box) the index of the first iris radius, from ``start`` on,
    whose passing set has shrunk under :data:`_ZOOM` of the grid (len(radii) if none), and per grid
    and radius the passing set's x extent and largest y (of the sample centres). The sets nest: a
    sample with n passing radii (:func:`_n_passing`) is in the sets of radii[:n], so the extremes of
    the columns (rows) per their largest n, taken from the largest n down, give every radius's at once."""
    dx, dy = np.array([g[4] for g in grids])[:, None], np.array([g[5] for g in grids])[:, None]
    b = np.array(boxes)
    n_grid, n_rad = len(grids), radii.size
    n_in = np.stack([g[7] for g in grids]).reshape(n_grid, _GRID // 2, _GRID)
    # a column (row) holds a sample of the set at radius i when its largest count exceeds i
    xs, ys = np.stack([g[0][:_GRID] for g in grids]), np.stack([g[1][::_GRID] for g in grids])

    def running(n, v, fn, empty):  # per grid and radius i: fn over the columns (rows) whose count n > i
        key = (np.arange(n_grid)[:, None] * (n_rad + 1) + n).ravel()
        e = np.full(n_grid * (n_rad + 1), empty)
        fn.at(e, key, v.ravel())
        return fn.accumulate(e.reshape(n_grid, n_rad + 1)[:, ::-1], axis=1)[:, ::-1][:, 1:]

    col, row = n_in.max(axis=1), n_in.max(axis=2)
    xmin, xmax = running(col, xs, np.minimum, np.inf), running(col, xs, np.maximum, -np.inf)
    ymax = running(row, ys, np.maximum, -np.inf)
    anyp = xmin < np.inf
    small = (anyp & ((xmax - xmin + 4 * dx < _ZOOM * (b[:, 1:2] - b[:, 0:1])) | (ymax + 2 * dy < _ZOOM * b[:, 2:3]))
             & (np.arange(radii.size)[None, :] >= np.asarray(start)[:, None]))
    return np.where(small.any(axis=1), np.argmax(small, axis=1), radii.size), (xmin, xmax, ymax)


#: Growth of every fitted ellipse beyond its rim points (the rim between two grid lines; 1.003 left the
#: Canon RF 85 wide open at 16.5 mm off axis 0.07 % short with the coarser grids of round 7)
_SAFETY = 1.006


def _fits(rims, which) -> np.ndarray:
    """Per rim ``which`` (indices into ``rims``, each with points), (cx, ax, ay, area): the ellipse
    about the rim's middle, axes along x and y, that holds every rim point (grown by
    :data:`_SAFETY`), and the passing set's area."""
    x, y, n = rims.points(which)
    starts = np.cumsum(n) - n
    lo, hi = np.minimum.reduceat(x, starts), np.maximum.reduceat(x, starts)
    cx, ax, ay = 0.5 * (lo + hi), 0.5 * (hi - lo), np.maximum.reduceat(y, starts)
    c = np.repeat(np.arange(n.size), n)
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.sqrt(((x - cx[c]) / ax[c]) ** 2 + (y / ay[c]) ** 2)
    g = np.where((ax > 0) & (ay > 0), np.maximum.reduceat(v, starts) * _SAFETY, math.inf)
    return np.stack([cx, ax * g, ay * g, rims.area[which]], axis=1)


def interpolated_ellipse(table: np.ndarray, levels, rho: float, s: float) -> np.ndarray:
    """(cx, ax, ay) as the shader reads ``table`` (levels x radii x 5) at film radius ``rho`` (mm) and
    iris radius ``s`` (mm): linear in rho, linear in s between levels, the last level's axes scaled
    by s / s_last below it."""
    _table(table, levels)
    return _ellipse_at(table, _levels(levels), require_finite("film radius", rho), require_finite("iris radius", s))


def interpolated_area(table: np.ndarray, levels, rho: float, s: float) -> float:
    """The passing set's area (mm^2) as the shader reads ``table``: a cubic in rho through four nodes
    (:func:`radial_cubic`), between levels a cubic in s through the levels' areas and slopes (Hermite: the area of the iris's image grows as its
    square, and saturates where other surfaces cut it), scaled by (s / s_last)^2 below the last;
    -1 where the cell it reads in is not trusted (radial_pupil_table)."""
    _table(table, levels)
    return _area_at(table, _levels(levels), require_finite("film radius", rho), require_finite("iris radius", s))


def _radial(table, rho):
    n_rad = table.shape[1]
    ri = min(max(rho / (RADIAL_MAX_MM / (n_rad - 1)), 0.0), n_rad - 1.0)
    j0 = min(int(math.floor(ri)), n_rad - 2)
    return j0, ri - j0


def _ellipse_at(table, levels, rho, s):
    j0, rw = _radial(table, rho)
    l0, lw, shrink = _bracket(levels, s)
    at = (1 - rw) * table[l0:l0 + 2, j0, :3] + rw * table[l0:l0 + 2, j0 + 1, :3]
    return ((1 - lw) * at[0] + lw * at[1]) * np.array([1.0, shrink, shrink])


def _area_at(table, levels, rho, s):
    j0, rw = _radial(table, rho)
    l0, _, shrink = _bracket(levels, s)
    if table[l0 + (shrink < 1.0), j0, 3] < 0:  # the cell's trust (below the last level: the last row's)
        return -1.0
    a = cell_area(table[l0:l0 + 2, :, 3])
    at = radial_cubic(*(a[:, j] for j in _cubic_nodes(j0, table.shape[1])), j0 + 2 < table.shape[1], rw)
    dt = (1 - rw) * table[l0:l0 + 2, j0, 4] + rw * table[l0:l0 + 2, j0 + 1, 4]
    if shrink < 1.0:
        return float(at[1] * shrink * shrink)
    return float(hermite(levels[l0 + 1], at[1], dt[1], levels[l0], at[0], dt[0], s))


def _cubic_nodes(j0, n_rad):
    """The four radius columns the area's cubic in rho reads for the cell from node j0 to j0 + 1: the one
    before (at the axis node 1, the mirror image: the area is even in rho) and the one after (past the
    table's end node j0 + 1 again, the cubic then extrapolating linearly, radial_cubic)."""
    j0 = np.asarray(j0)
    return np.abs(j0 - 1), j0, j0 + 1, np.minimum(j0 + 2, n_rad - 1)


def radial_cubic(p0, p1, p2, p3, has_p3, t):
    """The area between film radius nodes with values p1 and p2, at fraction t of the step: the
    Catmull-Rom cubic through the nodes, slopes (p2 - p0) / 2 and (p3 - p1) / 2 per step (Catmull and Rom
    1974; p3 = 2 p2 - p1 where ``has_p3`` is false: the last cell). Exact for a quadratic in rho; a set
    that other surfaces cut shrinks as a concave function of rho, which a straight line between nodes
    underestimates by up to 1.4 %."""
    p3 = np.where(has_p3, p3, 2 * p2 - p1)
    return p1 + 0.5 * t * ((p2 - p0) + t * ((2 * p0 - 5 * p1 + 4 * p2 - p3) + t * (3 * (p1 - p2) + p3 - p0)))


def hermite(s0: float, a0: float, d0: float, s1: float, a1: float, d1: float, s: float) -> float:
    """The cubic through (s0, a0) and (s1, a1) with slopes d0 and d1 there, at s (a0 when s0 == s1)."""
    span = s1 - s0
    if not span > 0:
        return a0
    t = min(max((s - s0) / span, 0.0), 1.0)
    return ((2 * t**3 - 3 * t**2 + 1) * a0 + (t**3 - 2 * t**2 + t) * span * d0 + (-2 * t**3 + 3 * t**2) * a1
            + (t**3 - t**2) * span * d1)


def _fill(table: np.ndarray, empty: np.ndarray) -> None:
    """Empty entries take the next larger level's ellipse at their radius (the passing sets nest), and
    radii with nothing at any level the nearest lit radius's (in place)."""
    n_level, n_rad, _ = table.shape
    for j in range(n_rad):
        for k in range(1, n_level):
            if empty[k, j] and not empty[k - 1, j]:
                table[k, j] = table[k - 1, j]
                empty[k, j] = False
    lit = [j for j in range(n_rad) if not empty[0, j]]
    if not lit:
        return
    for j in range(n_rad):
        if empty[0, j]:
            near = min(lit, key=lambda i: abs(i - j))
            table[:, j] = table[:, near]


def _tables_backend(backend: str, n_tables: int, n_surfaces: int) -> str:
    """The tracing backend of a job of ``n_tables`` radial pupil tables of a lens of ``n_surfaces`` surfaces
    (about :data:`TABLE_RAYS` rays each): :func:`~physcam.trace.kernels.backend_for_job` for the whole job,
    and where that leaves "auto" (the job pays for loading numba), the JIT kernel at once, numba loaded now
    (:func:`~physcam.trace.kernels.resolve_backend`). Asked per table, "auto" gave a lens's first tables to the
    numpy kernel (each about 0.1 s of numba's work, under the load budget), which traced them 5-10 times
    slower than the JIT kernel traced the rest: about 1.5 s of CPU lost per process building a focus table
    (round 15). Both kernels give the same rays (:mod:`physcam.trace.kernels`): the tables do not change."""
    from ..trace.kernels import backend_for_job, resolve_backend

    chosen = backend_for_job(backend, n_tables * TABLE_RAYS * (n_surfaces + 1))
    return resolve_backend(chosen) if chosen == "auto" else chosen


def radial_pupil_table(q, film_z: float, levels, *, backend: str = "auto", checks: list | None = None) -> np.ndarray:
    """The table (len(levels) x :data:`N_RADIAL` x 5: cx, ax, ay in mm on the rear vertex plane, the
    passing set's area in mm^2 and its slope in mm^2 per mm of iris radius) of the focused lens ``q``
    (a Prescription) with its film at ``film_z``, at the iris radii ``levels`` (:func:`iris_levels`).
    Where nothing passes at any iris, the ellipse is a neighbour's and the area 0. An entry's area
    is -1 - area where the shader may not weigh rays by the area in its cell (:func:`_trusted_cells`,
    :func:`cell_area`). ``backend``: the
    tracing backend (:func:`~physcam.trace.trace.trace_through`; "auto" picks one for the whole table,
    :func:`~physcam.trace.kernels.backend_for_job`: both give the same rays). ``checks``: a list that
    receives the traced areas at :func:`_check_points` (0 where nothing passes), for tables filled between
    focus marks to be checked as this one is (:func:`_checked_trust`)."""
    return _table_and_sets(q, film_z, levels, backend, checks, finer=False)[0]


def refined_pupil_tables(focused, levels, *, checks: list, backend: str = "auto") -> tuple[np.ndarray, list]:
    """(levels, tables): :func:`radial_pupil_table` of each focused lens of ``focused`` ((prescription, film z)
    pairs: one lens's traced focus marks, which share their levels), at ``levels`` with a level added between
    two wherever the area's cubic misses a traced area at their middle (:func:`_refined_levels`); the passing
    sets are traced once, at the radii the added levels read too (:class:`_PassingSets`). ``checks`` receives
    each table's traced check areas at the returned levels."""
    # the drafts (no growth, no trust: what _refined_levels reads) first; only the tables kept are finished
    from ..errors import WrongTypeError
    from ..lens.prescription import require_prescription

    try:
        focused = [(q, film_z) for q, film_z in focused]
    except (TypeError, ValueError):
        raise WrongTypeError("focused must be (prescription, film z) pairs, one per traced focus mark, "
                             "e.g. [(state.prescription, state.film_z)]") from None
    if focused:  # the job's backend, chosen once for all its tables
        backend = _tables_backend(backend, len(focused), len(require_prescription(focused[0][0]).surfaces))
    found = [_table_and_sets(q, film_z, levels, backend, checks, finer=True, draft=True) for q, film_z in focused]
    refined = _refined_levels(levels, [draft[0] for draft, _ in found], checks)
    if len(refined) == len(_levels(levels)):
        return _levels(levels), [_finished(*draft, _levels(levels), sets.rims) for draft, sets in found]
    checks.clear()  # the tables again at the refined levels, from the sets already traced
    return refined, [_assembled(sets, refined, checks) for _, sets in found]


def _table_and_sets(q, film_z: float, levels, backend: str, checks, *, finer: bool, draft: bool = False) -> tuple:
    """(table, passing sets) of :func:`radial_pupil_table` (``finer``: the sets traced also at the radii of
    the levels :func:`_refined_levels` may add; ``draft``: the table's draft instead, :func:`_drafted`)."""
    from ..lens.prescription import require_prescription

    q = require_prescription(q)
    film_z = require_finite("film z", film_z)
    if q.is_anamorphic:
        raise InputError(f"{q.name!r} is anamorphic: the radial pupil table needs a lens with rotational symmetry")
    levels = _levels(levels)
    if not film_z > q.vertex_z[-1]:
        raise InputError(f"the film (z = {film_z:g} mm) must lie behind the lens's last vertex (z = {q.vertex_z[-1]:g} mm)")
    sets = _PassingSets(q, film_z, levels, _tables_backend(backend, 1, len(q.surfaces)), finer=finer, lines=True)
    return (_drafted(sets, levels, checks) if draft else _assembled(sets, levels, checks)), sets


def _assembled(sets: _PassingSets, levels, checks) -> np.ndarray:
    """The table of :func:`radial_pupil_table` at the iris radii ``levels`` from the passing sets ``sets``
    (which find the rims it reads, :meth:`_PassingSets.need`)."""
    levels = _levels(levels)
    return _finished(*_drafted(sets, levels, checks), levels, sets.rims)


def _drafted(sets: _PassingSets, levels, checks) -> tuple:
    """(table, the rim each check reads, its area): :func:`_assembled`'s table before its ellipses are grown
    and its cells' trust is signed (:func:`_finished`), its areas and slopes final (what
    :func:`_refined_levels` reads). ``checks`` receives the check areas."""
    levels = _levels(levels)
    sets.need(levels)
    _, checked = _check_axes(levels)
    near = levels * (1 - _DS)  # the area's slope at each level (one-sided: one radius more per level, not two)
    index, rims = sets.index, sets.rims
    at = {float(s): i for i, s in enumerate(sets.radii)}
    area = np.append(rims.area, 0.0)  # index -1: nothing passes
    node = index[:N_RADIAL, [at[float(s)] for s in levels]].T  # (levels, radii): the rims the entries fit
    lit = node >= 0
    table = np.zeros((len(levels), N_RADIAL, 5))
    if lit.any():
        table[lit, :4] = _fits(rims, node[lit])
        down = index[:N_RADIAL, [at[float(s)] for s in near]].T
        table[..., 4] = np.where(lit, (area[node] - area[down]) / (_DS * levels[:, None]), 0.0)
    empty = ~lit
    _fill(table, empty)
    table[..., 3:5] = np.where(lit[..., None], table[..., 3:5], 0.0)  # nothing passes (the ellipse is a neighbour's)
    read_rim = index[:, [at[float(s)] for s in checked]].ravel()
    want = area[read_rim]
    if checks is not None:
        checks.append(want)
    return table, read_rim, want


def _finished(table, read_rim, want, levels, rims) -> np.ndarray:
    """The table of :func:`_drafted` (in place) with its ellipses grown and its cells' trust signed."""
    # every film point (nodes and mids) at every iris radius checked: the shader's reading there must hold
    # the traced set (grown until it does) and, for its cell to be trusted, give its area
    read_rho, read_s = _check_points(levels)
    has = read_rim >= 0
    _grow(table, levels, read_rho[has], read_s[has], read_rim[has], rims)
    # the area weighs rays only in the cells (between two levels and two radii) where the shader's
    # interpolation of the area is the traced one's within AREA_TOLERANCE at every set checked on or in
    # the cell, whatever bounds the set (the iris alone, or other surfaces too: the rim's area is a dense
    # trace's within 0.4 % either way, module notes); an entry's sign says whether its cell is trusted (untrusted:
    # -1 - area, cell_area). A failed check withdraws only the cells it lies on or in.
    table[..., 3] = np.where(_checked_trust(table, levels, want), table[..., 3], -1.0 - table[..., 3])
    return table


def _check_axes(levels) -> tuple[np.ndarray, np.ndarray]:
    """(film radii, iris radii) where :func:`radial_pupil_table` checks the shader's reading: the nodes and the
    mids between them; the levels, the mids between them and half the last level (largest first)."""
    levels = np.asarray(levels, dtype=float)
    step = RADIAL_MAX_MM / (N_RADIAL - 1)
    rhos = np.concatenate([np.arange(N_RADIAL) * step, (np.arange(N_RADIAL - 1) + 0.5) * step])  # nodes, then mids
    checked = np.unique(np.concatenate([levels, np.sqrt(levels[:-1] * levels[1:]), [levels[-1] / 2]]))[::-1]
    return rhos, checked


def _refined_levels(levels, tables, checks) -> np.ndarray:
    """``levels`` with the geometric middle of every interval where the shader's cubic in iris radius
    misses a traced table's area at the interval's middle (:func:`_check_points`) by over
    :data:`AREA_TOLERANCE` at a film radius of the lens's image circle (:func:`_in_circle`) whose reads at
    both levels hold it: where another surface begins to cut the passing set between the two (the area bends
    there, a kink the cubic rounds off), halving the interval halves the miss (the double Gauss's table traced
    at 2.5 m: 0.64 % at film radius 10.4 mm between 6.79 and 6.05 mm, f/2.8's interval; at most 0.21 % between
    the middle and either level). ``tables`` (radial_pupil_table's at ``levels``) and ``checks`` (the areas its
    ``checks`` received, one per table): the traced focus marks of one lens, which share its levels."""
    levels = _levels(levels)
    rhos, checked = _check_axes(levels)
    read_rho, read_s = _check_points(levels)
    is_level = np.isin(checked, levels)
    misses = np.zeros(len(levels) - 1, dtype=bool)
    inside = _in_circle(rhos, [np.reshape(want, (len(rhos), len(checked)))[:, -1] > 0 for want in checks])
    for table, want in zip(tables, checks):
        table = np.array(table, dtype=float)
        table[..., 3] = cell_area(table[..., 3])
        want = np.asarray(want, dtype=float)
        got = _areas_at(table, levels, read_rho, read_s)
        lit = (want > 0).reshape(len(rhos), len(checked))
        bad = (np.abs(got - want) > AREA_TOLERANCE * np.maximum(want, 1e-12)).reshape(len(rhos), len(checked)) | ~lit
        for c in np.flatnonzero(~is_level[1:-1]) + 1:  # a middle between the levels checked[c - 1] and checked[c + 1]
            misses[np.searchsorted(-levels, -checked[c]) - 1] |= bool((bad[:, c] & lit[:, c] & ~bad[:, c - 1]
                                                                       & ~bad[:, c + 1] & inside).any())
    mid = np.sqrt(levels[:-1] * levels[1:])[misses]
    return np.sort(np.concatenate([levels, mid]))[::-1]


def _in_circle(rhos, lit_smallest) -> np.ndarray:
    """Per film radius ``rhos`` (:func:`_check_axes`), whether it lies on a cell (between two film radius nodes)
    that holds a part of the lens's image circle at every traced focus: the film radii below the first where
    nothing passes at the smallest iris radius checked at some focus (``lit_smallest``: per focus, whether
    anything passes at half the last level, 1/32 of the file's stop). There the chief ray (through the stop's
    centre) is cut by a clear aperture, to within that iris: physcam's image circle (the lens cards'
    ``field_limit_deg``). It grows as the lens focuses closer; a sensor the lens covers at every focus lies
    inside the smallest."""
    rhos = np.asarray(rhos, dtype=float)
    dark = rhos[~np.all(np.asarray(lit_smallest, dtype=bool).reshape(-1, rhos.size), axis=0)]
    if not dark.size:
        return np.ones(rhos.size, dtype=bool)
    step = RADIAL_MAX_MM / (N_RADIAL - 1)
    return rhos <= math.ceil(dark.min() / step - 1e-9) * step + 1e-9  # the node that ends the edge's cell


def _check_points(levels) -> tuple[np.ndarray, np.ndarray]:
    """(film radius, iris radius) of every check of :func:`radial_pupil_table` at the iris radii ``levels``, in
    the order of its ``checks`` areas: every film radius of :func:`_check_axes` with every iris radius."""
    rhos, checked = _check_axes(levels)
    return np.repeat(rhos, len(checked)), np.tile(checked, len(rhos))


def _checked_trust(table, levels, want, *, doubtful=None) -> np.ndarray:
    """Per entry of the radial ``table`` (its area column's sign ignored), whether the shader may weigh rays
    by the area in its cell: the shader's area at every :func:`_check_points` is ``want`` (the passing sets'
    areas there, 0 where nothing passes) within :data:`AREA_TOLERANCE` on and in the cell, no check point
    of ``doubtful`` (a mask over them: ``want`` itself not known to that tolerance) lies on or in it, and
    something passes at its corners (:func:`_trusted_cells`)."""
    table = np.array(table, dtype=float)
    table[..., 3] = cell_area(table[..., 3])
    read_rho, read_s = _check_points(levels)
    want = np.asarray(want, dtype=float)
    got = _areas_at(table, levels, read_rho, read_s)
    bad = np.abs(got - want) > AREA_TOLERANCE * np.maximum(want, 1e-12)
    if doubtful is not None:
        bad |= np.asarray(doubtful, dtype=bool)
    step = RADIAL_MAX_MM / (N_RADIAL - 1)
    return _trusted_cells(levels, np.stack([read_rho[bad], read_s[bad]], axis=1), table[..., 3] > 0, step)


def _trusted_cells(levels, failed, lit, step: float) -> np.ndarray:
    """Per table entry (k, j), whether the shader may weigh rays by the area in its cell: iris radii
    from levels[k + 1] to levels[k] (k the last level: below it) and film radii from node j to j + 1.
    A cell is trusted when something passes at each of its corner entries (``lit``) and no
    (film radius, iris radius) of ``failed`` lies on or in it. The last radius column has no cell."""
    n_level, n_rad = lit.shape
    ok = lit.copy()
    both = np.concatenate([lit[:-1] & lit[1:], lit[-1:]])  # each cell's two levels (the last: itself)
    ok[:, :-1] = both[:, :-1] & both[:, 1:]
    failed = np.asarray(failed, dtype=float).reshape(-1, 2)
    rho, s = failed[:, :1], failed[:, 1:]
    lv = np.asarray(levels, dtype=float)
    on_k = np.concatenate([(lv[1:] <= s) & (s <= lv[:-1]), s <= lv[-1]], axis=1)  # (failed, levels)
    j = np.arange(n_rad)
    on_j = (j[:-1] * step - 1e-9 <= rho) & (rho <= j[1:] * step + 1e-9)  # (failed, cells across)
    # every (level, cell) pair of each failed point (one or two of each), paired point by point: the
    # cells the integer product on_k.T @ on_j counts, without its dense loop over every point
    fk, kk = np.nonzero(on_k)
    fj, jj = np.nonzero(on_j)
    cj = np.bincount(fj, minlength=len(failed))
    rep = cj[fk]
    offs = np.arange(int(rep.sum())) - np.repeat(np.cumsum(rep) - rep, rep)
    hit = np.zeros((n_level, n_rad - 1), dtype=bool)
    hit[np.repeat(kk, rep), jj[np.repeat((np.cumsum(cj) - cj)[fk], rep) + offs]] = True
    ok[:, :-1] &= ~hit
    return ok


def cell_area(v):
    """The passing set's area (mm^2) from a table entry's area column ``v`` (an untrusted cell's entry
    holds -1 - area, :func:`radial_pupil_table`)."""
    return np.where(np.asarray(v) < 0, -1.0 - np.asarray(v), v)


def _reads(table, levels, rhos, ss):
    """Per (film radius, iris radius) pair, arrays of what the shader reads: j0, rw (:func:`_radial`)
    and l0, lw, shrink (:func:`_bracket`)."""
    # _radial and _bracket of each, in whole arrays: the same comparisons and IEEE operations
    rho, s = np.asarray(rhos, dtype=float).ravel(), np.asarray(ss, dtype=float).ravel()
    n_rad = table.shape[1]
    ri = np.minimum(np.maximum(rho / (RADIAL_MAX_MM / (n_rad - 1)), 0.0), n_rad - 1.0)
    j0 = np.minimum(np.floor(ri).astype(np.int64), n_rad - 2)
    lv = np.asarray(levels, dtype=float)
    n = len(lv)
    below = s <= lv[-1]
    l0 = np.minimum(np.maximum(np.searchsorted(-lv, -s, side="right") - 1, 0), n - 2)
    gap = lv[l0] - lv[l0 + 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        lw = np.where(gap > 0, np.minimum(np.maximum((lv[l0] - s) / gap, 0.0), 1.0), 1.0)
    return (j0, ri - j0, np.where(below, n - 2, l0), np.where(below, 1.0, lw),
            np.where(below, s / lv[-1], 1.0))


def _ellipses_at(table, levels, rhos, ss) -> np.ndarray:
    """:func:`_ellipse_at` at every (rho, s) pair, (n, 3), the same arithmetic in whole arrays."""
    return _ellipses_read(table, *_reads(table, levels, rhos, ss))


def _ellipses_read(table, j0, rw, l0, lw, shrink) -> np.ndarray:
    rw, lw = rw[:, None], lw[:, None]
    at0 = (1 - rw) * table[l0, j0, :3] + rw * table[l0, j0 + 1, :3]
    at1 = (1 - rw) * table[l0 + 1, j0, :3] + rw * table[l0 + 1, j0 + 1, :3]
    return ((1 - lw) * at0 + lw * at1) * np.stack([np.ones_like(shrink), shrink, shrink], axis=1)


def _areas_at(table, levels, rhos, ss) -> np.ndarray:
    """:func:`_area_at` at every (rho, s) pair, the same arithmetic in whole arrays."""
    j0, rw, l0, _, shrink = _reads(table, levels, rhos, ss)
    bad = table[l0 + (shrink < 1.0), j0, 3] < 0
    a, d = cell_area(table[..., 3]), table[..., 4]
    nodes = _cubic_nodes(j0, table.shape[1])
    last = j0 + 2 < table.shape[1]
    a1, a0 = (radial_cubic(*(a[row, j] for j in nodes), last, rw) for row in (l0, l0 + 1))
    d1, d0 = ((1 - rw) * d[row, j0] + rw * d[row, j0 + 1] for row in (l0, l0 + 1))
    s0, s1, s = levels[l0 + 1], levels[l0], np.asarray(ss, dtype=float)
    span = s1 - s0
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.minimum(np.maximum((s - s0) / span, 0.0), 1.0)
    cubic = ((2 * t**3 - 3 * t**2 + 1) * a0 + (t**3 - 2 * t**2 + t) * span * d0 + (-2 * t**3 + 3 * t**2) * a1
             + (t**3 - t**2) * span * d1)
    cubic = np.where(span > 0, cubic, a0)  # hermite
    return np.where(bad, -1.0, np.where(shrink < 1.0, a0 * shrink * shrink, cubic))


def _grow(table, levels, rhos, ss, which, rims) -> None:
    """Grow the entries (in place) until the shader's ellipse at each film radius ``rhos[i]`` and iris
    radius ``ss[i]`` holds the rim ``which[i]`` of ``rims``: each entry's axes by the largest factor
    that any reading it weighs in (with weight over 1e-9) needs, until every one holds. An entry only
    grows, and a grown entry holds what it held (the centres do not move)."""
    if len(which) == 0:
        return
    reads = _reads(table, levels, rhos, ss)
    j0, rw, l0, lw, _ = reads
    # the four entries each reading mixes, and which of them weigh in it
    rows, cols = np.stack([l0, l0, l0 + 1, l0 + 1]), np.stack([j0, j0 + 1, j0, j0 + 1])
    weighs = np.stack([(lw < 1) & (rw < 1 - 1e-9), (lw < 1) & (rw > 1e-9), (lw > 0) & (rw < 1 - 1e-9), (lw > 0) & (rw > 1e-9)])
    which = np.asarray(which)
    for _ in range(8):
        x, y, n = rims.points(which)
        starts, c = np.cumsum(n) - n, np.repeat(np.arange(n.size), n)
        e = _ellipses_read(table, *reads)
        with np.errstate(divide="ignore", invalid="ignore"):
            v = np.sqrt(((x - e[c, 0]) / e[c, 1]) ** 2 + (y / e[c, 2]) ** 2)
        need = np.maximum.reduceat(v, starts) * _SAFETY
        need = np.where((e[:, 1] > 0) & (e[:, 2] > 0), need, math.inf)
        short = np.flatnonzero(~(need <= 1.0))
        if not short.size:
            return
        f = np.ones(table.shape[:2])
        w = weighs[:, short]
        np.maximum.at(f, (rows[:, short][w], cols[:, short][w]), np.broadcast_to(need[short] * (1 + 1e-6), w.shape)[w])
        table[..., 1:3] *= f[..., None]
        # the readings that held hold still (their entries only grew): only the short ones are read again
        which, reads, rows, cols, weighs = which[short], tuple(r[short] for r in reads), rows[:, short], cols[:, short], w
