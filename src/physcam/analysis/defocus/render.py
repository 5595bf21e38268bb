"""Depth of field from the real lens, applied to a pinhole render with depth (``physcam defocus``).

Method (docs/defocus.md): each pixel is a point of the scene, at the inverse depth ``u`` its
depth pass gives; it is split linearly in ``u`` between the two bracketing depth nodes of
:mod:`physcam.analysis.defocus.kernels` (so the blur grows smoothly, with no banding). The
picture is cut into depth **layers**, one per node, and each layer is *scattered*: every
``tile`` x ``tile`` block of it is convolved (FFT; a direct sum for kernels up to 7 px) with the
lens's own PSF traced for that tile's centre and that node's depth (field- and depth-dependent:
size, cat's eye, iris, vignetting; per wavelength with dispersion), colour and coverage (alpha)
alike. The blurred layers are composited **back to front** with "over",
``C = C_k + (1 - A_k) C``, ``A = A_k + (1 - A_k) A``, so a blurred foreground covers what lies
behind it in proportion to its own blurred coverage (occlusion at depth edges), and the result is
``C / A`` (Kraus and Strengert, "Depth-of-Field Rendering by Pyramidal Image Processing",
Eurographics 2007, section 3: layers, matting, normalisation).

Each pixel belongs to the **group** of its lower node; a group's coverage (alpha), like its light,
is shared between its two nodes' layers, and a group is composited once both are blurred (so a
surface between two nodes does not partly hide itself). Behind a nearer group, a layer is
continued with its own mean colour over the tile at alpha 1 (in tiles where it has pixels), so
the hole a small bright foreground leaves in the background is filled with the background, not
renormalised away (that made a bokeh 16 % too bright and 10 % too narrow). A renderer's depth pass
gives an antialiased edge pixel the depth of one side only: ``edge_px`` (:func:`near_edges`) gives
pixels next to a nearer one its depth, so a bright foreground's edge light is blurred with it.

Known limits: (1) what the pinhole did not see (the background behind a foreground edge) is not
invented: it is the background layer's mean colour over the tile; where no layer is behind
(outside the tiles the background has pixels in) the result is renormalised by ``C / A``; (2) within one layer there is no self-occlusion;
(3) the kernel is constant over a tile (field sampled every ``tile`` px) and linear in ``u``
between nodes ``step_px + step_rel b`` of blur apart; (4) light from outside the frame is missing, so the
frame's edge is renormalised like (1); (5) the image must be linear light (scene-referred EXR).

Cost: each (tile, layer) pair that holds pixels costs one FFT convolution of
(tile + 2R)^2 (R the kernel radius), ``channels + 2`` images: about
``pairs x (tile + 2R)^2 log(tile + 2R) x (channels + 3)``; compositing costs the layers' blurred
areas. Kernels are traced once per (tile, node) and kept in the :class:`KernelCache`.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import InputError
from .kernels import DIRECT_BLUR_PX, DefocusCamera, KernelCache
from .layers import _upsample, blur_layer, frame_of, layer_corners, layer_grid, layer_pairs

__all__ = ["DEPTH_KINDS", "DEPTH_UNITS_MM", "inverse_depth", "near_edges", "defocus"]

#: planar: along the optical axis from the plane of the entrance pupil (Blender's Z pass of a camera
#: at the pupil); ray: along the pixel's ray from the pupil's centre; inverse: 1 / planar (Nuke's depth.Z)
DEPTH_KINDS = ("planar", "ray", "inverse")
DEPTH_UNITS_MM = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4, "ft": 304.8}


def inverse_depth(depth, camera: DefocusCamera, *, kind: str = "planar", unit: str = "m",
                  origin=(0, 0)) -> np.ndarray:
    """Inverse planar depth ``u`` (1/mm, 0 at infinity) of each pixel of a depth pass.

    ``depth`` (h, w) in ``unit`` (``inverse``: 1/``unit``), ``origin`` the data window's corner in
    the display window (x, y). A value of 1e9 m or more (Blender's empty background: 1e10) is
    infinity. NaN, negative and zero depths, and points inside the lens, are refused."""
    if kind not in DEPTH_KINDS:
        raise InputError(f"the depth kind must be one of {', '.join(DEPTH_KINDS)}, got {kind!r}")
    if unit not in DEPTH_UNITS_MM:
        raise InputError(f"the depth unit must be one of {', '.join(DEPTH_UNITS_MM)}, got {unit!r}")
    z = np.asarray(depth, dtype=np.float64)
    if z.ndim != 2:
        raise InputError(f"the depth pass must be one channel (h, w), got shape {z.shape}")
    bad = ~np.isfinite(z) & ~(np.isposinf(z) & (kind != "inverse"))
    if bad.any():
        y, x = np.argwhere(bad)[0]
        raise InputError(f"the depth pass has {int(bad.sum())} NaN or infinite value(s), the first at pixel "
                         f"({x}, {y}): every pixel needs a depth")
    neg = z < 0 if kind == "inverse" else z <= 0
    if neg.any():
        y, x = np.argwhere(neg)[0]
        raise InputError(f"the depth pass has {int(neg.sum())} {'negative' if kind == 'inverse' else 'zero or negative'} "
                         f"value(s), the first {z[y, x]:g} at pixel ({x}, {y}): depths lie in front of the camera")
    scale = DEPTH_UNITS_MM[unit]
    with np.errstate(divide="ignore", over="ignore"):
        if kind == "inverse":
            u = z / scale
        else:
            u = np.where(z * scale >= 1e12, 0.0, 1.0 / (z * scale))
            if kind == "ray":
                h, w = z.shape
                xs = (origin[0] + np.arange(w) + 0.5 - camera.width / 2) * camera.pitch_mm
                ys = (camera.height / 2 - origin[1] - np.arange(h) - 0.5) * camera.pitch_mm
                f = camera.pinhole_mm
                u = u * np.sqrt(f * f + xs[None, :] ** 2 + ys[:, None] ** 2) / f  # 1/planar = (1/ray) / cos
    near = 1.0 / max(camera.front_from_film_mm - camera.pupil_from_film_mm + 1.0, 1.0)
    if (u > near).any():
        y, x = np.argwhere(u > near)[0]
        raise InputError(f"pixel ({x}, {y}) is {1 / u[y, x]:.4g} mm from the entrance pupil, inside or against the "
                         f"lens (its front is {1 / near - 1:.4g} mm from the pupil): check the depth unit (--depth-unit)")
    return u


def near_edges(u: np.ndarray, px: int = 1) -> np.ndarray:
    """``u`` with each pixel given the nearest (largest) inverse depth within ``px`` pixels (a
    (2 px + 1)^2 max filter). A renderer's depth pass gives an antialiased edge pixel, which holds
    light from both sides of a depth edge, the depth of one side only (Cycles: often the far one),
    so a bright foreground's edge light would be blurred as background; taking the nearer depth
    blurs it with the foreground instead (the background's part of that pixel then moves with the
    foreground: an error of at most ``px`` pixels along the edge)."""
    if not isinstance(u, np.ndarray) or u.ndim != 2:
        from ...errors import WrongTypeError

        raise WrongTypeError(f"near_edges takes an (h, w) numpy array of inverse depths, got {u!r:.60}")
    if px <= 0:
        return u
    h, w = u.shape
    pad = np.pad(u, px, mode="edge")
    out = u.copy()
    for dy in range(2 * px + 1):
        for dx in range(2 * px + 1):
            np.maximum(out, pad[dy:dy + h, dx:dx + w], out=out)
    return out


def _node_weights(u: np.ndarray, cam: DefocusCamera):
    """Each pixel's lower depth node and its weight on the node above (linear in u)."""
    n_far = cam.node_far()
    lo = np.maximum(np.floor(cam.node_index(u) + 1e-9), n_far).astype(np.int64)
    first = int(lo.min())
    table = cam.node_u(np.arange(first, int(lo.max()) + 2))  # the nodes' u, looked up (not per pixel)
    u_lo, u_hi = table[lo - first], table[lo - first + 1]
    w_hi = np.clip((u - u_lo) / (u_hi - u_lo), 0.0, 1.0)
    return lo, w_hi


def _check(image, u, edge_px, alpha_channel):
    img = np.asarray(image, dtype=np.float32)
    if img.ndim == 2:
        img = img[..., None]
    if img.ndim != 3 or img.shape[:2] != np.shape(u):
        raise InputError(f"the depth pass is {np.shape(u)[::-1]} pixels and the image {img.shape[:2][::-1]}: "
                         "they must be the same size")
    if not np.isfinite(img).all():
        raise InputError("the image has NaN or infinite pixels: defocus needs finite linear light")
    if isinstance(edge_px, bool) or not isinstance(edge_px, (int, np.integer)) or not 0 <= edge_px <= 8:
        raise InputError(f"edge_px must be a whole number of pixels from 0 to 8, got {edge_px!r}")
    if alpha_channel is not None:
        if isinstance(alpha_channel, bool) or not isinstance(alpha_channel, (int, np.integer)) or \
                not 0 <= alpha_channel < img.shape[2] or img.shape[2] < 2:
            raise InputError(f"alpha_channel must index one of the image's {img.shape[2]} channels beside a colour one, "
                             f"got {alpha_channel!r}")
        a = img[..., alpha_channel]
        if (a < -1e-6).any() or (a > 1 + 1e-6).any():
            raise InputError("the alpha channel must lie in 0..1 (premultiplied colour over coverage)")
    if (img < 0).any():
        raise InputError("the image has negative pixels: defocus needs linear light, 0 or more")
    return img


def defocus(image, u, cache: KernelCache, *, origin=(0, 0), edge_px: int = 1, alpha_channel: int | None = None,
            progress=None) -> np.ndarray:
    """``image`` (h, w, channels; linear light, colour premultiplied by alpha) defocused through the
    cache's camera, given each pixel's inverse planar depth ``u`` (1/mm, :func:`inverse_depth`).
    ``origin``: the data window's corner in the display window; ``edge_px``: depth edges widened
    toward the far side by this many pixels (:func:`near_edges`; 0: the depth as given);
    ``alpha_channel``: the index of the image's coverage channel (None: an opaque picture), which
    comes back as the defocused coverage. Returns a float32 array of the image's shape (method and
    limits in the module notes)."""
    img = _check(image, u, edge_px, alpha_channel)
    cam = cache.camera
    h, w, c = img.shape
    lo, t = _node_weights(near_edges(np.asarray(u, dtype=np.float64), int(edge_px)), cam)
    keep = [i for i in range(c) if i != alpha_channel]
    a = np.clip(img[..., alpha_channel], 0.0, 1.0) if alpha_channel is not None else np.ones((h, w), np.float32)
    groups = np.unique(lo)
    nodes = np.unique(np.concatenate([groups, groups + 1]))
    margin = int(math.ceil(0.75 * float(np.max(cam.blur_px_at(nodes))))) + 4
    f = frame_of(img[..., keep], a, lo, t, margin, cam.tile, origin, alpha_channel is not None)
    pairs = layer_pairs(f)
    _prepare(cache, f, pairs, progress)
    colour, cover = _composite(f, cache, pairs, progress)
    m = f.margin
    out = np.empty_like(img)
    out[..., keep] = np.moveaxis(colour[:, m:m + h, m:m + w], 0, 2)
    if alpha_channel is not None:
        out[..., alpha_channel] = cover[m:m + h, m:m + w]
    return out if np.ndim(image) == 3 else out[..., 0]


def _prepare(cache, f, pairs, progress) -> None:
    """Trace (or read) every node kernel the layers' blur grids blend from, in one batch."""
    cols, rows = cache.grid
    needed, direct = set(), []
    for n, tiles in pairs.items():
        xs, ys = layer_corners(f, cache.camera, n, tiles)
        if float(cache.camera.blur_px_at(n)) <= DIRECT_BLUR_PX:
            direct += _used_corners(f, cache.camera, n, tiles, xs, ys)
            continue
        found = []
        for nodes, pos in ((cols, xs), (rows, ys)):
            i = np.clip(np.searchsorted(nodes, pos, side="right") - 1, 0, len(nodes) - 2)
            found.append(np.unique(np.concatenate([i, i + 1])))
        needed |= {(int(c), int(r), int(n)) for c in found[0] for r in found[1]}
    cache.prepare(needed, progress, direct)


def _used_corners(f, cam, n, tiles, xs, ys) -> list[tuple[float, float, int]]:
    """The corners (x, y, n) of node n's blur grid (columns ``xs``, rows ``ys``) within one grid step
    of one of its tiles: the only ones whose kernels the layer reads."""
    s, step, _ = layer_grid(f, cam, n, tiles)
    S, t = s * step, f.tile
    ty = np.array([a for a, _, _ in tiles])[:, None]
    tx = np.array([b for _, b, _ in tiles])[:, None]
    near_x = (f.origin[0] + tx * t < xs[None, :] + S) & (f.origin[0] + (tx + 1) * t > xs[None, :] - S)
    near_y = (f.origin[1] + ty * t < ys[None, :] + S) & (f.origin[1] + (ty + 1) * t > ys[None, :] - S)
    used = near_y.T.astype(np.int64) @ near_x.astype(np.int64)  # (rows, columns): tiles near both
    return [(float(xs[i]), float(ys[j]), int(n)) for j, i in zip(*np.nonzero(used))]


def _composite(f, cache, pairs, progress):
    """The nodes blurred and composited near to far (module notes): the colour (c, H, W) and the coverage."""
    H, W = f.lo.shape
    c = f.colour.shape[0]
    out = np.zeros((c, H, W), dtype=np.float32)  # colour planes first (as the layers': whole rows)
    cov = np.zeros((H, W), dtype=np.float32)  # coverage of the groups composited so far
    cov1 = np.zeros((H, W), dtype=np.float32) if f.has_alpha else None
    carry = None  # (U, U1, box): the upper shares of the next farther group
    nodes = sorted(pairs, reverse=True)
    lowest = int(f.lo.min())
    fills = {n for n, tiles in pairs.items() if any(fill for _, _, fill in tiles)}
    budget = _Budget(f.lo.shape)
    for done, n in enumerate(range(nodes[0], lowest - 1, -1), 1):
        lay = _fold(f, blur_layer(f, cache, n, pairs.get(n, [])))
        group_cov = [(lay, "A")] + ([(carry, "U")] if carry is not None else [])
        if lay is not None:
            box = lay["box"]
            tr = f.inside[box] * (1.0 - np.clip(cov[box], 0.0, 1.0))
            out[(slice(None),) + box] += tr * lay["V"]
            if n in fills or n - 1 in fills:
                budget.spend(out, box, tr, lay)
        else:
            budget.carry = None
        for src, name in group_cov:
            if src is not None:
                cov[src["box"]] += src[name]
                if cov1 is not None:
                    cov1[src["box"]] += src[name + "1"]
        carry = lay
        if progress is not None and n in pairs:
            progress(done, len(nodes))
    if cov1 is None:
        return out, None
    # the coverage, made whole where the picture's pixels, opaque or not, cover the film completely
    # (the kernels of neighbouring depth layers differ, so their coverages add to 1 only nearly)
    full = np.clip(cov1, 0.0, 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        alpha = np.where(full > 0, np.clip(cov, 0.0, 1.0) / np.where(full > 0, full, 1.0), 0.0)
    return out, np.clip(alpha, 0.0, 1.0).astype(np.float32)


def _fold(f, lay):
    """The light and coverage a node sends past the picture's edge, folded back across it (a
    mirror): none is lost or made there, and a flat field stays flat to the edge (exactly where the
    kernels are symmetric across it)."""
    if lay is None:
        return None
    m = f.margin
    H, W = f.lo.shape
    ys, xs = lay["box"]
    for axis, (sl, size) in enumerate(((ys, H), (xs, W))):
        lo_out, hi_out = max(m - sl.start, 0), max(sl.stop - (size - m), 0)
        if not (lo_out or hi_out):
            continue
        for k in ("V", "G", "A", "U", "A1", "U1"):
            a = lay.get(k)
            if a is None:
                continue
            a = np.moveaxis(a, axis - 2, 0)  # a view: folding it folds the plane (its last two axes)
            n = a.shape[0]
            if lo_out:  # rows 0 .. lo_out-1 of the box lie before the picture: mirror them in
                k = min(lo_out, n - lo_out)
                a[lo_out:lo_out + k] += a[lo_out - 1:lo_out - 1 - k:-1] if lo_out - 1 - k >= 0 else a[lo_out - 1::-1][:k]
                a[:lo_out] = 0
            if hi_out:
                k = min(hi_out, n - hi_out)
                a[n - hi_out - k:n - hi_out] += a[n - hi_out:n - hi_out + k][::-1]
                a[n - hi_out:] = 0
    return lay


class _Budget:
    """The light fills may bring (module notes): each node's light lost to nearer coverage, on a grid
    of :data:`BUDGET_CELL` pixels, kept for that node's fill and what is left for the next farther
    node's (a group's light is shared between two nodes), then dropped; a fill is scaled down where,
    summed over a window twice its kernel's radius, it would bring more than that."""

    def __init__(self, shape):
        q = BUDGET_CELL
        self.shape = (-(-shape[0] // q), -(-shape[1] // q))
        self.carry = None

    def spend(self, out, box, tr, lay) -> None:
        q = BUDGET_CELL
        y0, x0 = box[0].start, box[1].start
        own = np.zeros(self.shape)
        loss = (1.0 - tr) * _channel_sum(lay["V"])
        _add_cells(own, loss, y0, x0, q)
        avail = own + (self.carry if self.carry is not None else 0.0)
        g = lay["G"]
        if g is not None:
            gc = np.zeros(self.shape)
            _add_cells(gc, tr * _channel_sum(g), y0, x0, q)
            r = max(-(-2 * lay["radius"] // q), 2)
            with np.errstate(invalid="ignore", divide="ignore"):
                scale = np.clip(np.nan_to_num(_box_sum(avail, r) / _box_sum(gc, r), posinf=0.0), 0.0, 1.0)
            cy0, cx0 = max(y0 // q - 1, 0), max(x0 // q - 1, 0)  # the box's cells and one around
            cy1, cx1 = -(-box[0].stop // q) + 1, -(-box[1].stop // q) + 1
            part = _upsample_cells(scale[cy0:cy1, cx0:cx1], q)  # the cells that exist (the last ones hold the box)
            part = part[y0 - cy0 * q: box[0].stop - cy0 * q, x0 - cx0 * q: box[1].stop - cx0 * q]  # (0, 0): (cy0 q, cx0 q)
            out[(slice(None),) + box] += (part * tr) * g
            avail = np.maximum(avail - scale * gc, 0.0)
        self.carry = np.minimum(avail, own)  # a node's loss funds its own fill and the next one's, no more


def _channel_sum(a: np.ndarray) -> np.ndarray:
    """The sum of a (c, h, w) array's colour planes, plane by plane."""
    out = a[0].copy()
    for c in range(1, a.shape[0]):
        out += a[c]
    return out


def _add_cells(cells: np.ndarray, a: np.ndarray, y0: int, x0: int, q: int) -> None:
    """Add the sums of ``a`` (placed at (y0, x0) of the frame) over q x q cells into ``cells``."""
    h, w = a.shape
    ya, xa = y0 // q * q, x0 // q * q
    p = np.zeros((-(-(y0 + h - ya) // q) * q, -(-(x0 + w - xa) // q) * q))
    p[y0 - ya:y0 - ya + h, x0 - xa:x0 - xa + w] = a
    part = p.reshape(p.shape[0] // q, q, p.shape[1] // q, q).sum(axis=(1, 3))
    cy, cx = ya // q, xa // q
    cells[cy:cy + part.shape[0], cx:cx + part.shape[1]] += part[:cells.shape[0] - cy, :cells.shape[1] - cx]


def _upsample_cells(a: np.ndarray, q: int) -> np.ndarray:
    """Values per q x q cell to values per pixel (q times the cells each way), bilinear between cell
    centres (clamped at the ends): :func:`~physcam.analysis.defocus.layers._upsample` without its
    division by q^2."""
    return _upsample(a, q) * np.float32(q * q)


#: the grid (px) the fill's light budget is summed on
BUDGET_CELL = 4


def _box_sum(a: np.ndarray, r: int) -> np.ndarray:
    """Sum of ``a`` over the (2r + 1)^2 window around each pixel (zero outside)."""
    c = np.pad(a.astype(np.float64), ((r + 1, r), (r + 1, r))).cumsum(axis=0).cumsum(axis=1)
    n = 2 * r + 1
    return c[n:, n:] - c[:-n, n:] - c[n:, :-n] + c[:-n, :-n]


