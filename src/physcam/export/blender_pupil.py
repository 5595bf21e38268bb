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
(ax, ay). The sets' rims are found on aim grids, or along lines from the film point's chief aim where the iris alone
bounds a set: :mod:`physcam.export.blender_pupil_sets`, whose notes have the geometry and its accuracy.

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
from .blender_pupil_sets import (_LINES, _SAFETY, _LineSets, _RimSet, _fits, _grid_rims, _passing_grids,
                                 _rear_boxes)

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
