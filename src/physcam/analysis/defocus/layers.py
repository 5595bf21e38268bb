"""The depth layers of :func:`physcam.analysis.defocus.render.defocus`: what each tile sends to each depth
node, and its blur.

A pixel of inverse depth u lies between depth nodes ``lo`` and ``lo + 1`` and sends the share
``1 - t`` of its light and coverage to the first, ``t`` to the second (linear in u: the blur grows
smoothly, no banding). Its **group** is ``lo``. The frame is padded by a margin (the edge pixels
repeated) so that light comes in from outside the frame as it does in a camera; that light, and the
**fill** that continues a group behind a nearer one, are kept apart from the picture's own light
(they are estimates: :func:`physcam.analysis.defocus.render.defocus` allows them no more light than they
replace).

The fill of group g: behind a pixel whose group is at least two nodes nearer (a depth edge; a
surface whose depth varies smoothly needs none), group g is present with the density it has among
the pixels around that are not nearer than it, in its mean colour there (both per tile, blended
between tile centres so they vary smoothly): ``rho = S_g / A_g`` and colour ``L_g / S_g``, S_g the
coverage of group g in a tile, A_g the coverage of groups g and farther, L_g the light of group g.
A small object (a spot beside a near surface) so continues behind it with little coverage; a
background around a foreground with coverage 1.

Each (tile, node) pair is blurred with the tile's kernel at that node
(:meth:`~physcam.analysis.defocus.kernels.KernelCache.tile_kernel`; FFT, or a direct sum for
kernels up to 7 px): planes ``V`` (the picture's light), ``G`` (margin and fill light), ``A``
(coverage of group n: its pixels' lower shares and its fill), ``U`` (coverage of group n - 1: its
pixels' upper shares) and, when the image has an alpha channel, ``A1``, ``U1`` (the same with
alpha 1, the coverage an opaque picture would have).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np



@dataclass
class Frame:
    """The padded picture: colour (c, h, w: planes first), coverage ``a`` (h, w), lower node ``lo`` and upper
    weight ``t`` per pixel, ``inside`` (the picture, not its margin), the margin width, the tile,
    the display position of pixel (0, 0) and per-tile fill statistics (:func:`fill_stats`)."""

    colour: np.ndarray
    a: np.ndarray
    lo: np.ndarray
    t: np.ndarray
    inside: np.ndarray
    margin: int
    tile: int
    origin: tuple[float, float]
    has_alpha: bool
    stats: dict = field(default_factory=dict)

    @property
    def tiles(self) -> tuple[int, int]:
        h, w = self.lo.shape
        return math.ceil(h / self.tile), math.ceil(w / self.tile)

    def tile_slice(self, ty: int, tx: int):
        t = self.tile
        return slice(ty * t, (ty + 1) * t), slice(tx * t, (tx + 1) * t)


def frame_of(colour, a, lo, t, margin, tile, origin, has_alpha) -> Frame:
    """The frame padded by ``margin`` pixels on every side (edge pixels repeated)."""
    m = int(margin)
    pad2 = ((m, m), (m, m))
    h, w = lo.shape
    inside = np.zeros((h + 2 * m, w + 2 * m), dtype=bool)
    inside[m:m + h, m:m + w] = True
    planes = np.ascontiguousarray(np.moveaxis(np.asarray(colour), 2, 0), dtype=np.float32)
    f = Frame(np.pad(planes, ((0, 0),) + pad2, mode="edge"), np.pad(a, pad2, mode="edge").astype(np.float32),
              np.pad(lo, pad2, mode="edge").astype(np.int32), np.pad(t, pad2, mode="edge").astype(np.float32), inside,
              m, int(tile), (origin[0] - m, origin[1] - m), has_alpha)
    f.stats = fill_stats(f)
    return f


def fill_stats(f: Frame) -> dict:
    """Per tile and group: coverage S, coverage of that group and farther ones A, light L (module notes)."""
    ny, nx = f.tiles
    h, w = f.lo.shape
    ys, xs = np.indices((h, w))
    tid = (ys // f.tile) * nx + xs // f.tile
    groups = np.unique(f.lo)
    gi = np.searchsorted(groups, f.lo)
    key = (tid * len(groups) + gi).ravel()
    size = ny * nx * len(groups)
    S = np.bincount(key, weights=f.a.ravel(), minlength=size).reshape(ny, nx, len(groups))
    L = np.stack([np.bincount(key, weights=f.colour[c].ravel(), minlength=size) for c in range(f.colour.shape[0])],
                 axis=-1).reshape(ny, nx, len(groups), -1)
    near = np.zeros((h, w), dtype=np.int32)  # each pixel's nearest 4-neighbour's group
    near[:] = f.lo
    for a, b in (((slice(1, None),), (slice(None, -1),)), ((slice(None, -1),), (slice(1, None),)),
                 ((slice(None), slice(1, None)), (slice(None), slice(None, -1))),
                 ((slice(None), slice(None, -1)), (slice(None), slice(1, None)))):
        np.maximum(near[a], f.lo[b], out=near[a])
    edge = (near >= f.lo + 2).ravel()  # the far side of a depth edge: a neighbour two nodes nearer or more
    E = np.bincount(key[edge], minlength=size).reshape(ny, nx, len(groups)) > 0
    S1 = np.bincount(key, minlength=size).reshape(ny, nx, len(groups)).astype(float)  # with alpha 1 (pixel counts)
    return {"groups": groups, "S": S, "A": np.cumsum(S, axis=2), "L": L, "edge": E, "S1": S1, "A1": np.cumsum(S1, axis=2),
            "key": key}


#: a group is continued behind nearer pixels (a fill) only where it meets them at a depth edge (a
#: neighbour two nodes nearer or more: a surface whose depth changes smoothly needs none) and is at
#: least this dense among the pixels around that are not nearer (a small object has no fill)
FILL_MIN_DENSITY = 0.05


def layer_pairs(f: Frame) -> dict:
    """{node: [(ty, tx, fill group present), ...]}: the tiles each depth node receives light or a fill in."""
    st = f.stats
    groups = st["groups"]
    ny, nx = f.tiles
    pairs: dict = {}
    sums = {k: np.zeros_like(st[k]) for k in ("S", "A", "S1", "A1")}  # over each tile and its neighbours
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            dst = (slice(max(-dy, 0), ny + min(-dy, 0)), slice(max(-dx, 0), nx + min(-dx, 0)))
            src = (slice(max(dy, 0), ny + min(dy, 0)), slice(max(dx, 0), nx + min(dx, 0)))
            for k in sums:
                sums[k][dst] += st[k][src]
    E3 = np.zeros_like(st["edge"])
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            E3[max(-dy, 0):ny + min(-dy, 0), max(-dx, 0):nx + min(-dx, 0)] |= \
                st["edge"][max(dy, 0):ny + min(dy, 0), max(dx, 0):nx + min(dx, 0)]
    with np.errstate(invalid="ignore", divide="ignore"):
        # the group continues behind nearer pixels here: it is dense (in light, or in pixels when the
        # picture has an alpha: its transparent background too), and meets them at a depth edge
        dense = np.nan_to_num(sums["S"] / sums["A"]) >= FILL_MIN_DENSITY
        if f.has_alpha:
            dense |= np.nan_to_num(sums["S1"] / sums["A1"]) >= FILL_MIN_DENSITY
        near = dense & E3
    # per tile and group: pixels sending light to the group's lower node (t < 1) and to its upper one (t > 0)
    key, t, size = st["key"], f.t.ravel(), ny * nx * len(groups)
    to_lo = np.bincount(key[t < 1], minlength=size).reshape(ny, nx, len(groups)) > 0
    to_up = np.bincount(key[t > 0], minlength=size).reshape(ny, nx, len(groups)) > 0
    inside = np.bincount(key // len(groups), weights=f.inside.ravel(), minlength=ny * nx).reshape(ny, nx) > 0
    for ty in range(ny):
        for tx in range(nx):
            if not inside[ty, tx]:  # the margin sends nothing (light leaving the frame is folded back)
                continue
            nodes = set(groups[to_lo[ty, tx]].tolist()) | set((groups[to_up[ty, tx]] + 1).tolist())
            top = groups[np.flatnonzero(st["S1"][ty, tx] > 0)[-1]]  # the tile's nearest group
            fills = set(groups[near[ty, tx] & (groups + 2 <= top)].tolist())
            for n in nodes | fills:
                pairs.setdefault(int(n), []).append((ty, tx, int(n) in fills))
    return pairs


def _tile_weights(n_tiles: int, tile: int, index: int, length: int) -> np.ndarray:
    """(length, 3): each pixel's linear weights on the centres of tiles index - 1, index, index + 1."""
    pos = (index * tile + np.arange(length) + 0.5) / tile - 0.5  # in tile-centre units
    w = np.zeros((length, 3))
    for k, j in enumerate((index - 1, index, index + 1)):
        if 0 <= j < n_tiles:
            w[:, k] = np.clip(1.0 - np.abs(pos - j), 0.0, 1.0)
    ends = (pos < 0) & (index == 0), (pos > n_tiles - 1) & (index == n_tiles - 1)
    w[ends[0], 1] = 1.0
    w[ends[1], 1] = 1.0
    return w


def _fill(f: Frame, ty: int, tx: int, g: int, sl):
    """Group g's density (h, w) and light per unit of coverage (c, h, w) behind the pixels of tile
    (ty, tx) at least two nodes nearer than it, those pixels, and its density in pixels (alpha 1:
    the coverage an opaque picture would have); None if there are none (module notes)."""
    st = f.stats
    gi = int(np.searchsorted(st["groups"], g))
    ny, nx = f.tiles
    lo = f.lo[sl]
    hole = lo >= g + 2
    if not hole.any():
        return None
    ys, xs = slice(max(ty - 1, 0), ty + 2), slice(max(tx - 1, 0), tx + 2)
    wy = _tile_weights(ny, f.tile, ty, lo.shape[0])[:, (0 if ty > 0 else 1):(3 if ty < ny - 1 else 2)]
    wx = _tile_weights(nx, f.tile, tx, lo.shape[1])[:, (0 if tx > 0 else 1):(3 if tx < nx - 1 else 2)]
    def ratio(num, den):
        d = wy @ den[ys, xs, gi] @ wx.T
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(d > 0, (wy @ num @ wx.T) / np.where(d > 0, d, 1.0), 0.0)

    rho = ratio(st["S"][ys, xs, gi], st["A"])
    light = np.stack([ratio(st["L"][ys, xs, gi][..., c], st["A"]) for c in range(st["L"].shape[-1])])
    rho1 = ratio(st["S1"][ys, xs, gi], st["A1"]) if f.has_alpha else rho
    return rho, light, hole, rho1


#: a node whose kernels reach more than this many pixels is blurred at a lower resolution (module notes)
LOW_RES_RADIUS = 6
#: the fewest low-resolution pixels a side of the tiles a node is blurred in
MIN_CORNER_STEP = 16
#: kernels up to this radius (low-resolution px) are applied by a direct sum, larger ones by FFT
DIRECT_RADIUS = 2
#: tiles blurred in one batch of FFTs
_BATCH = 16


def _scale(radius: int, tile: int) -> int:
    """The resolution divisor of a node whose largest kernel has ``radius`` px: a power of two
    bringing the radius down to about :data:`LOW_RES_RADIUS`, at most the tile."""
    s = 1
    while radius / s > LOW_RES_RADIUS and 2 * s <= tile:
        s *= 2
    return s


def _sources(f: Frame, n: int, tiles, box, s: int) -> dict:
    """The planes node n receives (module notes) over ``box`` (y0, y1, x0, x1 of the padded frame,
    multiples of s), summed over s x s blocks: V, G (c, h, w) light (before the transmission), A, U
    coverage, and A1, U1 with alpha; G only when a fill brings light."""
    y0, y1, x0, x1 = box
    H, W = f.lo.shape
    ya, xa = max(y0, 0), max(x0, 0)  # the box may reach past the padded frame (its blocks start at the picture's edge)
    sub = (slice(ya, min(y1, H)), slice(xa, min(x1, W)))
    lo, tt, a, ins = f.lo[sub], f.t[sub], f.a[sub], f.inside[sub]  # the margin sends nothing (module notes)
    one = np.float32(1.0)
    share_lo = np.where((lo == n) & ins, one - tt, np.float32(0.0))
    share_up = np.where((lo == n - 1) & ins, tt, np.float32(0.0))
    planes = {"V": (share_lo + share_up) * f.colour[(slice(None),) + sub]}
    if f.has_alpha:
        planes.update(A=share_lo * a, U=share_up * a, A1=share_lo, U1=share_up)
    else:  # an opaque picture: coverage 1 (frame_of), so A and U are the shares themselves
        planes.update(A=share_lo, U=share_up)
    for ty, tx, fill in tiles:
        got = _fill(f, ty, tx, n, f.tile_slice(ty, tx)) if fill else None
        if got is None:
            continue
        rho, fl, hole, rho1 = got
        sl = f.tile_slice(ty, tx)
        dst = (slice(sl[0].start - ya, sl[0].start - ya + rho.shape[0]), slice(sl[1].start - xa, sl[1].start - xa + rho.shape[1]))
        hole = hole & f.inside[sl]
        behind = np.where(hole, f.a[sl], 0.0)  # the fill lies behind the nearer pixels' coverage
        if "G" not in planes:
            planes["G"] = np.zeros_like(planes["V"])
        planes["G"][(slice(None),) + dst] += behind * fl
        planes["A"][dst] += behind * rho
        if f.has_alpha:
            planes["A1"][dst] += hole * rho1
    shape = (y1 - y0, x1 - x0)
    out = {}
    for k, v in planes.items():
        if v.shape[-2:] != shape:
            full = np.zeros(v.shape[:-2] + shape, np.float32)
            full[..., ya - y0:ya - y0 + v.shape[-2], xa - x0:xa - x0 + v.shape[-1]] = v
            v = full
        out[k] = _block_sum(v, s)
    return out


def _block_sum(a: np.ndarray, s: int) -> np.ndarray:
    """Sums over s x s blocks (the last two axes; their lengths are multiples of s)."""
    while s > 1:  # halve each axis in turn: strided adds are cheaper than a reduction over a reshape
        a = a[..., 0::2, :] + a[..., 1::2, :]
        a = a[..., 0::2] + a[..., 1::2]
        s //= 2
    return a


def _kernel_at_scale(k: np.ndarray, s: int) -> np.ndarray:
    """A kernel (unit sum per channel) for a grid s times coarser. Each fine pixel's share goes to the
    four nearest coarse pixels bilinearly (a tent: the sum and the centroid are kept), its offset d
    first mapped to M d, M = V diag(c) V^T on the kernel's principal axes V, so that the blur the
    coarse grid adds (the sources summed over s x s blocks: s^2 / 12 per axis; this tent: s^2 / 6;
    the bilinear return to full resolution: s^2 / 6) leaves the kernel's covariance as it was:
    c_i^2 = 1 - (5 s^2 / 12) / lambda_i (at least 1/4), lambda_i its principal variances."""
    if s == 1:
        return k
    r = k.shape[0] // 2
    m00, m01, m11 = _scale_map(k[..., k.shape[2] // 2].astype(float), s)
    ys, xs = np.nonzero(k.any(axis=2) if k.shape[2] > 1 else k[..., 0])  # the lit pixels (the rest add nothing)
    xo, yo = xs - float(r), ys - float(r)
    px = (m00 * xo + m01 * yo) / s  # coarse-pixel coordinates of each fine pixel
    py = (m01 * xo + m11 * yo) / s
    R = int(math.ceil(max(np.abs(px).max(), np.abs(py).max()))) + 1
    n = 2 * R + 1
    x0, y0 = np.floor(px), np.floor(py)
    fx, fy = px - x0, py - y0
    at = (y0.astype(np.int64) + R) * n + (x0.astype(np.int64) + R)
    idx = np.concatenate([at, at + 1, at + n, at + n + 1])  # the four coarse pixels around each fine one
    gx, gy = 1.0 - fx, 1.0 - fy
    w = np.concatenate([gy * gx, gy * fx, fy * gx, fy * fx])
    out = np.empty((n, n, k.shape[2]), np.float32)
    for ch in range(k.shape[2]):
        v = k[ys, xs, ch]
        out[..., ch] = np.bincount(idx, weights=w * np.concatenate([v, v, v, v]), minlength=n * n).reshape(n, n)
    return _trim_kernel(out)


def _scale_map(m: np.ndarray, s: int) -> tuple[float, float, float]:
    """M (m00, m01, m11; symmetric) of :func:`_kernel_at_scale` for the light ``m`` (2r + 1, 2r + 1):
    its covariance from the row and column sums, and V diag(c) V^T in closed form for a 2 x 2
    symmetric matrix (c_- I + (c_+ - c_-) P_+, P_+ = (C - lambda_- I) / (lambda_+ - lambda_-), the
    projector on the larger axis)."""
    r = m.shape[0] // 2
    o = np.arange(-r, r + 1, dtype=float)
    col, row = m.sum(axis=0), m.sum(axis=1)  # the light of each column (x) and row (y)
    t = col.sum()
    dx, dy = o - (col * o).sum() / t, o - (row * o).sum() / t
    vxx, vyy = (col * dx * dx).sum() / t, (row * dy * dy).sum() / t
    vxy = ((m * dx).sum(axis=1) * dy).sum() / t
    half, disc = 0.5 * (vxx + vyy), math.hypot(0.5 * (vxx - vyy), vxy)

    def c(lam):
        return math.sqrt(min(max(1.0 - (5.0 * s * s / 12.0) / max(lam, 1e-12), 0.25), 1.0))

    hi, lo = c(half + disc), c(half - disc)
    if not disc > 1e-12 * half:  # round: M = c I
        return hi, 0.0, hi
    a = (hi - lo) / (2.0 * disc)
    return lo + a * (vxx - half + disc), a * vxy, lo + a * (vyy - half + disc)


def _trim_kernel(k: np.ndarray) -> np.ndarray:
    """``k`` cut to the smallest centred square holding all its light."""
    r = k.shape[0] // 2
    ys, xs = np.nonzero(k.sum(axis=2))
    if len(ys) == 0:
        return k[r:r + 1, r:r + 1]
    e = int(max(np.abs(ys - r).max(), np.abs(xs - r).max()))
    return k[r - e:r + e + 1, r - e:r + e + 1]


def blur_layer(f: Frame, cache, n: int, tiles) -> dict | None:
    """Node n blurred (module notes): its sources summed into s x s blocks (s from its kernels'
    size: a large blur needs no full resolution), times the transmission, split among the corners
    of a grid of s * tile pixels (bilinear weights), each corner's part convolved with the kernel
    at that corner, so every pixel's kernel is the bilinear blend of its four corners' and changes
    smoothly (no seams at tile borders); then back to full resolution (bilinear, light kept).
    Returns the planes over a box of the padded frame, the box and the largest kernel radius; None
    if the node receives nothing."""
    if not tiles:
        return None
    H, W = f.lo.shape
    s, step, (y0, y1, x0, x1) = layer_grid(f, cache.camera, n, tiles)
    low = _sources(f, n, tiles, (y0, y1, x0, x1), s)
    T = _transmission_blocks(f, cache, n, y0, x0, low["A"].shape, s)
    T = np.moveaxis(T, 2, 0)  # (channels, h, w), as the light planes
    low["V"] = low["V"] * T
    if "G" in low:
        low["G"] = low["G"] * T
    out, r = _corners(f, cache, n, low, s, step, (y0, x0))
    return _to_full(out, s, (y0, x0), r, H, W)


def layer_grid(f: Frame, cam, n: int, tiles):
    """How node n is blurred: its resolution divisor s (from the thin-lens blur there, along the
    narrower meridian of an anamorphic's oval: a power of two bringing the kernel's radius to about
    :data:`LOW_RES_RADIUS`), the low-res pixels per tile side and the box (y0, y1, x0, x1 of the
    padded frame) its tiles' sources are summed over."""
    t = f.tile
    radius = 0.55 * float(cam.blur_px_at(n)) * cam.blur_per_u_minor / cam.blur_per_u + 1.0
    s = _scale(radius, t)
    step = max(t // s, MIN_CORNER_STEP)
    m, H, W = f.margin, f.lo.shape[0], f.lo.shape[1]
    # the blocks start at the picture's edge, so that none straddles it
    y0 = m + (min(ty for ty, _, _ in tiles) * t - m) // s * s
    x0 = m + (min(tx for _, tx, _ in tiles) * t - m) // s * s
    y1 = m - (-(min((max(ty for ty, _, _ in tiles) + 1) * t, H) - m) // s) * s
    x1 = m - (-(min((max(tx for _, tx, _ in tiles) + 1) * t, W) - m) // s) * s
    return s, step, (y0, y1, x0, x1)


def layer_corners(f: Frame, cam, n: int, tiles) -> tuple[np.ndarray, np.ndarray]:
    """The display positions (x, y) of every corner of node n's blur grid (:func:`layer_grid`)."""
    s, step, (y0, y1, x0, x1) = layer_grid(f, cam, n, tiles)
    S = s * step
    ys = f.origin[1] + np.arange(y0, y1 + S, S)
    xs = f.origin[0] + np.arange(x0, x1 + S, S)
    return xs, ys


def _transmission_blocks(f: Frame, cache, n: int, y0: int, x0: int, shape, s: int) -> np.ndarray:
    """T at the centres of the s x s blocks of a box at (y0, x0) of the padded frame: (h, w, channels)."""
    h, w = shape
    ys = f.origin[1] + y0 + (np.arange(h) + 0.5) * s
    xs = f.origin[0] + x0 + (np.arange(w) + 0.5) * s
    yy, xx = np.meshgrid(ys, xs, indexing="ij")
    return cache.transmission(xx, yy, n)


def _corners(f: Frame, cache, n: int, low: dict, s: int, t: int, origin):
    """The low-resolution planes blurred tile by tile (tiles of ``t`` low-res pixels), each pixel
    with the bilinear blend of its tile's four corner kernels: ``K = Kc + xi Kx + eta Ky + xi eta
    Kxy`` (xi, eta in -1/2..1/2 across the tile), so a tile is four convolutions (of the planes and
    of xi, eta and xi eta times them), summed in the Fourier domain; one where its corners' kernels
    agree within :data:`SAME_KERNEL`. Neighbouring tiles share their corners: the kernel is
    continuous across tile borders (no seams). Tiles are batched by the size of their own kernels.
    Returns the blurred planes over the box grown by the largest kernel radius R, and R."""
    h, w = low["A"].shape
    c = f.colour.shape[0]
    cover = [k for k in ("A", "U", "A1", "U1") if k in low]
    light = low["V"]
    g = low.get("G")
    cov = np.stack([low[k] for k in cover])
    kern, groups = {}, {}
    lit = _tiles_lit([cov, light] + ([g] if g is not None else []), t)
    lit_g = _tiles_lit([g], t) if g is not None else None
    for ty in range(-(-h // t)):
        for tx in range(-(-w // t)):
            if not lit[ty, tx]:
                continue
            corners = ((ty, tx), (ty, tx + 1), (ty + 1, tx), (ty + 1, tx + 1))
            for cy, cx in corners:
                if (cy, cx) not in kern:
                    pos = (f.origin[0] + origin[1] + cx * t * s, f.origin[1] + origin[0] + cy * t * s)
                    kern[(cy, cx)] = cache.scaled_kernel(pos[0], pos[1], n, s, _kernel_at_scale)
            r = max(kern[cn].shape[0] for cn in corners) // 2
            key = (lit_g is not None and bool(lit_g[ty, tx]), _varies(kern, ty, tx), r + r % 2)  # radii batched in pairs
            groups.setdefault(key, []).append((ty, tx))
    R = max(k for _, _, k in groups)
    H2, W2 = -(-h // t) * t, -(-w // t) * t  # whole tiles: the last row and column padded with zeros
    out = {"V": np.zeros((c, H2 + 2 * R, W2 + 2 * R), np.float32),
           "cov": np.zeros((len(cover), H2 + 2 * R, W2 + 2 * R), np.float32)}
    if g is not None:
        out["G"] = np.zeros_like(out["V"])
    padded: dict = {}
    for (with_g, varies, r), tiles in groups.items():
        names = ["V"] + (["G"] if with_g else []) + cover
        stack = np.concatenate([light] + ([g] if with_g else []) + [cov], axis=0)
        if stack.shape[1:] != (H2, W2):
            stack = np.pad(stack, ((0, 0), (0, H2 - h), (0, W2 - w)))
        for b in range(0, len(tiles), _BATCH):
            res = _blur_tiles(stack, tiles[b:b + _BATCH], kern, padded, t, r, names, c, varies)
            for i, (ty, tx) in enumerate(tiles[b:b + _BATCH]):
                box = (slice(ty * t + R - r, ty * t + R + t + r), slice(tx * t + R - r, tx * t + R + t + r))
                out["V"][(slice(None),) + box] += res[i, :c]
                if with_g:
                    out["G"][(slice(None),) + box] += res[i, c:2 * c]
                out["cov"][(slice(None),) + box] += res[i, -len(cover):]
    cut = (slice(None), slice(0, h + 2 * R), slice(0, w + 2 * R))
    planes = {k: np.maximum(out[k][cut], 0.0) for k in ("V", "G") if k in out}  # (c, h, w)
    for i, k in enumerate(cover):
        planes[k] = np.maximum(out["cov"][i][cut[1:]], 0.0)
    return planes, R


def _tiles_lit(planes, t: int) -> np.ndarray:
    """(tiles down, tiles across): whether any of ``planes`` ((k, h, w) arrays) is non-zero in each t x t tile."""
    nz = np.zeros(planes[0].shape[1:], bool)
    for p in planes:
        nz |= (p != 0).any(axis=0)
    h, w = nz.shape
    ny, nx = -(-h // t), -(-w // t)
    if (ny * t, nx * t) != (h, w):
        nz = np.pad(nz, ((0, ny * t - h), (0, nx * t - w)))
    return nz.reshape(ny, t, nx, t).any(axis=(1, 3))


#: a tile whose corner kernels differ by less than this (sum of absolute differences) is blurred
#: with their mean alone
SAME_KERNEL = 2e-3


def _varies(kern: dict, ty: int, tx: int) -> bool:
    """Whether tile (ty, tx)'s corner kernels differ (:data:`SAME_KERNEL`)."""
    ks = [kern[(ty, tx)], kern[(ty, tx + 1)], kern[(ty + 1, tx)], kern[(ty + 1, tx + 1)]]
    if len({k.shape for k in ks}) > 1:
        return True
    return any(float(np.abs(k - ks[0]).sum()) > SAME_KERNEL * k.shape[2] for k in ks[1:])


def _blur_tiles(stack, tiles, kern, padded, t, r, names, c, varies) -> np.ndarray:
    """(tiles, planes, t + 2r, t + 2r): the tiles of ``stack`` blurred (:func:`_corners`); ``padded``
    memoises the corner kernels padded to radius r."""
    ramp = ((np.arange(t) + 0.5) / t - 0.5).astype(np.float32)
    blocks = np.stack([stack[:, ty * t:(ty + 1) * t, tx * t:(tx + 1) * t] for ty, tx in tiles])  # (k, P, t, t)
    for ty, tx in tiles:
        for cn in ((ty, tx), (ty, tx + 1), (ty + 1, tx), (ty + 1, tx + 1)):
            if (cn, r) not in padded:
                padded[(cn, r)] = _pad_kernel(kern[cn], r)
    kb = _terms(padded, tiles, r, varies)  # (k, 4 or 1, channels, n, n)
    if varies:
        bx = blocks * ramp[None, None, None, :]
        terms = np.stack([blocks, bx, blocks * ramp[None, None, :, None], bx * ramp[None, None, :, None]], axis=1)
    else:
        terms = blocks[:, None]
    plane_of = _kernel_index(names, c, kb.shape[2])
    if r <= DIRECT_RADIUS:
        return _direct_sum(terms, kb[:, :, plane_of])
    size = fast_len(t + 2 * r)
    spec = np.fft.rfft2(terms, s=(size, size))
    ks = np.fft.rfft2(kb, s=(size, size))
    spec *= ks if ks.shape[2] == 1 else ks[:, :, plane_of]  # one kernel channel: broadcast over the planes
    return np.fft.irfft2(spec.sum(axis=1), s=(size, size))[..., :t + 2 * r, :t + 2 * r]


def _direct_sum(terms: np.ndarray, kers: np.ndarray) -> np.ndarray:
    """Sum over j of the full convolutions of ``terms[:, j]`` (tiles, planes, t, t) with ``kers[:, j]``
    (tiles, planes, n, n), by direct sums (all the batch's tiles at once): (tiles, planes, t + n - 1,
    t + n - 1)."""
    k, m, p, h, w = terms.shape
    n = kers.shape[-1]
    out = None
    for j in range(m):
        part = np.zeros((k, p, h + n - 1, w + n - 1), dtype=np.float32)
        for dy in range(n):
            for dx in range(n):
                cf = kers[:, j, :, dy, dx]
                if cf.any():
                    part[:, :, dy:dy + h, dx:dx + w] += cf[:, :, None, None] * terms[:, j]
        out = part if out is None else out + part
    return out


def _terms(padded: dict, tiles, r: int, varies: bool = True) -> np.ndarray:
    """(tiles, 4, channels, 2r + 1, 2r + 1): the kernels Kc, Kx, Ky, Kxy of each tile (ty, tx) (see
    :func:`_corners`); Kc alone (tiles, 1, ...) unless ``varies``."""
    k = np.stack([[padded[(cn, r)] for cn in ((ty, tx), (ty, tx + 1), (ty + 1, tx), (ty + 1, tx + 1))]
                  for ty, tx in tiles])  # (tiles, 4 corners, n, n, channels)
    k00, k01, k10, k11 = k[:, 0], k[:, 1], k[:, 2], k[:, 3]
    kc = 0.25 * (k00 + k01 + k10 + k11)
    if not varies:
        return np.moveaxis(kc[:, None], 4, 2).astype(np.float32)
    kx = 0.5 * (k01 + k11 - k00 - k10)
    ky = 0.5 * (k10 + k11 - k00 - k01)
    kxy = k00 + k11 - k01 - k10
    return np.moveaxis(np.stack([kc, kx, ky, kxy], axis=1), 4, 2).astype(np.float32)


def _kernel_index(names, c: int, channels: int) -> np.ndarray:
    """For each plane of ``names``, the kernel channel it is blurred with: its own for light (the
    middle one beyond the kernel's channels, or for a mono image), the middle one for coverage."""
    mid = channels // 2
    own = [i if c >= channels > 1 and i < channels else mid for i in range(c)]
    out = []
    for name in names:
        out += own if name in ("V", "G") else [mid]
    return np.array(out)


def _pad_kernel(k: np.ndarray, r: int) -> np.ndarray:
    """``k`` (2q + 1, 2q + 1, channels) centred in zeros of radius r >= q."""
    p = r - k.shape[0] // 2
    if not p:
        return k
    out = np.zeros((2 * r + 1, 2 * r + 1) + k.shape[2:], k.dtype)
    out[p:p + k.shape[0], p:p + k.shape[1]] = k
    return out


def _to_full(planes: dict, s: int, origin, r: int, H: int, W: int) -> dict:
    """Low-resolution blurred planes back on the padded frame (bilinear; each block's light kept),
    cut to the frame: the planes, their box and the kernel radius in full-resolution pixels."""
    y0, x0 = origin
    if s > 1:
        planes = {k: _upsample(v, s) for k, v in planes.items()}
    R = r * s
    h, w = planes["A"].shape
    oy, ox = y0 - R, x0 - R
    ya, xa, yb, xb = max(oy, 0), max(ox, 0), min(oy + h, H), min(ox + w, W)
    lay = {k: v[..., ya - oy:yb - oy, xa - ox:xb - ox] for k, v in planes.items()}
    lay.setdefault("G", None)
    lay["box"] = (slice(ya, yb), slice(xa, xb))
    lay["radius"] = R
    return lay


def _upsample(a: np.ndarray, s: int, into: np.ndarray | None = None) -> np.ndarray:
    """(..., h, w) values per s x s block to (..., h s, w s) values per pixel: bilinear between block
    centres (clamped at the ends), divided by s^2, so that each block's sum is kept. The last two
    axes are the picture's (colour planes first: every pass runs over whole rows), one plane at a
    time (a smaller working set: 1.2-2x less CPU for three); ``into``: the array to write."""
    a = np.asarray(a, dtype=np.float32)
    out = np.empty(a.shape[:-2] + (a.shape[-2] * s, a.shape[-1] * s), np.float32) if into is None else into
    if a.ndim > 2:
        for i in np.ndindex(a.shape[:-2]):
            _upsample(a[i], s, out[i])
        return out
    for axis in (0, 1):
        def cut(part, axis=axis):
            return (slice(None),) * axis + (part,)

        prev = np.concatenate([a[cut(slice(0, 1))], a[cut(slice(0, -1))]], axis=axis)
        nxt = np.concatenate([a[cut(slice(1, None))], a[cut(slice(-1, None))]], axis=axis)
        res = np.empty((a.shape[0] * s, a.shape[1]), np.float32) if axis == 0 else out
        k = np.float32(1 / s) if axis == 0 else np.float32(1)  # 1/s^2 at the first pass: exact, a power of 2
        for q in range(s):
            d = np.float32((q + 0.5) / s - 0.5)  # the pixel's offset from its block's centre, in blocks
            o = res[cut(slice(q, None, s))]
            np.multiply(a, (1 - abs(d)) * k * k, out=o)
            o += (abs(d) * k * k) * (prev if d < 0 else nxt)
        a = res
    return out


def fast_len(n: int) -> int:
    """The smallest 2^a 3^b 5^c >= n (a quick FFT length)."""
    best = 1 << (n - 1).bit_length()
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            q = p35
            while q < n:
                q *= 2
            best = min(best, q)
            p35 *= 3
        p5 *= 5
    return best
