"""Where ``physcam defocus`` traces its kernels across the picture, and what it reads between them.

**Field nodes** (issue 47: spaced by how fast the kernel changes). A tensor grid symmetric about
the frame centre: columns at ``x = W/2 (1 +- rho_k)``, rows at ``y = H/2 (1 +- rho_k)``, for
fractions ``0 = rho_0 < ... < rho_K = 1`` of the half-frame. The fractions come from bisection
along the diagonal (the picture position ``(W/2 (1 + rho), H/2 (1 - rho))``, top right, the
farthest from the axis for its rho): an interval is split while the kernel traced at its middle
differs from the even blend of its ends' kernels (what the interpolation makes there) by more than
:data:`CENTROID_TOL_PX` in centroid or :data:`WIDTH_TOL` in second-moment width, at two probe
depths (the farthest node and a near one; :func:`probe_nodes`). Between nodes a kernel is the
bilinear blend of its four nodes' kernels, each binned around its own focus-plane image (below).

**Transmission** ``T``: the flux through the lens of a pinhole pixel's patch relative to the frame
centre's at the same depth, ``cos(theta) Omega(field) / Omega(axis)`` (docs/defocus.md), read per
pixel from a finer table so that a flat field has no steps: for a rotationally symmetric lens,
:data:`TABLE_RADII` radii along the diagonal (out to 1.25 of the half-diagonal, for the frame's
margin), T a function of the radius; for an anamorphic lens, a quadrant grid (such lenses are
symmetric about both meridians). Traced at each depth ladder node
(:meth:`~physcam.analysis.defocus.kernels.DefocusCamera.ladder`), linear in inverse depth between.

**Centring.** Every kernel is binned around its own light's centroid, so the output keeps the
render's geometry: the lens's distortion (up to 16 px in the corners of a 2K frame of the double
Gauss) and the pixel or two a cat's eye's centroid moves with depth are left out. A kernel that
moved its light would leave a seam wherever two tiles' kernels move it differently (a tenth of a
pixel is a 7 % line on a flat field at a small blur); distortion is applied, if wanted, by
physcam's ST map (``physcam distortion``), as a compositor redistorts a CG element. So that the ST
map gives the film's blur back (and does not squeeze it a second time), a kernel's offsets are
taken from the film's pixels to the render's by the inverse of the distortion's local Jacobian at
its field node (:func:`~physcam.analysis.defocus.trace.distortion_jacobians`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .trace import FAR_MM, bin_fan, bin_fans, fan_centroid, interpolate_fan, pupil_boxes, solid_angles, trace_fans


#: the blend of two nodes' kernels may sit this far (px) from the kernel traced between them
CENTROID_TOL_PX = 0.25
#: ... and its second-moment width differ from it by this fraction
WIDTH_TOL = 0.03
#: the finest fraction of the half-frame between field nodes, and the most fractions
_MIN_STEP, _MAX_FRACTIONS = 1.0 / 16, 5
#: samples of a probe fan
PROBE_SAMPLES = 1 << 13
#: radii of the transmission table along the diagonal, and grid of an anamorphic's quadrant
TABLE_RADII, TABLE_GRID = 81, (33, 17)
#: how far beyond the frame's corner the table reaches (fraction of the half-frame)
TABLE_REACH = 1.25


def box_depths(cam) -> list[float]:
    """The inverse depths a field position's sampling box is sized from: infinity, the focus and the
    depth of a 512 px blur (or the lens's front, if nearer): the same for every frame of a camera."""
    near = cam.focus_u + 512.0 / cam.blur_per_u
    limit = 1.0 / max(cam.front_from_film_mm - cam.pupil_from_film_mm + 1.0, 1.0)
    return [0.0, cam.focus_u, min(near, limit)]


def diagonal_point(cam, rho: float) -> tuple[float, float]:
    """The picture position (display px, y down) a fraction ``rho`` along the half-diagonal, top right."""
    return 0.5 * cam.width * (1.0 + rho), 0.5 * cam.height * (1.0 - rho)


def probe_nodes(cam) -> tuple[int, ...]:
    """The depth ladder nodes the field grid is probed at: the farthest, and the first near ladder
    node whose blur is at least 24 px or twice the farthest's (the cat's eye shows in a large blur)."""
    far = cam.node_far()
    b_far = float(cam.blur_px_at(far))
    want = max(24.0, 2.0 * b_far)
    n = 0
    while float(cam.blur_px_at(n)) < want and n < 4096:
        n += cam.ladder_step
    return (far, n) if far != n else (n,)


def _moments(fan, centre):
    """Weight, centroid (px from ``centre``) and covariance (px^2) of a fan's light."""
    g = fan.w > 0
    w = fan.w[g]
    t = w.sum()
    x, y = fan.ox[g] - centre[0], fan.oy[g] - centre[1]
    with np.errstate(invalid="ignore", divide="ignore"):  # a fan without light: NaN moments, never a split
        cx, cy = (w * x).sum() / t, (w * y).sum() / t
        cov = np.array([[(w * (x - cx) ** 2).sum(), (w * (x - cx) * (y - cy)).sum()],
                        [(w * (x - cx) * (y - cy)).sum(), (w * (y - cy) ** 2).sum()]]) / t
    return np.array([cx, cy]), cov


def _blend_error(a, b, m) -> tuple[float, float]:
    """(centroid distance px, largest relative width difference) between the even blend of the
    kernels of moments ``a`` and ``b`` and the kernel of moments ``m``."""
    (ca, va), (cb, vb), (cm, vm) = a, b, m
    c = 0.5 * (ca + cb)
    v = 0.5 * (va + np.outer(ca, ca) + vb + np.outer(cb, cb)) - np.outer(c, c)
    width = np.sqrt(np.maximum(np.diag(v), 0.0))
    true = np.sqrt(np.maximum(np.diag(vm), 0.0))
    return float(np.hypot(*(c - cm))), float(np.max(np.abs(width - true) / (true + 0.5)))


def field_fractions(cam) -> tuple[float, ...]:
    """The field nodes' fractions of the half-frame (module notes), by bisection along the diagonal."""
    depths = [float(cam.node_u(n)) for n in probe_nodes(cam)]
    cache: dict = {}

    def moments(rhos):
        new = [r for r in rhos if r not in cache]
        if new:
            pts = [diagonal_point(cam, r) for r in new]
            boxes = pupil_boxes(cam, pts, box_depths(cam))
            jobs = [(p, u, b, PROBE_SAMPLES) for p, b in zip(pts, boxes) for u in depths + [cam.focus_u]]
            fans = trace_fans(cam, jobs)
            k = len(depths) + 1
            for i, r in enumerate(new):
                centre = fan_centroid(fans[i * k + k - 1])
                cache[r] = [_moments(f, centre) for f in fans[i * k: i * k + k - 1]]
        return [cache[r] for r in rhos]

    done, todo = [0.0, 1.0], [(0.0, 1.0)]
    while todo and len(done) < _MAX_FRACTIONS + 1:
        a, b = todo.pop(0)
        if b - a <= _MIN_STEP:
            continue
        m = 0.5 * (a + b)
        ma, mb, mm = moments([a, b, m])
        worst = [_blend_error(x, y, z) for x, y, z in zip(ma, mb, mm)]
        if any(c > CENTROID_TOL_PX or w > WIDTH_TOL for c, w in worst):
            done.append(m)
            todo += [(a, m), (m, b)]
            todo.sort(key=lambda ab: ab[0] - ab[1])  # the widest interval first
    return tuple(sorted(done))


def grid_nodes(cam, fractions) -> tuple[np.ndarray, np.ndarray]:
    """The field grid's columns and rows (display px), from its fractions."""
    f = np.asarray(fractions, dtype=float)
    sym = np.concatenate([-f[:0:-1], f])
    return 0.5 * cam.width * (1.0 + sym), 0.5 * cam.height * (1.0 + sym)


@dataclass
class FieldTable:
    """Transmission on the table's positions (module notes): along the diagonal (``radial``) or on
    a quadrant grid; ``qx``, ``qy`` their offsets from the centre (px, x right, y up);
    ``transmission[n]`` (positions, channels) at each ladder node n traced so far."""

    radial: bool
    qx: np.ndarray
    qy: np.ndarray
    transmission: dict

    def positions(self, cam) -> list[tuple[float, float]]:
        """The table's picture positions (display px)."""
        return [(0.5 * cam.width + x, 0.5 * cam.height - y) for x, y in zip(self.qx, self.qy)]

    def _weights(self, cam, x, y):
        """Interpolation indices and weights of picture positions (x, y) (arrays) in the table."""
        dx, dy = np.abs(x - 0.5 * cam.width), np.abs(y - 0.5 * cam.height)
        if self.radial:
            r = np.hypot(dx, dy) / math.hypot(0.5 * cam.width, 0.5 * cam.height)
            step = TABLE_REACH / (TABLE_RADII - 1)
            t = np.clip(r / step, 0, TABLE_RADII - 1 - 1e-9)
            i = t.astype(np.int64)
            return [(i, 1.0 - (t - i)), (i + 1, t - i)]
        nx, ny = TABLE_GRID
        tx = np.clip(dx / (TABLE_REACH * 0.5 * cam.width) * (nx - 1), 0, nx - 1 - 1e-9)
        ty = np.clip(dy / (TABLE_REACH * 0.5 * cam.height) * (ny - 1), 0, ny - 1 - 1e-9)
        ix, iy = tx.astype(np.int64), ty.astype(np.int64)
        fx, fy = tx - ix, ty - iy
        return [(iy * nx + ix, (1 - fx) * (1 - fy)), (iy * nx + ix + 1, fx * (1 - fy)),
                ((iy + 1) * nx + ix, (1 - fx) * fy), ((iy + 1) * nx + ix + 1, fx * fy)]

    def transmission_at(self, cam, x, y, n) -> np.ndarray:
        """T (…, channels) at picture positions (x, y) and depth node ``n`` (linear in u between
        the ladder nodes around it, which must be in the table)."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        (a, b), (wa, wb) = cam.ladder(n), cam.ladder_weight(n)
        tab = wa * self.transmission[a] + wb * self.transmission[b]
        return sum(w[..., None] * tab[i] for i, w in self._weights(cam, x, y)).astype(np.float32)


def _table_positions(cam):
    """The quadrant offsets (px from the centre: x right, y up) of a new table's positions."""
    if not cam.lens.is_anamorphic:
        rho = np.linspace(0.0, TABLE_REACH, TABLE_RADII)
        return True, 0.5 * cam.width * rho, 0.5 * cam.height * rho
    nx, ny = TABLE_GRID
    gx, gy = np.meshgrid(np.linspace(0, TABLE_REACH * 0.5 * cam.width, nx),
                         np.linspace(0, TABLE_REACH * 0.5 * cam.height, ny))
    return False, gx.ravel(), gy.ravel()


def field_table(cam, table: FieldTable | None, ladder_nodes) -> FieldTable:
    """``table`` (or a new one) with the transmission at every node of ``ladder_nodes`` traced."""
    if table is None:
        radial, qx, qy = _table_positions(cam)
        table = FieldTable(radial, qx, qy, {})
    todo = sorted(set(ladder_nodes) - set(table.transmission))
    if not todo:
        return table
    pts = table.positions(cam)
    us = [float(cam.node_u(n)) for n in todo]
    omega = solid_angles(cam, pts, us)  # (points, depths, channels)
    for j, n in enumerate(todo):
        d = 1.0 / max(float(cam.node_u(n)), 1.0 / FAR_MM)
        cos_t = np.array([_cos_theta(cam, p, d) for p in pts])
        axis = np.where(omega[0, j] > 0, omega[0, j], 1.0)
        table.transmission[n] = omega[:, j, :] / axis * cos_t[:, None]
    _say_dark(cam, table, todo, omega)
    return table


def _say_dark(cam, table, nodes, omega) -> None:
    """A warning where no light of the traced pupil reached the film from a table position while the
    axis's did: the picture is black there (the lens does not cover the frame, or at a very small stop
    the kernels' pupil search misses the light: a review found f/500 on dgauss_50mm, whose corner keeps
    cos^4 of its light at f/300)."""
    dark = (omega.max(axis=2) <= 0) & (omega[0].max(axis=1) > 0)[None, :]
    if not dark.any():
        return
    import warnings

    from ...errors import PhysCamWarning

    k = int(dark.any(axis=1).sum())
    warnings.warn(f"no light reached the film from {k} of {len(table.qx)} field positions toward the frame's edge "
                  f"at f/{cam.fstop:g}: the picture is black there (the lens does not cover the frame, or the stop "
                  f"is too small for the kernels' pupil search: try a larger one)", PhysCamWarning, stacklevel=3)


def _cos_theta(cam, point, d) -> float:
    """cos of the angle at the pupil between the axis and the object point of ``point`` at depth d."""
    sx, sy = cam.film_point(*point)
    X, Y = sx * d / cam.pinhole_x_mm, sy * d / cam.pinhole_mm
    return d / math.sqrt(d * d + X * X + Y * Y)


def node_kernel(cam, fan_a, fan_b, n, maps=None, unwarp=None) -> tuple[np.ndarray, tuple[float, float]]:
    """The kernel of depth node ``n`` from the ladder fans around it, binned around its light's
    centroid (module notes) in the render's pixels (``unwarp``: the inverse of the distortion's
    local Jacobian there) and scaled to a unit sum per channel; and that centroid (px from the
    pinhole's image)."""
    u = float(cam.node_u(n))
    fan = interpolate_fan(fan_a, fan_b, u, maps) if fan_a is not fan_b else fan_a
    centre = fan_centroid(fan)
    img, _ = bin_fan(fan, centre, len(cam.wavelengths_nm), unwarp)
    return _unit_kernel(img), centre


def direct_kernels(cam, fans, unwarps) -> list[np.ndarray]:
    """:func:`node_kernel` of each fan traced at its node's own depth (``fans[i]`` with ``unwarps[i]``),
    binned together (:func:`~physcam.analysis.defocus.trace.bin_fans`, by sample count): the same kernels."""
    out: list = [None] * len(fans)
    by_size: dict = {}
    for i, fan in enumerate(fans):
        by_size.setdefault(len(fan.w), []).append(i)
    for same in by_size.values():
        for b in range(0, len(same), 128):  # about 10 arrays of (128, samples) float64 at once
            idx = same[b:b + 128]
            got = bin_fans([fans[i] for i in idx], len(cam.wavelengths_nm), [unwarps[i] for i in idx])
            for i, (_, (img, _)) in zip(idx, got):
                out[i] = _unit_kernel(img)
    return out


def _unit_kernel(img: np.ndarray) -> np.ndarray:
    """A binned kernel trimmed to :data:`KERNEL_LIGHT` of its light and scaled to a unit sum per channel (float32)."""
    img = _trim(img, KERNEL_LIGHT)
    tot = img.sum(axis=(0, 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        img = np.where(tot > 0, img / np.where(tot > 0, tot, 1.0), 0.0)
    return img.astype(np.float32)


#: a kernel is cut to the smallest centred square holding this much of its light (the rest, a few
#: stray rays of a halo, is given back to it by the unit sum): smaller convolutions, same light
KERNEL_LIGHT = 0.9995


def _trim(img: np.ndarray, keep: float = 1.0) -> np.ndarray:
    """``img`` cut to the smallest centred square holding ``keep`` of its light (all of it by default)."""
    r = img.shape[0] // 2
    m = img.sum(axis=2)
    tot = float(m.sum())
    if not tot > 0:
        return img[r:r + 1, r:r + 1]
    inside = np.cumsum(np.bincount(_ring(r), weights=m.ravel(), minlength=r + 1))
    e = int(np.searchsorted(inside, keep * tot * (1 - 1e-12)))
    return img[r - e:r + e + 1, r - e:r + e + 1]


_RINGS: dict = {}


def _ring(r: int) -> np.ndarray:
    """Each pixel's square "radius" max(|dy|, |dx|) from the centre of a (2r + 1)^2 image, flat (memoised)."""
    if r not in _RINGS:
        ys, xs = np.indices((2 * r + 1, 2 * r + 1))
        _RINGS[r] = np.maximum(np.abs(ys - r), np.abs(xs - r)).ravel()
    return _RINGS[r]
