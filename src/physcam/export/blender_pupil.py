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
is interpolated to s along the grid line (it is smooth); where another surface clips, the rim is
put at the next sample out (conservative). The grids zoom in as the passing set shrinks, so every
set spans 24-48 samples across.

The shader interpolates the ellipse linearly in rho between nodes, in s between levels (below the
last level it scales the last level's axes by s / s_last: the pupil's linear regime) and between
the two focus states it blends (grown by fw (1 - fw) times the centres' shift there). The
interpolation in rho and s is checked here: the passing sets at every mid radius and mid level (and
at half the last level) are traced too, and the entries are grown until the interpolated ellipse
holds them. Stopped down the passing set is the iris's image, nearly an ellipse itself, so nearly
every sample passes (0.96-0.99 on the double Gauss from f/5.6 on); wide open and at the frame's
edge it is the iris's image cut by the other elements (cat's eye), and 0.75-0.9 pass.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError, require_finite, require_type

__all__ = ["RADIAL_MAX_MM", "N_RADIAL", "LEVEL_RATIO", "N_LEVEL", "radial_pupil_table", "iris_levels",
           "level_bracket", "interpolated_ellipse", "interpolated_area", "hermite"]

#: Film radius the table reaches (mm): the half diagonal of physcam's largest sensor (IMAX 15/70).
RADIAL_MAX_MM = 44.0
#: Film radii tabulated, uniform from the axis to :data:`RADIAL_MAX_MM`.
N_RADIAL = 25
#: Iris radius ratio between consecutive levels below the file's stop (a third of a stop in f-number).
LEVEL_RATIO = 2.0 ** (1.0 / 3.0)
#: Iris levels tabulated: the widest iris, the file's stop, and on down to 1/16 of it (four stops).
N_LEVEL = 14
_GRID = 48  # aim samples across a grid (half as many across its y >= 0 half)
#: The largest error of the interpolated passing area that may weigh a ray (see radial_pupil_table).
AREA_TOLERANCE = 0.004
_DS = 0.02  # the area's slope at a level: from the areas at 2 % smaller and larger irises


def iris_levels(semi_max: float, semi_file: float) -> np.ndarray:
    """The tabulated iris radii (mm), largest first: the widest iris (``semi_max``: physcam's camera
    state opens the stop a little beyond the file's, to the lens's marked f-number), the file's stop
    (``semi_file``: on axis the other elements pass no more) and :data:`LEVEL_RATIO` steps below it."""
    if not 0 < semi_file <= semi_max:
        raise InputError(f"iris levels need 0 < file stop <= widest iris, got {semi_file!r} and {semi_max!r}")
    return np.concatenate([[float(semi_max)], float(semi_file) * LEVEL_RATIO ** -np.arange(N_LEVEL - 1, dtype=float)])


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
        self.radius = None

    def density_at(self, x, y):
        self.radius = np.hypot(x, y)
        return np.ones_like(self.radius)


def _grid(box):
    """A ``_GRID`` x ``_GRID/2`` grid of aim points over ``box`` (x0, x1, y1: the y >= 0 half): x, y, steps."""
    x0, x1, y1 = box
    nx, ny = _GRID, _GRID // 2
    dx, dy = (x1 - x0) / nx, y1 / ny
    gx, gy = np.meshgrid(x0 + (np.arange(nx) + 0.5) * dx, (np.arange(ny) + 0.5) * dy)
    return gx.ravel(), gy.ravel(), dx, dy


def _aims(q, film_z: float, fx, px, py, big: float):
    """(passes every surface but the stop, radius where it crosses the stop plane) of rays from film
    points (fx, 0) to aim points (px, py) on the rear vertex plane, in one trace."""
    from ..trace.rays import OK, RayBatch
    from ..trace.trace import trace_through

    fx = np.asarray(fx, dtype=float)
    start = np.stack([fx, np.zeros_like(fx), np.full(fx.size, film_z)], axis=1)
    rays = RayBatch.from_arrays(start, np.stack([px - fx, py, np.full(px.size, q.vertex_z[-1] - film_z)], axis=1),
                                q.wavelength_nm)
    probe = _StopCrossing()
    trace_through(q, rays, reverse=True, clip=True, stop_semi_diameter=big, aperture=probe, in_place=True)
    return rays.flag == OK, probe.radius * big


#: Neighbours a rim is looked for toward: +x, -x and +y (the y = 0 side mirrors itself), as the
#: sample's and the neighbour's cells of a (ny, nx) grid, and the step's direction.
_TOWARD = (((slice(None), slice(0, -1)), (slice(None), slice(1, None)), (1, 0)),
           ((slice(None), slice(1, None)), (slice(None), slice(0, -1)), (-1, 0)),
           ((slice(0, -1), slice(None)), (slice(1, None), slice(None)), (0, 1)))
_HALVINGS = 4  # where another surface clips between two samples, it is found to 1/16 of a step


def _trace(q, film_z: float, fxs, boxes, big: float) -> list:
    """Rays from film points (fx, 0) to the aim grid over each one's box on the rear vertex plane, in
    one trace: per film point (x, y, passes every surface but the stop, radius where it crosses the
    stop plane, grid steps, clip edges). Between a passing sample and a clipped neighbour the edge of
    what the other surfaces pass is found by halving (:data:`_HALVINGS`): per direction of
    :data:`_TOWARD`, (lo, hi) fractions of the step that pass and that do not."""
    grids = [_grid(b) for b in boxes]
    gx = np.concatenate([g[0] for g in grids])
    gy = np.concatenate([g[1] for g in grids])
    fx = np.repeat(np.asarray(fxs, dtype=float), [g[0].size for g in grids])
    ok, rad = _aims(q, film_z, fx, gx, gy, big)
    ny, nx = _GRID // 2, _GRID
    out, i = [], 0
    for f, g in zip(fxs, grids):
        n = g[0].size
        out.append([g[0], g[1], ok[i:i + n], rad[i:i + n], g[2], g[3], f])
        i += n
    # the clip edges: every (passing sample, clipped neighbour) pair of every grid, halved together
    pairs = []  # (grid index, direction index, j, i, x, y, step x, step y, film x)
    for gi, (gx_, gy_, ok_, rad_, dx, dy, f) in enumerate(out):
        okg = ok_.reshape(ny, nx)
        for di, (ca, cb, (sx, sy)) in enumerate(_TOWARD):
            jj, ii = np.nonzero(okg[ca] & ~okg[cb])
            ja, ia = jj + (ca[0].start or 0), ii + (ca[1].start or 0)
            pairs.append((gi, di, jj, ii, gx_[0] + ia * dx, gy_[0] + ja * dy, np.full(jj.size, sx * dx),
                          np.full(jj.size, sy * dy), np.full(jj.size, f)))
    x, y, sx, sy, ff = [np.concatenate([p[k] for p in pairs]) for k in (4, 5, 6, 7, 8)]
    lo, hi = np.zeros(x.size), np.ones(x.size)
    for _ in range(_HALVINGS):
        mid = 0.5 * (lo + hi)
        passes = _aims(q, film_z, ff, x + mid * sx, y + mid * sy, big)[0] if x.size else np.zeros(0, bool)
        lo, hi = np.where(passes, mid, lo), np.where(passes, hi, mid)
    k = 0
    for gi, g in enumerate(out):
        g.append([(np.zeros((ny, nx)), np.ones((ny, nx))) for _ in _TOWARD])
    for gi, di, jj, ii, *_ in pairs:
        n = jj.size
        g_lo, g_hi = out[gi][7][di]
        g_lo[jj, ii], g_hi[jj, ii] = lo[k:k + n], hi[k:k + n]
        k += n
    return [tuple(g[:6]) + (g[7],) for g in out]


def _rims(g, radii) -> list:
    """Per iris radius s in ``radii``, the rim of the passing set on grid ``g`` as points (x, y), or
    None when nothing passes. Between a passing sample and a neighbour the iris stops, the rim is
    where the stop radius crosses s (linear between the two: the stop radius is smooth); toward a
    neighbour another surface clips, or past the grid's edge, it is put at the neighbour
    (conservative). The set is convex (the iris's image, cut by other round apertures), so its rim
    bounds it."""
    gx, gy, ok, rad, dx, dy, edges = g
    ny, nx = _GRID // 2, _GRID
    ok, rad = ok.reshape(ny, nx), rad.reshape(ny, nx)
    s = np.asarray(radii, dtype=float)[:, None, None]
    inside = ok & (rad <= s)  # (radii, ny, nx)
    parts = []  # (radius index, x, y) arrays
    # toward +x, -x and +y: the sample's (a) and its neighbour's (b) cells
    for ((ja, ia_), (jb, ib), (sx, sy)), (e_lo, e_hi) in zip(_TOWARD, edges):
        ex, ey = sx * dx, sy * dy
        ra, rb = rad[ja, ia_], rad[jb, ib]
        rim = inside[:, ja, ia_] & ~inside[:, jb, ib]
        k, jj, ii = np.nonzero(rim)
        nb_ok = ok[jb, ib][jj, ii]
        with np.errstate(divide="ignore", invalid="ignore"):
            f_iris = np.clip((s[k, 0, 0] - ra[jj, ii]) / (rb[jj, ii] - ra[jj, ii]), 0.0, 1.0)
        # where another surface clips, the rim is at the halved edge (held: its far end; area: its middle)
        f = np.where(nb_ok, f_iris, e_hi[jj, ii])
        fa = np.where(nb_ok, f_iris, 0.5 * (e_lo[jj, ii] + e_hi[jj, ii]))
        jj, ii = jj + (ja.start or 0), ii + (ia_.start or 0)
        parts.append((k, gx[0] + ii * dx + ex * f, gy[0] + jj * dy + ey * f,
                      gx[0] + ii * dx + ex * fa, gy[0] + jj * dy + ey * fa, ~nb_ok))
    for cells, ox, oy in (((slice(None), slice(0, 1)), -dx, 0.0), ((slice(None), slice(nx - 1, None)), dx, 0.0),
                          ((slice(ny - 1, None), slice(None)), 0.0, dy)):  # past the grid's edge: a step out
        k, jj, ii = np.nonzero(inside[:, cells[0], cells[1]])
        jj, ii = jj + (cells[0].start or 0), ii + (cells[1].start or 0)
        parts.append((k, gx[0] + ii * dx + ox, gy[0] + jj * dy + oy, gx[0] + ii * dx + ox / 2, gy[0] + jj * dy + oy / 2,
                      np.ones(k.size, dtype=bool)))
    k = np.concatenate([p[0] for p in parts])
    cols = [np.concatenate([p[c] for p in parts]) for c in range(1, 6)]
    order = np.argsort(k, kind="stable")
    k, cols = k[order], [c[order] for c in cols]
    cuts = np.searchsorted(k, np.arange(len(radii) + 1))
    return [Rim(*(c[cuts[i]:cuts[i + 1]] for c in cols[:4]), bool(cols[4][cuts[i]:cuts[i + 1]].any()))
            if cuts[i + 1] > cuts[i] else None for i in range(len(radii))]


class Rim:
    """A passing set's rim: points (x, y >= 0) that hold it (where another surface clips, a step out),
    points (xa, ya) at the best estimate of its edge (half a step out there), for its area, and
    whether a surface other than the iris (or the grid's edge) bounds it anywhere (``clipped``)."""

    def __init__(self, x, y, xa, ya, clipped: bool):
        self.x, self.y, self.xa, self.ya, self.clipped = x, y, xa, ya, clipped
        self._area = None

    def area(self) -> float:
        """The set's area (mm^2, both halves): the polygon through its edge points, taken in angle order
        about their middle (the set is convex)."""
        if self._area is None:
            self._area = self._polygon_area()
        return self._area

    def _polygon_area(self) -> float:
        x = np.concatenate([self.xa, self.xa])
        y = np.concatenate([self.ya, -self.ya])
        o = np.argsort(np.arctan2(y, x - 0.5 * (x.min() + x.max())))
        x, y = x[o], y[o]
        return float(0.5 * abs(x[:-1] @ y[1:] - y[:-1] @ x[1:] + x[-1] * y[0] - y[-1] * x[0]))


def _first_grids(q, film_z: float, fxs, s_max: float, r_rear: float, big: float) -> tuple[list, list]:
    """Per film point (fx, 0): the box (x0, x1, y1) of its first grid and the grid (:func:`_trace`).
    The rear element's square, unless fewer than :data:`~physcam.trace.pupil_bounds.MIN_HITS` of its
    aims pass at iris radius ``s_max`` (a cover glass close to the film: the spot is under one grid
    step); then a window about the point straight ahead, half as wide as the film's distance from
    the rear vertex, doubled while the passing aims touch its edge or none pass."""
    from ..trace.pupil_bounds import MIN_HITS

    full = (-r_rear, r_rear, r_rear)
    boxes = [full] * len(fxs)
    grids = _trace(q, film_z, fxs, boxes, big)
    pending = [p for p, g in enumerate(grids) if (g[2] & (g[3] <= s_max)).sum() < MIN_HITS]
    h = 0.5 * (film_z - q.vertex_z[-1])
    while pending and h < 2 * r_rear:
        wins = {p: (max(fxs[p] - h, -r_rear), min(fxs[p] + h, r_rear), min(h, r_rear)) for p in pending}
        wins = {p: w for p, w in wins.items() if w[1] > w[0]}
        done = set()
        for p, g in zip(wins, _trace(q, film_z, [fxs[p] for p in wins], list(wins.values()), big) if wins else []):
            w, sel = wins[p], g[2] & (g[3] <= s_max)
            if sel.any():
                x, y = g[0][sel], g[1][sel]
                edge = ((w[0] > -r_rear and x.min() < w[0] + g[4]) or (w[1] < r_rear and x.max() > w[1] - g[4])
                        or (w[2] < r_rear and y.max() > w[2] - g[5]))
                if not edge:
                    boxes[p], grids[p] = w, g
                    done.add(p)
        pending = [p for p in pending if p not in done]
        h *= 2
    return boxes, grids


def _passing_sets(q, film_z: float, fxs, radii, r_rear: float, big: float) -> list:
    """Per film point (fx, 0) and per iris radius in ``radii`` (descending): the rim of the passing
    set (:func:`_rims`), or None when nothing passes. A point's grid zooms in on its passing set once
    that has shrunk to under half of the grid."""
    radii = np.asarray(radii, dtype=float)
    boxes, grids = _first_grids(q, film_z, fxs, radii[0], r_rear, big)
    start = [0] * len(fxs)  # the first radius each point's current grid serves
    uses = [[] for _ in fxs]  # per film point: (grid, the radii it serves)
    pending = list(range(len(fxs)))
    while pending:
        zoom = {}
        for p in pending:
            gx, gy, ok, rad, dx, dy, _ = grids[p]
            box = boxes[p]
            rs = radii[start[p]:]
            sel = ok & (rad <= rs[:, None])  # (radii, samples)
            anyp = sel.any(axis=1)
            xmin = np.where(sel, gx, np.inf).min(axis=1)
            xmax = np.where(sel, gx, -np.inf).max(axis=1)
            ymax = np.where(sel, gy, -np.inf).max(axis=1)
            small = anyp & (xmax - xmin + 4 * dx < 0.5 * (box[1] - box[0])) & (ymax + 2 * dy < 0.5 * box[2])
            # the grid serves the radii before the first one that has shrunk under half of it
            first = int(np.argmax(small)) if small.any() else rs.size
            if first < rs.size:
                uses[p].append((grids[p], rs[:first]))
                zoom[p] = (xmin[first] - 2 * dx, xmax[first] + 2 * dx, ymax[first] + 2 * dy)
                start[p] += first
            else:
                uses[p].append((grids[p], rs))
        for p, g in zip(zoom, _trace(q, film_z, [fxs[p] for p in zoom], list(zoom.values()), big) if zoom else []):
            grids[p], boxes[p] = g, zoom[p]
        pending = list(zoom)
    return [[rim for g, rs in u if len(rs) for rim in _rims(g, rs)] for u in uses]


#: Growth of every fitted ellipse beyond its rim points (the rim between two grid lines)
_SAFETY = 1.003


def _fit(rim) -> np.ndarray:
    """(cx, ax, ay, area): the ellipse about the rim's middle, axes along x and y, that holds every rim
    point, and the passing set's area."""
    x, y = rim.x, rim.y
    cx = 0.5 * (x.min() + x.max())
    ax = 0.5 * (x.max() - x.min())
    ay = y.max()
    g = _need(rim, cx, ax, ay)
    return np.array([cx, ax * g, ay * g, rim.area()])


def _need(rim, cx: float, ax: float, ay: float) -> float:
    """The factor the ellipse's axes need so that it holds ``rim``'s points (times :data:`_SAFETY`)."""
    if rim is None:
        return 1.0
    x, y = rim.x, rim.y
    if not (ax > 0 and ay > 0):
        return math.inf
    return float(np.sqrt(((x - cx) / ax) ** 2 + (y / ay) ** 2).max()) * _SAFETY


def interpolated_ellipse(table: np.ndarray, levels, rho: float, s: float) -> np.ndarray:
    """(cx, ax, ay) as the shader reads ``table`` (levels x radii x 5) at film radius ``rho`` (mm) and
    iris radius ``s`` (mm): linear in rho, linear in s between levels, the last level's axes scaled
    by s / s_last below it."""
    _table(table, levels)
    return _ellipse_at(table, _levels(levels), require_finite("film radius", rho), require_finite("iris radius", s))


def interpolated_area(table: np.ndarray, levels, rho: float, s: float) -> float:
    """The passing set's area (mm^2) as the shader reads ``table``: linear in rho, between levels a
    cubic in s through the levels' areas and slopes (Hermite: the area of the iris's image grows as its
    square, and saturates where other surfaces cut it), scaled by (s / s_last)^2 below the last;
    -1 where an entry it reads does not hold a trusted area (radial_pupil_table)."""
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
    if table[l0:l0 + 2, j0:j0 + 2, 3].min() < 0:
        return -1.0
    at = (1 - rw) * table[l0:l0 + 2, j0, 3:] + rw * table[l0:l0 + 2, j0 + 1, 3:]
    if shrink < 1.0:
        return float(at[1, 0] * shrink * shrink)
    return float(hermite(levels[l0 + 1], at[1, 0], at[1, 1], levels[l0], at[0, 0], at[0, 1], s))


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


def radial_pupil_table(q, film_z: float, levels) -> np.ndarray:
    """The table (len(levels) x :data:`N_RADIAL` x 5: cx, ax, ay in mm on the rear vertex plane, the
    passing set's area in mm^2 and its slope in mm^2 per mm of iris radius) of the focused lens ``q``
    (a Prescription) with its film at ``film_z``, at the iris radii ``levels`` (:func:`iris_levels`).
    Where nothing passes at any iris, the ellipse is a neighbour's and the area 0."""
    from ..lens.prescription import require_prescription

    q = require_prescription(q)
    film_z = require_finite("film z", film_z)
    if q.is_anamorphic:
        raise InputError(f"{q.name!r} is anamorphic: the radial pupil table needs a lens with rotational symmetry")
    levels = _levels(levels)
    if not film_z > q.vertex_z[-1]:
        raise InputError(f"the film (z = {film_z:g} mm) must lie behind the lens's last vertex (z = {q.vertex_z[-1]:g} mm)")
    semi_max = levels[0]
    mids = np.sqrt(levels[:-1] * levels[1:])
    below = levels[-1] / 2
    checked = np.unique(np.concatenate([levels, mids, [below]]))[::-1]
    near = np.concatenate([levels * (1 - _DS), levels * (1 + _DS)])  # the area's slope at each level
    radii = np.unique(np.concatenate([checked, near]))[::-1]
    index = {float(s): i for i, s in enumerate(radii)}
    r_rear = q.surfaces[-1].semi_diameter
    big = 20.0 * max(semi_max, q.surfaces[q.stop_index].semi_diameter)
    step = RADIAL_MAX_MM / (N_RADIAL - 1)
    sets = _passing_sets(q, film_z, [j * step for j in range(N_RADIAL)] + [(j + 0.5) * step for j in range(N_RADIAL - 1)],
                         radii, r_rear, big)
    at_node, at_mid = sets[:N_RADIAL], sets[N_RADIAL:]
    table = np.zeros((len(levels), N_RADIAL, 5))
    empty = np.ones((len(levels), N_RADIAL), dtype=bool)
    for j in range(N_RADIAL):
        for k, s in enumerate(levels):
            reg = at_node[j][index[float(s)]]
            if reg is not None:
                table[k, j, :4] = _fit(reg)
                up, down = at_node[j][index[float(s * (1 + _DS))]], at_node[j][index[float(s * (1 - _DS))]]
                table[k, j, 4] = ((up.area() if up else 0.0) - (down.area() if down else 0.0)) / (2 * _DS * s)
                empty[k, j] = False
    dark = empty.copy()
    _fill(table, empty)
    table[..., 3] = np.where(dark, 0.0, table[..., 3])  # nothing passes (the ellipse is a neighbour's)
    table[..., 4] = np.where(dark, 0.0, table[..., 4])
    # grow the entries until the shader's interpolation holds every traced set between them
    checks = [(j * step, at_node[j]) for j in range(N_RADIAL)] + [((j + 0.5) * step, at_mid[j])
                                                                   for j in range(N_RADIAL - 1)]
    for rho, sets in checks:
        ri = rho / step
        j0 = min(int(math.floor(ri + 1e-9)), N_RADIAL - 2)
        cols = [j0] if abs(ri - j0) < 1e-9 else [j0, j0 + 1]
        for s in checked:
            reg = sets[index[float(s)]]
            if reg is None:
                continue
            for _ in range(8):
                cx, ax, ay = _ellipse_at(table, levels, rho, float(s))
                g = _need(reg, cx, ax, ay)
                if g <= 1.0:
                    break
                rows = _rows_used(levels, float(s))
                for k in rows:
                    for j in cols:
                        table[k, j, 1:3] *= g * (1 + 1e-6)
    # the area weighs rays only where the shader's interpolation of it is the traced area's within
    # AREA_TOLERANCE at every radius and iris between the entries (elsewhere their area is -1)
    trusted = table[..., 3] > 0
    for rho, sets in checks:
        ri = rho / step
        j0 = min(int(math.floor(ri + 1e-9)), N_RADIAL - 2)
        cols = [j0] if abs(ri - j0) < 1e-9 else [j0, j0 + 1]
        for s in checked:
            reg = sets[index[float(s)]]
            want = reg.area() if reg is not None else 0.0
            got = _area_at(table, levels, rho, float(s))
            if abs(got - want) > AREA_TOLERANCE * max(want, 1e-12):
                l0, lw, shrink = _bracket(levels, float(s))
                for k in ([l0, l0 + 1] if shrink == 1.0 else [l0 + 1]):
                    for j in cols:
                        trusted[k, j] = False
    table[..., 3] = np.where(trusted, table[..., 3], -1.0)
    return table


def _rows_used(levels, s: float) -> list[int]:
    """The level rows the shader reads at iris radius ``s``."""
    l0, lw, _ = _bracket(levels, s)
    return [k for k, w in ((l0, 1 - lw), (l0 + 1, lw)) if w > 0] or [l0]
