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

from ..errors import InputError

__all__ = ["RADIAL_MAX_MM", "N_RADIAL", "LEVEL_RATIO", "N_LEVEL", "radial_pupil_table", "iris_levels",
           "level_bracket", "interpolated_ellipse", "interpolated_area"]

#: Film radius the table reaches (mm): the half diagonal of physcam's largest sensor (IMAX 15/70).
RADIAL_MAX_MM = 44.0
#: Film radii tabulated, uniform from the axis to :data:`RADIAL_MAX_MM`.
N_RADIAL = 25
#: Iris radius ratio between consecutive levels below the file's stop (a third of a stop in f-number).
LEVEL_RATIO = 2.0 ** (1.0 / 3.0)
#: Iris levels tabulated: the widest iris, the file's stop, and on down to 1/16 of it (four stops).
N_LEVEL = 14
_GRID = 48  # aim samples across a grid (half as many across its y >= 0 half)


def iris_levels(semi_max: float, semi_file: float) -> np.ndarray:
    """The tabulated iris radii (mm), largest first: the widest iris (``semi_max``: physcam's camera
    state opens the stop a little beyond the file's, to the lens's marked f-number), the file's stop
    (``semi_file``: on axis the other elements pass no more) and :data:`LEVEL_RATIO` steps below it."""
    if not 0 < semi_file <= semi_max:
        raise InputError(f"iris levels need 0 < file stop <= widest iris, got {semi_file!r} and {semi_max!r}")
    return np.concatenate([[float(semi_max)], float(semi_file) * LEVEL_RATIO ** -np.arange(N_LEVEL - 1, dtype=float)])


def level_bracket(levels, s: float) -> tuple[int, float, float]:
    """(l0, lw, shrink): the shader's reading of iris radius ``s``: levels l0 and l0 + 1 mixed with
    weight lw (linear in s); below the last level, the last one's axes times ``shrink`` = s / s_last."""
    n = len(levels)
    if s <= levels[-1]:
        return n - 2, 1.0, s / levels[-1]
    l0 = max([k for k in range(n - 1) if s <= levels[k]] or [0])
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


def _trace(q, film_z: float, fxs, boxes, big: float) -> list:
    """Rays from film points (fx, 0) to the aim grid over each one's box on the rear vertex plane, in
    one trace: per film point (x, y, passes every surface but the stop, radius where it crosses the
    stop plane, grid steps)."""
    from ..trace.rays import OK, RayBatch
    from ..trace.trace import trace_through

    grids = [_grid(b) for b in boxes]
    gx = np.concatenate([g[0] for g in grids])
    gy = np.concatenate([g[1] for g in grids])
    fx = np.repeat(np.asarray(fxs, dtype=float), [g[0].size for g in grids])
    z_rear = q.vertex_z[-1]
    start = np.stack([fx, np.zeros_like(fx), np.full(fx.size, film_z)], axis=1)
    rays = RayBatch.from_arrays(start, np.stack([gx - fx, gy, np.full(gx.size, z_rear - film_z)], axis=1),
                                q.wavelength_nm)
    probe = _StopCrossing()
    trace_through(q, rays, reverse=True, clip=True, stop_semi_diameter=big, aperture=probe, in_place=True)
    ok, rad = rays.flag == OK, probe.radius * big
    out, i = [], 0
    for g in grids:
        n = g[0].size
        out.append((g[0], g[1], ok[i:i + n], rad[i:i + n], g[2], g[3]))
        i += n
    return out


def _rims(g, radii) -> list:
    """Per iris radius s in ``radii``, the rim of the passing set on grid ``g`` as points (x, y), or
    None when nothing passes. Between a passing sample and a neighbour the iris stops, the rim is
    where the stop radius crosses s (linear between the two: the stop radius is smooth); toward a
    neighbour another surface clips, or past the grid's edge, it is put at the neighbour
    (conservative). The set is convex (the iris's image, cut by other round apertures), so its rim
    bounds it."""
    gx, gy, ok, rad, dx, dy = g
    ny, nx = _GRID // 2, _GRID
    ok, rad = ok.reshape(ny, nx), rad.reshape(ny, nx)
    s = np.asarray(radii, dtype=float)[:, None, None]
    inside = ok & (rad <= s)  # (radii, ny, nx)
    parts = []  # (radius index, x, y) arrays
    # toward +x, -x and +y (the y = 0 side mirrors itself): the sample's (a) and its neighbour's (b) cells
    for (ja, ia_), (jb, ib), ex, ey in (((slice(None), slice(0, -1)), (slice(None), slice(1, None)), dx, 0.0),
                                        ((slice(None), slice(1, None)), (slice(None), slice(0, -1)), -dx, 0.0),
                                        ((slice(0, -1), slice(None)), (slice(1, None), slice(None)), 0.0, dy)):
        ra, rb = rad[ja, ia_], rad[jb, ib]
        rim = inside[:, ja, ia_] & ~inside[:, jb, ib]
        k, jj, ii = np.nonzero(rim)
        with np.errstate(divide="ignore", invalid="ignore"):
            f = np.where(ok[jb, ib][jj, ii], np.clip((s[k, 0, 0] - ra[jj, ii]) / (rb[jj, ii] - ra[jj, ii]), 0.0, 1.0), 1.0)
        nb_ok = ok[jb, ib][jj, ii]
        fa = np.where(nb_ok, f, 0.5)  # the area's estimate: half a step where another surface clips
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

    def area(self) -> float:
        """The set's area (mm^2, both halves): the polygon through its edge points, taken in angle order
        about their middle (the set is convex)."""
        x = np.concatenate([self.xa, self.xa])
        y = np.concatenate([self.ya, -self.ya])
        o = np.argsort(np.arctan2(y, x - 0.5 * (x.min() + x.max())))
        x, y = x[o], y[o]
        return float(0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def _passing_sets(q, film_z: float, fxs, radii, r_rear: float, big: float) -> list:
    """Per film point (fx, 0) and per iris radius in ``radii`` (descending): the rim of the passing
    set (:func:`_rims`), or None when nothing passes. A point's grid zooms in on its passing set once
    that has shrunk to under half of the grid."""
    boxes = [(-r_rear, r_rear, r_rear)] * len(fxs)
    grids = _trace(q, film_z, fxs, boxes, big)
    uses = [[(g, [])] for g in grids]  # per film point: (grid, the radii it serves)
    for s in radii:
        zoom = {}
        for p, g in enumerate(grids):
            gx, gy, ok, rad, dx, dy = g
            sel = ok & (rad <= s)
            if sel.any():
                x, y = gx[sel], gy[sel]
                box = boxes[p]
                if x.max() - x.min() + 4 * dx < 0.5 * (box[1] - box[0]) and y.max() + 2 * dy < 0.5 * box[2]:
                    zoom[p] = (x.min() - 2 * dx, x.max() + 2 * dx, y.max() + 2 * dy)
        if zoom:
            for p, g in zip(zoom, _trace(q, film_z, [fxs[p] for p in zoom], list(zoom.values()), big)):
                grids[p], boxes[p] = g, zoom[p]
                uses[p].append((g, []))
        for p in range(len(fxs)):
            uses[p][-1][1].append(s)
    return [[rim for g, rs in u if rs for rim in _rims(g, rs)] for u in uses]


#: Growth of every fitted ellipse beyond its rim points (the rim between two grid lines)
_SAFETY = 1.003


def _fit(rim) -> np.ndarray:
    """(cx, ax, ay, area): the ellipse about the rim's middle, axes along x and y, that holds every rim
    point, and the passing set's area when the iris alone bounds it (else -1: another surface clips
    it, and its area is not known well enough to weigh rays by)."""
    x, y = rim.x, rim.y
    cx = 0.5 * (x.min() + x.max())
    ax = 0.5 * (x.max() - x.min())
    ay = y.max()
    g = _need(rim, cx, ax, ay)
    return np.array([cx, ax * g, ay * g, -1.0 if rim.clipped else rim.area()])


def _need(rim, cx: float, ax: float, ay: float) -> float:
    """The factor the ellipse's axes need so that it holds ``rim``'s points (times :data:`_SAFETY`)."""
    if rim is None:
        return 1.0
    x, y = rim.x, rim.y
    if not (ax > 0 and ay > 0):
        return math.inf
    return float(np.sqrt(((x - cx) / ax) ** 2 + (y / ay) ** 2).max()) * _SAFETY


def interpolated_ellipse(table: np.ndarray, levels, rho: float, s: float) -> np.ndarray:
    """(cx, ax, ay) as the shader reads ``table`` (levels x radii x 3) at film radius ``rho`` (mm) and
    iris radius ``s`` (mm): linear in rho, linear in s between levels, the last level's axes scaled
    by s / s_last below it."""
    n_level, n_rad, _ = table.shape
    ri = min(max(rho / (RADIAL_MAX_MM / (n_rad - 1)), 0.0), n_rad - 1.0)
    j0 = min(int(math.floor(ri)), n_rad - 2)
    rw = ri - j0
    at = (1 - rw) * table[:, j0] + rw * table[:, j0 + 1]
    l0, lw, shrink = level_bracket(levels, s)
    return ((1 - lw) * at[l0, :3] + lw * at[l0 + 1, :3]) * np.array([1.0, shrink, shrink])


def interpolated_area(table: np.ndarray, levels, rho: float, s: float) -> float:
    """The passing set's area (mm^2) as the shader reads ``table``: linear in rho, linear in s^2
    between levels (the area of an iris's image goes as its square), scaled by (s / s_last)^2 below;
    -1 when an entry it reads is clipped by another surface than the iris (the area is not known)."""
    n_level, n_rad, _ = table.shape
    ri = min(max(rho / (RADIAL_MAX_MM / (n_rad - 1)), 0.0), n_rad - 1.0)
    j0 = min(int(math.floor(ri)), n_rad - 2)
    rw = ri - j0
    at = (1 - rw) * table[:, j0, 3] + rw * table[:, j0 + 1, 3]
    l0, _, shrink = level_bracket(levels, s)
    if min(table[l0:l0 + 2, j0:j0 + 2, 3].ravel()) < 0:
        return -1.0
    hi, lo = levels[l0], levels[l0 + 1]
    w2 = min(max((hi * hi - s * s) / (hi * hi - lo * lo), 0.0), 1.0) if hi > lo else 1.0
    return float(((1 - w2) * at[l0] + w2 * at[l0 + 1]) * shrink * shrink)


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
    """The table (len(levels) x :data:`N_RADIAL` x 4: cx, ax, ay in mm on the rear vertex plane and the
    passing set's area in mm^2) of the focused lens ``q`` (a Prescription) with its film at
    ``film_z``, at the iris radii ``levels`` (:func:`iris_levels`). An ellipse with zero axes: no
    ray passes at any iris there."""
    if q.is_anamorphic:
        raise InputError(f"{q.name!r} is anamorphic: the radial pupil table needs a lens with rotational symmetry")
    levels = np.asarray(levels, dtype=float)
    semi_max = levels[0]
    mids = np.sqrt(levels[:-1] * levels[1:])
    below = levels[-1] / 2
    radii = np.unique(np.concatenate([levels, mids, [below]]))[::-1]
    index = {float(s): i for i, s in enumerate(radii)}
    r_rear = q.surfaces[-1].semi_diameter
    big = 20.0 * max(semi_max, q.surfaces[q.stop_index].semi_diameter)
    step = RADIAL_MAX_MM / (N_RADIAL - 1)
    sets = _passing_sets(q, film_z, [j * step for j in range(N_RADIAL)] + [(j + 0.5) * step for j in range(N_RADIAL - 1)],
                         radii, r_rear, big)
    at_node, at_mid = sets[:N_RADIAL], sets[N_RADIAL:]
    table = np.zeros((len(levels), N_RADIAL, 4))
    empty = np.ones((len(levels), N_RADIAL), dtype=bool)
    for j in range(N_RADIAL):
        for k, s in enumerate(levels):
            reg = at_node[j][index[float(s)]]
            if reg is not None:
                table[k, j] = _fit(reg)
                empty[k, j] = False
    dark = empty.copy()
    _fill(table, empty)
    table[..., 3] = np.where(dark, -1.0, table[..., 3])  # nothing passes (the ellipse is a neighbour's)
    # grow the entries until the shader's interpolation holds every traced set between them
    checks = [(j * step, at_node[j]) for j in range(N_RADIAL)] + [((j + 0.5) * step, at_mid[j])
                                                                   for j in range(N_RADIAL - 1)]
    for rho, sets in checks:
        ri = rho / step
        j0 = min(int(math.floor(ri + 1e-9)), N_RADIAL - 2)
        cols = [j0] if abs(ri - j0) < 1e-9 else [j0, j0 + 1]
        for s in radii:
            reg = sets[index[float(s)]]
            if reg is None:
                continue
            for _ in range(8):
                cx, ax, ay = interpolated_ellipse(table, levels, rho, float(s))
                g = _need(reg, cx, ax, ay)
                if g <= 1.0:
                    break
                rows = _rows_used(levels, float(s))
                for k in rows:
                    for j in cols:
                        table[k, j, 1:3] *= g * (1 + 1e-6)
    return table


def _rows_used(levels, s: float) -> list[int]:
    """The level rows the shader reads at iris radius ``s``."""
    l0, lw, _ = level_bracket(levels, s)
    return [k for k, w in ((l0, 1 - lw), (l0 + 1, lw)) if w > 0] or [l0]
