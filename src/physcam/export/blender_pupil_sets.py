"""The passing sets behind the Blender extension's pupil tables (:mod:`physcam.export.blender_pupil`): from a
film point (rho, 0), which aims on the rear vertex plane pass the lens, at every iris radius at once (one trace
with the iris taken out records each ray's stop radius; a ray passes an iris of radius s when it passes every
other surface and crosses the stop within s), their rims, areas and the ellipses that hold them.

A set's rim is found between the samples of an aim grid: where the iris stops a ray, the stop radius
is interpolated to s along the grid line (it is smooth); where another surface clips, the edge is
found by halving the step (the rim that holds the set is put at the halving's far end, conservative;
its area takes the middle), unless the iris stops the ray first on the way (the stop radius at the
halving's last passing point already exceeds s: then the rim is interpolated there, as above). A
grid zooms in once its set spans under :data:`_ZOOM` of it across or along, so a set spans at least
about 20 of the 36 samples each way: a rim's area is a dense trace's within 0.4 % (cut by other
surfaces or not; the double Gauss and the Canon RF 85, f/2 to f/16, film radius to 22 mm).
Where the iris alone bounds a set the grids are not needed: its rim is found along 25 lines from the
film point's chief aim (the aim whose ray crosses the stop's centre: every set holds it, and a convex set
is star-shaped from it; found from meridional fans, also where the film lies so close behind the rear vertex
that a point's passing spot there is under one step of the fan across the rear element, :func:`_chief_aims`),
the stop radius sampled geometrically along each line and the rim interpolated
where it reaches s (:class:`_LineSets`; about 620 rays a film point against about 3,400 in grids). The lines
serve the iris radii under every cut line's clip edge by 5 %, so no other surface reaches the set, and only
where the interpolation is sure of the rim (:data:`_LINE_DOUBT`); the wider radii (where other surfaces cut
the set: wide open, off axis) and the film points whose chief ray is cut (outside the image circle) keep the
grids. The lines' areas are a dense trace's within 0.15 % (the grids' up to 0.27 % short; the double Gauss,
a fisheye, a zoom, the Canon RF 85, the Angenieux f/1 and the ARRI Signature 58 mm, whose film lies 1.0 mm
behind its rear vertex: tests/export/test_blender_pupil_lines.py).
"""

from __future__ import annotations

import math

import numpy as np

_GRID = 36  # aim samples across a grid (half as many across its y >= 0 half)


class _StopCrossing:
    """Stands in for the iris shape in physcam's tracer (which calls ``density_at`` with every ray's
    place on the stop's unit disk, then traces on): keeps each ray's radius there and passes them all (a
    density of 1.0: the tracer leaves the rays as they are)."""

    def __init__(self):
        self.radius = self.x = self.y = None

    def density_at(self, x, y):
        self.x, self.y, self.radius = x, y, np.hypot(x, y)
        return 1.0


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
    index of its rim there, -1 where nothing passes (or the rim is not wanted). Where ``backend`` has a compiled
    rim pass (:func:`~physcam.trace.kernels.rim_pass`: the C kernel's, or numba's) it finds the same rims."""
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
_SEEDED_STEPS = 3  # Newton's steps more for a chief aim seeded by one passing fan aim (:func:`_chief_aims`)
_SEEDED_MISS = 1e-9  # ... and how near the stop's centre its ray must then cross, as a share of the fan's span


def _fan(q, film_z: float, fxs, x0, x1, big: float, backend: str) -> tuple[np.ndarray, np.ndarray]:
    """Per film point (fx, 0), :data:`_FAN` meridional aims from x0 to x1: (the chief aim where a passing pair of
    them brackets it, linear between the two, else nan; the passing aim whose ray crosses the stop nearest its
    centre, nan where none passes)."""
    px = x0[:, None] + (np.arange(_FAN) + 0.5)[None, :] / _FAN * (x1 - x0)[:, None]
    ok, probe = _aims_probe(q, film_z, np.repeat(fxs, _FAN), px.ravel(), np.zeros(px.size), big, backend)
    ok, xs = ok.reshape(px.shape), (probe.x * big).reshape(px.shape)
    pair = ok[:, :-1] & ok[:, 1:] & ((xs[:, :-1] <= 0) != (xs[:, 1:] <= 0))
    i, j = np.arange(fxs.size), np.argmax(pair, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(pair.any(axis=1), px[i, j] + (px[i, j + 1] - px[i, j]) * xs[i, j] / (xs[i, j] - xs[i, j + 1]), np.nan)
    near = np.where(ok, np.abs(xs), np.inf)
    k = np.argmin(near, axis=1)
    return c, np.where(np.isfinite(near[i, k]), px[i, k], np.nan)


def _chief_aims(q, film_z: float, fxs, boxes, big: float, backend: str) -> tuple[np.ndarray, np.ndarray]:
    """Per film point (fx, 0): (the aim x on the rear vertex plane of its ray through the stop's centre, the
    rate d x_stop / d aim x there), nan where none is found. A passing pair of :data:`_FAN` meridional aims
    across the point's box (:func:`_rear_boxes`) brackets it and three Newton steps find it. Where none does
    (the film close behind the rear vertex: its passing spot there under one step of the fan; or a point on the
    image circle's vignetted edge, its chief aim between a cut aim and a passing one), a fan across the window
    about the point straight ahead, half as wide as the film's distance from the rear vertex (the first
    window :func:`_first_grids` looks in), brackets it or, failing that, the passing aim of either fan whose
    ray crosses the stop nearest its centre seeds Newton's steps; there :data:`_SEEDED_STEPS` more, and the
    aim is kept only where its ray passes and crosses the stop within :data:`_SEEDED_MISS` of the fan's span
    of its centre (else nan: the chief ray is cut, outside the image circle)."""
    fxs = np.asarray(fxs, dtype=float)
    b = np.asarray(boxes, dtype=float).reshape(-1, 3)
    c, seed = _fan(q, film_z, fxs, b[:, 0], b[:, 1], big, backend)
    seeded = np.isnan(c)
    w = np.flatnonzero(seeded)
    if w.size:
        half = 0.5 * (film_z - q.vertex_z[-1])
        c[w], seed_w = _fan(q, film_z, fxs[w], np.maximum(fxs[w] - half, b[w, 0]), np.minimum(fxs[w] + half, b[w, 1]),
                            big, backend)
        c[w] = np.where(np.isnan(c[w]), np.where(np.isnan(seed_w), seed[w], seed_w), c[w])
    rate = np.full(fxs.size, np.nan)
    h = 1e-4 * (b[:, 1] - b[:, 0])
    for step in range(3 + _SEEDED_STEPS):  # Newton's steps, the rate by a forward difference (more from a seed)
        g = np.flatnonzero(np.isfinite(c) & ((step < 3) | seeded))
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
    g = np.flatnonzero(seeded & np.isfinite(c))
    if g.size:  # kept only where its ray passes and crosses the stop at its centre
        ok, probe = _aims_probe(q, film_z, fxs[g], c[g], np.zeros(g.size), big, backend)
        cut = g[~(ok & (np.abs(probe.x * big) <= _SEEDED_MISS * (b[g, 1] - b[g, 0])))]
        c[cut], rate[cut] = np.nan, np.nan
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
        doubt = doubt.any(axis=1)  # (points, radii)
        self.first = np.maximum(self.first, np.where(doubt.any(axis=1), radii.size - np.argmax(doubt[:, ::-1], axis=1), 0))

    def _rim_t(self, s) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(held t, mean t, doubt): per film point, line and iris radius of ``s``, where the rim crosses the line
        (held: a cut line's far end; mean: its middle) and whether the interpolation is doubtful there (the two
        quadratics about it differ by over :data:`_LINE_DOUBT` of t, or by an unknown share)."""
        s = np.asarray(s, dtype=float)
        n_points, n_lines, n_samples = self.t.shape
        lines = n_points * n_lines
        if not lines:  # no film point on lines
            return np.zeros((n_points, n_lines, s.size)), np.zeros((n_points, n_lines, s.size)), np.zeros(
                (n_points, n_lines, s.size), dtype=bool)
        with np.errstate(divide="ignore", invalid="ignore"):
            lt, lr = np.log(self.t).reshape(lines, -1), np.log(self.r).reshape(lines, -1)
            # Newton's divided differences of log t in log r of every three samples in a row (empty slots: nan)
            d01 = np.diff(lt, axis=1) / np.diff(lr, axis=1)
            d012 = np.diff(d01, axis=1) / (lr[:, 2:] - lr[:, :-2])
        # the samples under s per line (r rises along it; an empty slot's is inf): j = #{k: log r_k < log s}, compared
        # as band + log r against band + log s (each line in its own band: log r spans far less than _BAND), found
        # from the other side in one search, every line's log s in its band ascending, and a count per line
        line = np.arange(lines)[:, None]
        band = line * _BAND
        ls = np.log(s)[None, :]
        o = np.argsort(ls[0], kind="stable")
        w = (band + ls[:, o]).ravel()
        pos = np.searchsorted(w, (band + np.minimum(lr, _BAND / 4)).ravel(), side="right").reshape(lines, -1)
        pos -= line * s.size  # per sample, how many of its line's log s lie at or under its log r
        count = np.bincount((line * (s.size + 1) + pos).ravel(), minlength=lines * (s.size + 1)).reshape(lines, -1)
        j = np.empty((lines, s.size), dtype=np.int32)
        j[:, o] = np.cumsum(count, axis=1, dtype=np.int32)[:, :s.size]
        n = self.n.reshape(lines, 1).astype(np.int32)
        beyond = j >= n  # past the last passing sample: the clip edge (every line is cut or reaches s)
        under = j == 0  # under the first sample
        # per line and first sample a of three in a row: log t_a, log r_a, the divided differences and log r_a+1
        m = n_samples - 2
        coef = np.stack([lt[:, :m], lr[:, :m], d01[:, :m], lr[:, 1:m + 1], d012]).reshape(5, -1)
        base, top = (line * m).astype(np.int32), n - 3

        def quad(shift):  # Lagrange's quadratic of log t in log r through the samples a, a + 1, a + 2 of each line
            # (a = j - shift held to 0..n - 3), in place in the gathered rows: the same IEEE operations as
            # lt_a + (ls - lr_a) * (d01_a + (ls - lr_b) * d012_a)
            a = j - np.int32(shift)
            np.maximum(a, 0, out=a)
            np.minimum(a, top, out=a)
            a += base
            lt_a, lr_a, d01_a, lr_b, d012_a = np.take(coef, a.ravel(), axis=1).reshape(5, lines, -1)
            u = np.subtract(ls, lr_b, out=lr_b)
            u *= d012_a
            u += d01_a
            u *= np.subtract(ls, lr_a, out=lr_a)
            u += lt_a
            return u

        with np.errstate(invalid="ignore", over="ignore"):
            # the two samples about s and the next one out (in at the line's last), and the one in instead: where
            # the two quadratics differ the curve bends too fast for the samples (r flattens toward a clip)
            q1, q2 = quad(1), quad(2)
            d = np.subtract(q2, q1, out=q2)
            np.abs(np.expm1(d, out=d), out=d)
            doubt = ~(d <= _LINE_DOUBT) & ~(under | beyond)  # nan and inf doubted too
            t_iris = np.exp(np.where(under, lt[:, :1] + ls - lr[:, :1], q1))  # under the first: r ~ t
        shape = (n_points, n_lines, s.size)
        t_iris, doubt, beyond = t_iris.reshape(shape), doubt.reshape(shape), beyond.reshape(shape)
        held = np.where(beyond, self.hi[..., None], t_iris)
        mean = np.where(beyond, 0.5 * (self.lo[..., None] + self.hi[..., None]), t_iris)
        return held, mean, doubt

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
