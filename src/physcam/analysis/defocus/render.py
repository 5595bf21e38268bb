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
from .kernels import DefocusCamera, KernelCache

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
    u_lo, u_hi = cam.node_u(lo), cam.node_u(lo + 1)
    w_hi = np.clip((u - u_lo) / (u_hi - u_lo), 0.0, 1.0)
    return lo, w_hi.astype(np.float32)


def _fast_len(n: int) -> int:
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


def _convolve(src: np.ndarray, ker: np.ndarray) -> np.ndarray:
    """Full 2-D convolution of each plane of ``src`` (k, h, w) with ``ker`` (n, n) or, per plane,
    (k, n, n): (k, h + n - 1, w + n - 1). Direct for small kernels, else FFT (float32)."""
    k, h, w = src.shape
    n = ker.shape[-1]
    kers = np.broadcast_to(ker, (k, n, n)) if ker.ndim == 2 else ker
    if n <= 7:
        out = np.zeros((k, h + n - 1, w + n - 1), dtype=np.float32)
        for dy in range(n):
            for dx in range(n):
                c = kers[:, dy, dx]
                if c.any():
                    out[:, dy:dy + h, dx:dx + w] += c[:, None, None] * src
        return out
    sy, sx = _fast_len(h + n - 1), _fast_len(w + n - 1)
    fs = np.fft.rfft2(src, s=(sy, sx))
    fk = np.fft.rfft2(kers if ker.ndim == 3 else ker, s=(sy, sx))
    return np.fft.irfft2(fs * fk, s=(sy, sx))[:, : h + n - 1, : w + n - 1].astype(np.float32, copy=False)


def _layer_source(img, wgt, rel):
    """Planes (colour..., alpha, alpha of the farther group) of one tile of one layer (node n).
    A pixel belongs to the **group** of its lower node (``rel`` = that node - n): its light and
    its coverage are shared between that node's layer and the next, so its group's coverage is
    (1 - w) K_lo + w K_hi, like its light. Colour: the layer's share ``wgt`` of each pixel's light.
    Alpha: the share of the pixels of group n, and 1 where a nearer group hides this layer
    (``rel`` > 0), whose colour there continues the layer's mean colour over the tile (so the hole a
    foreground leaves is not renormalised away, C / A, later). Last plane: the upper share of group
    n - 1's coverage (``rel`` = -1), added to that group's alpha before it is composited."""
    col = img * wgt[..., None]
    hidden = rel > 0
    if hidden.any():
        col = col + hidden[..., None] * (col.sum(axis=(0, 1)) / max(float(wgt.sum()), 1e-12))
    alpha = np.where(rel == 0, wgt, 0.0) + hidden
    upper = np.where(rel == -1, wgt, 0.0)
    return np.concatenate([np.moveaxis(col, 2, 0), alpha[None], upper[None]], axis=0).astype(np.float32)


def _tile_layer(img, wgt, kernel, colour_channels, rel):
    """One tile of one layer blurred: planes (colour..., alpha, farther alpha) convolved with the
    kernel; colour scaled by the transmission (vignetting), the alphas by a kernel of unit sum."""
    k = kernel.image
    tr = np.asarray(kernel.transmission, dtype=np.float32)
    g = 1 if k.shape[2] == 3 else 0
    unit = k[..., g] / tr[g] if tr[g] > 0 else np.zeros_like(k[..., g])
    c = img.shape[2]
    src = _layer_source(img, wgt, rel)
    if k.shape[2] == 1 or colour_channels < 3:
        out = _convolve(src, unit)
        out[:c] *= tr[g]
        return out
    kers = np.empty((c + 2,) + unit.shape, dtype=np.float32)
    for i in range(c):
        kers[i] = k[..., i] if i < 3 else unit * tr[g]
    kers[c] = kers[c + 1] = unit
    return _convolve(src, kers)


def _over(acc_c, acc_a, lay_c, lay_a, bb) -> None:
    """``acc`` = the layer over ``acc`` (premultiplied), in the box ``bb``."""
    a = np.clip(lay_a[bb], 0.0, 1.0)
    acc_c[bb] = lay_c[bb] + (1.0 - a)[..., None] * acc_c[bb]
    acc_a[bb] = a + (1.0 - a) * acc_a[bb]


def defocus(image, u, cache: KernelCache, *, origin=(0, 0), edge_px: int = 1, progress=None) -> np.ndarray:
    """``image`` (h, w, channels; linear light) defocused through the cache's camera, given each
    pixel's inverse planar depth ``u`` (1/mm, :func:`inverse_depth`). ``origin``: the data
    window's corner in the display window; ``edge_px``: depth edges widened toward the far side by
    this many pixels (:func:`near_edges`; 0: the depth as given). Returns a float32 array of the
    image's shape (method and limits in the module notes)."""
    img = np.asarray(image, dtype=np.float32)
    if img.ndim == 2:
        img = img[..., None]
    if img.ndim != 3 or img.shape[:2] != np.shape(u):
        raise InputError(f"the depth pass is {np.shape(u)[::-1]} pixels and the image {img.shape[:2][::-1]}: "
                         "they must be the same size")
    if not np.isfinite(img).all():
        raise InputError("the image has NaN or infinite pixels: defocus needs finite linear light")
    cam = cache.camera
    h, w, c = img.shape
    if isinstance(edge_px, bool) or not isinstance(edge_px, (int, np.integer)) or not 0 <= edge_px <= 8:
        raise InputError(f"edge_px must be a whole number of pixels from 0 to 8, got {edge_px!r}")
    lo, w_hi = _node_weights(near_edges(np.asarray(u, dtype=np.float64), int(edge_px)), cam)
    t = cam.tile
    layers: dict[int, list] = {}
    for ty in range(math.ceil(h / t)):
        for tx in range(math.ceil(w / t)):
            sl = (slice(ty * t, (ty + 1) * t), slice(tx * t, (tx + 1) * t))
            for n in np.unique(np.concatenate([lo[sl].ravel(), lo[sl].ravel() + 1])):
                wt = np.where(lo[sl] == n, 1.0 - w_hi[sl], 0.0) + np.where(lo[sl] + 1 == n, w_hi[sl], 0.0)
                if wt.max() > 1e-6:
                    layers.setdefault(int(n), []).append((tx, ty, sl, wt.astype(np.float32), lo[sl] - n))
    acc_c = np.zeros((h, w, c), dtype=np.float32)
    acc_a = np.zeros((h, w), dtype=np.float32)
    pending = None  # (node, colour, alpha, box): composited once the next node adds its coverage
    for done, n in enumerate(sorted(layers), 1):  # far (small u) first: back to front
        lay_c, lay_a, lay_u, bb = _blur_layer(img, layers[n], n, cache, origin)
        if pending is not None:
            m, pc, pa, pbb = pending
            if m == n - 1:
                pa += lay_u
                pbb = (slice(min(pbb[0].start, bb[0].start), max(pbb[0].stop, bb[0].stop)),
                       slice(min(pbb[1].start, bb[1].start), max(pbb[1].stop, bb[1].stop)))
            _over(acc_c, acc_a, pc, pa, pbb)
        pending = (n, lay_c, lay_a, bb)
        if progress is not None:
            progress(done, len(layers))
    if pending is not None:
        _over(acc_c, acc_a, pending[1], pending[2], pending[3])
    out = acc_c / np.maximum(acc_a, 1e-6)[..., None]
    return out if np.ndim(image) == 3 else out[..., 0]


def _blur_layer(img, tiles, n, cache, origin):
    """Layer ``n`` scattered tile by tile: its colour, its group's alpha, the upper share of group
    n - 1's alpha (full-frame arrays) and the box they cover."""
    h, w, c = img.shape
    lay_c = np.zeros((h, w, c), dtype=np.float32)
    lay_a = np.zeros((h, w), dtype=np.float32)
    lay_u = np.zeros((h, w), dtype=np.float32)
    y_lo, y_hi, x_lo, x_hi = h, 0, w, 0
    for tx, ty, sl, wt, rel in tiles:
        kern = cache.get(cache.node_centre(tx, ty, (h, w), origin), n)
        out = _tile_layer(img[sl], wt, kern, c, rel)
        r = kern.radius
        ya, xa = sl[0].start - r, sl[1].start - r
        yb, xb = ya + out.shape[1], xa + out.shape[2]
        cy0, cx0, cy1, cx1 = max(ya, 0), max(xa, 0), min(yb, h), min(xb, w)
        part = out[:, cy0 - ya: cy1 - ya, cx0 - xa: cx1 - xa]
        lay_c[cy0:cy1, cx0:cx1] += np.moveaxis(part[:c], 0, 2)
        lay_a[cy0:cy1, cx0:cx1] += part[c]
        lay_u[cy0:cy1, cx0:cx1] += part[c + 1]
        y_lo, y_hi, x_lo, x_hi = min(y_lo, cy0), max(y_hi, cy1), min(x_lo, cx0), max(x_hi, cx1)
    return lay_c, lay_a, lay_u, (slice(y_lo, y_hi), slice(x_lo, x_hi))
