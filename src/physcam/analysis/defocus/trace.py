"""Ray fans for :mod:`physcam.analysis.defocus.kernels`: traced in batches, interpolated in depth.

A **fan** is the light of one object point, the one the render's pinhole sees at a picture position
(a field node) at an inverse planar depth ``u`` (1/mm from the entrance pupil's plane): rays from
the point to sample points spread over a box of the entrance pupil's plane, traced by physcam's
tracer to the film. Each ray's landing point is kept as a **picture offset** (pixels, x right,
y down) from the pinhole's image of the point, with its weight ``dA cos^3(theta)``: d^2 times the
solid angle it stands for (dA the box's area per sample, d the point's depth; d^2 is left out so
that weights interpolate in depth, and cancels in a kernel's transmission, which compares fans at
one depth). A blocked ray has weight 0.

**Samples.** The box is fixed per field node (every depth uses it) and found by a pilot: a grid
over the front element's clear disk seen from the point, plus a finer grid over the paraxial
entrance pupil; the box holds every pilot ray that passed, one grid cell wider. The samples are the
first ``n`` points of one shuffled Owen-scrambled Sobol sequence (prefixes of a power of two are
stratified), mapped into the box: sample ``i`` aims at the same pupil point at every depth and is
traced at wavelength ``i mod k`` (k = 1, or 3 with dispersion).

**Depth.** A sample's offset from the pinhole image is, in Gaussian optics, its pupil point times
``f_pin (u - u_focus) / p``: linear in u (the thin-lens blur of docs/defocus.md). So a fan at an
inverse depth between two traced ones is interpolated sample by sample, linearly in u: offsets and
weights. A sample that passed at one end only (vignetting moves with depth) keeps the passing end's
offset moved by the fan's own linear map from pupil point to offset change (least squares over the
samples that passed at both ends), its weight interpolated toward 0.

Batches: every fan asked for at once is traced in chunks of :data:`CHUNK_RAYS` rays, one tracer
call each (issue 47: not one call per kernel), in single precision (a picture's: the tracer's CPU 1.1-1.8x
less; float32 rays land within 0.06 um of float64's, docs/ray-tracing.md). A ray starts
where it crosses a plane before the front element (:func:`_start_z`; its aim point moved back along it in
double precision), not at its object point: up to :data:`FAR_MM` away, where float32's step is 1 mm.
Its direction and weight are computed from the object point in double precision first.

**Solid angle** (for the transmission, where a sampled count would be 0.2 % noisy at thousands of
rays): the rays that pass fill a convex region of the pupil's plane (the iris's image, clipped by
the lens's rims). From a point inside it (the centre of the pilot rays that passed) its edge is
found along :data:`AZIMUTHS` directions by bisection, and ``d^2 Omega = sum over directions of
dphi R^2 int_0^1 g(R t) t dt`` (g the ray's weight, cos^3 of its angle times the iris's density),
the integral by 4-point Gauss-Legendre: exact for a round pupil, second order in 1/AZIMUTHS elsewhere.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import OpticsError


#: rays per tracer call (about 100 bytes of memory per ray in flight: a quarter million keeps a chunk's
#: columns nearer the cache from their writing to the trace than a million did, about 10 % less CPU)
CHUNK_RAYS = 1 << 18
#: the depth of the "infinity" node, mm (10 km: its blur differs from infinity's by
#: D_ep f_pin 1e-7 / p, 0.001 px for a 50 mm f/2.8 on 0.1 mm pixels). Not farther: from 1e9 mm the
#: traced rays lose precision and the kernel grows a halo tens of pixels wide
FAR_MM = 1.0e7
#: directions and bisection steps of the solid-angle search (module notes)
AZIMUTHS, _STEPS = 64, 16
#: the pilot's grids: over the front element (per side) and over the paraxial entrance pupil
_PILOT_FRONT, _PILOT_PUPIL = 24, 12
_SEED = 0x5EED_DEF0


@dataclass
class Fan:
    """One object point's rays: ``ox``, ``oy`` picture offsets (px) from its pinhole image (0 where
    blocked, so that sums over a fan need no mask), ``w`` the solid angle per ray (0 where blocked), ``ch`` each ray's wavelength index,
    ``ex``, ``ey`` its aim point on the entrance pupil's plane (mm)."""

    field_px: tuple[float, float]
    u: float
    ox: np.ndarray
    oy: np.ndarray
    w: np.ndarray
    ch: np.ndarray
    ex: np.ndarray
    ey: np.ndarray

    def prefix(self, n: int) -> "Fan":
        """The fan of its first ``n`` samples."""
        return Fan(self.field_px, self.u, self.ox[:n], self.oy[:n], self.w[:n], self.ch[:n], self.ex[:n], self.ey[:n])


_SAMPLES: dict = {}


def _unit_samples(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The first ``n`` points of the fans' Sobol sequence in [0, 1)^2 (memoised, grown as needed)."""
    from ...trace.lowdiscrepancy import owen_sobol_2d

    have = _SAMPLES.get("n", 0)
    if have < n:
        size = max(n, 2 * have)
        _SAMPLES["xy"] = owen_sobol_2d(size, 0, _SEED)
        _SAMPLES["n"] = size
    x, y = _SAMPLES["xy"]
    return x[:n], y[:n]


def _depth_mm(u: float) -> float:
    return FAR_MM if u <= 1.0 / FAR_MM else 1.0 / u


def _object_point(cam, field_px, u) -> tuple[float, float, float, float]:
    """(X, Y, z) in lens space of the point the pinhole sees at ``field_px`` at inverse depth u, and its depth."""
    d = _depth_mm(u)
    sx, sy = cam.film_point(*field_px)
    z_ep = cam.film_z - cam.pupil_from_film_mm
    return sx * d / cam.pinhole_x_mm, sy * d / cam.pinhole_mm, z_ep - d, d


def _rays(px, py, pz, ax, ay, az, wavelengths):
    """A float64 RayBatch from object points (px, py, pz) toward aim points (ax, ay, az), all (n,) arrays
    (or scalars for the aim plane ``az``), and the cosine of each ray's angle to the axis."""
    from ...trace import RayBatch

    dx, dy, dz = ax - px, ay - py, az - pz
    inv = 1.0 / np.sqrt(dx * dx + dy * dy + dz * dz)
    n = len(dx)
    N = dz * inv
    return RayBatch(np.array(px, dtype=float), np.array(py, dtype=float), np.array(pz, dtype=float), dx * inv,
                    dy * inv, N, wavelengths, np.ones(n), np.zeros(n, dtype=np.uint8)), N


def _trace(cam, rays):
    """Film landing (x, y) mm and a pass mask of ``rays`` (traced in place)."""
    from ...trace import trace_to_film

    out = trace_to_film(cam.focused, rays, film_z=cam.film_z, fresnel=False, stop_semi_diameter=cam.stop_semi,
                        aperture=cam.aperture, backend="auto", in_place=True)
    ok = out.ok & (out.weight > 0)
    return out.x, out.y, ok, out.weight


def _pilot_grids(cam, pts, z_ep):
    """The pilot's aim points on the pupil's plane for object points ``pts`` (n, 3): a grid over the
    front element's clear disk seen from each point, and a finer one over the paraxial entrance
    pupil; (x, y, cell size), each (n, points per object point)."""
    r_front = cam.focused.surfaces[0].semi_diameter
    r_ep = 0.5 * max(cam.pupil_diameter_mm, cam.pupil_diameter_x_mm)
    s = (z_ep - pts[:, 2]) / (0.0 - pts[:, 2])  # the front vertex plane (z = 0) seen from the point, on the pupil's
    centres = np.stack([pts[:, 0] * (1 - s), pts[:, 1] * (1 - s)], axis=1)
    out = []
    for n, c, half in ((_PILOT_FRONT, centres, r_front * s), (_PILOT_PUPIL, np.zeros_like(centres),
                                                                np.full(len(s), 1.5 * r_ep))):
        g = (np.arange(n) + 0.5) / n * 2 - 1
        gx, gy = (a.ravel() for a in np.meshgrid(g, g))
        out.append((c[:, 0:1] + half[:, None] * gx[None, :], c[:, 1:2] + half[:, None] * gy[None, :],
                    np.repeat((2 * half / n)[:, None], n * n, axis=1)))
    return tuple(np.concatenate([o[i] for o in out], axis=1) for i in range(3))


def pupil_boxes(cam, fields_px, us) -> list[tuple[float, float, float, float]]:
    """For each field node, the box (x0, x1, y0, y1, mm on the entrance pupil's plane) that holds
    every ray from its object points at inverse depths ``us`` that reaches the film (module notes);
    the paraxial pupil's box where none does (the frame is wider than the lens covers: no light)."""
    z_ep = cam.film_z - cam.pupil_from_film_mm
    r_ep = 0.5 * max(cam.pupil_diameter_mm, cam.pupil_diameter_x_mm)
    pts = np.array([_object_point(cam, f, u)[:3] for f in fields_px for u in us])  # (k * len(us), 3)
    ax, ay, cell = _pilot_grids(cam, pts, z_ep)
    m = ax.shape[1]
    rays, _ = _rays(np.repeat(pts[:, 0], m), np.repeat(pts[:, 1], m), np.repeat(pts[:, 2], m), ax.ravel(), ay.ravel(),
                    z_ep, np.full(ax.size, cam.wavelengths_nm[len(cam.wavelengths_nm) // 2]))
    _, _, ok, _ = _trace(cam, rays)
    ok = ok.reshape(len(fields_px), -1)
    ax, ay, cell = (a.reshape(len(fields_px), -1) for a in (ax, ay, cell))
    boxes = []
    for k in range(len(fields_px)):
        sel = ok[k]
        if not sel.any():
            boxes.append((-r_ep, r_ep, -r_ep, r_ep))
            continue
        c = cell[k][sel].max()
        bx, by = ax[k][sel], ay[k][sel]
        boxes.append((bx.min() - c, bx.max() + c, by.min() - c, by.max() + c))
    return boxes


def solid_angles(cam, fields_px, us) -> np.ndarray:
    """``d^2 Omega`` (mm^2) per field position, inverse depth and wavelength: (k, len(us), channels)
    (module notes)."""
    z_ep = cam.film_z - cam.pupil_from_film_mm
    wls = np.asarray(cam.wavelengths_nm, dtype=float)
    pts = np.array([_object_point(cam, f, u)[:3] for f in fields_px for u in us])
    centre = _pilot_centres(cam, pts, z_ep)
    dark = np.isnan(centre[:, 0])  # no light passes from these points
    centre = np.nan_to_num(centre)
    m = len(pts) * len(wls)
    px, py, pz = (np.repeat(np.repeat(pts[:, i], len(wls)), AZIMUTHS) for i in range(3))
    cx, cy = (np.repeat(np.repeat(centre[:, i], len(wls)), AZIMUTHS) for i in range(2))
    wl = np.tile(np.repeat(wls, AZIMUTHS), len(pts))
    phi = np.tile((np.arange(AZIMUTHS) + 0.5) * 2 * math.pi / AZIMUTHS, m)
    c, s = np.cos(phi), np.sin(phi)
    lo, hi = np.zeros(len(phi)), np.full(len(phi), 4.0 * cam.focused.surfaces[0].semi_diameter + 1.0)
    for _ in range(_STEPS):
        mid = 0.5 * (lo + hi)
        rays, _ = _rays(px, py, pz, cx + mid * c, cy + mid * s, z_ep, wl)
        _, _, ok, _ = _trace(cam, rays)
        lo, hi = np.where(ok, mid, lo), np.where(ok, hi, mid)
    tq, wq = np.polynomial.legendre.leggauss(4)
    tq, wq = 0.5 * (tq + 1.0), 0.5 * wq
    total = np.zeros(len(phi))
    for t, wt in zip(tq, wq):
        r = lo * t
        rays, cos_t = _rays(px, py, pz, cx + r * c, cy + r * s, z_ep, wl)
        cos3 = cos_t ** 3  # before the trace (in place) moves the directions
        _, _, ok, weight = _trace(cam, rays)
        total += wt * t * np.where(ok, weight, 0.0) * cos3
    omega = (total * lo * lo).reshape(m, AZIMUTHS).sum(axis=1) * (2 * math.pi / AZIMUTHS)
    omega[np.repeat(dark, len(wls))] = 0.0
    return omega.reshape(len(fields_px), len(us), len(wls))


def _pilot_centres(cam, pts, z_ep) -> np.ndarray:
    """For each object point (n, 3), the centre of the pilot rays to the pupil's plane that pass
    (module notes: the grids of :func:`pupil_boxes`); NaN where none passes."""
    grids = _pilot_grids(cam, pts, z_ep)
    ax, ay = grids[0], grids[1]
    m = ax.shape[1]
    rays, _ = _rays(np.repeat(pts[:, 0], m), np.repeat(pts[:, 1], m), np.repeat(pts[:, 2], m), ax.ravel(), ay.ravel(),
                    z_ep, np.full(ax.size, cam.wavelengths_nm[len(cam.wavelengths_nm) // 2]))
    _, _, ok, _ = _trace(cam, rays)
    ok = ok.reshape(len(pts), m)
    cnt = ok.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.stack([(ok * ax).sum(axis=1) / cnt, (ok * ay).sum(axis=1) / cnt], axis=1)


def trace_fans(cam, jobs) -> list[Fan]:
    """The fans of ``jobs``, each (field_px, u, box, n_samples), traced together in chunks of
    :data:`CHUNK_RAYS` rays (module notes)."""
    wls = np.asarray(cam.wavelengths_nm, dtype=float)
    z_ep = cam.film_z - cam.pupil_from_film_mm
    fans: list = [None] * len(jobs)
    todo = list(range(len(jobs)))[::-1]
    while todo:
        batch, total = [], 0
        while todo and (not batch or total + jobs[todo[-1]][3] <= CHUNK_RAYS):
            batch.append(todo.pop())
            total += jobs[batch[-1]][3]
        for j, fan in zip(batch, _trace_batch(cam, [jobs[j] for j in batch], wls, z_ep)):
            fans[j] = fan
    return fans


def _trace_batch(cam, jobs, wls, z_ep) -> list[Fan]:
    """One tracer call for the rays of ``jobs`` (module notes). The rays are laid out by sample count:
    the jobs of one count are a (jobs, samples) block of the columns, written with one broadcast
    operation per column (a job's object point, box and wavelength are constants of its row)."""
    from ...trace import RayBatch

    counts = np.array([n for _, _, _, n in jobs], dtype=np.int64)
    order = np.argsort(counts, kind="stable")
    starts = np.empty(len(jobs), dtype=np.int64)
    starts[order] = np.cumsum(counts[order]) - counts[order]
    total = int(counts.sum())
    sx, sy = _unit_samples(int(counts.max()))
    k = len(wls)
    chs = (np.arange(int(counts.max())) % k).astype(np.int8)
    pts = np.array([_object_point(cam, f, u)[:3] for f, u, _, _ in jobs])
    box = np.array([b for _, _, b, _ in jobs], dtype=float)
    cols = [np.empty(total) for _ in range(6)]  # L M N w ex ey (float64)
    L, M, N, w, ex, ey = cols
    f4 = np.float32
    x, y, z = (np.empty(total, f4) for _ in range(3))  # where each ray starts (module notes: single precision)
    z_s = _start_z(cam)
    for n in np.unique(counts):
        js = order[counts[order] == n]  # consecutive in the layout
        a, n = int(starts[js[0]]), int(n)
        x2, y2, z2, L2, M2, N2, w2, e2, g2 = (c[a:a + len(js) * n].reshape(len(js), n) for c in [x, y, z] + cols)
        px, py, pz = (pts[js, i][:, None] for i in range(3))
        x0, y0 = box[js, 0][:, None], box[js, 2][:, None]
        bw, bh = (box[js, 1] - box[js, 0])[:, None], (box[js, 3] - box[js, 2])[:, None]
        np.multiply(sx[:n], bw, out=e2)
        e2 += x0
        np.multiply(sy[:n], bh, out=g2)
        g2 += y0
        dz = z_ep - pz
        np.subtract(e2, px, out=L2)
        np.subtract(g2, py, out=M2)
        np.multiply(L2, L2, out=N2)
        N2 += M2 * M2
        N2 += dz * dz
        np.sqrt(N2, out=N2)
        np.divide(1.0, N2, out=N2)
        L2 *= N2
        M2 *= N2
        N2 *= dz
        np.multiply(N2, N2, out=w2)  # cos^3, before the trace moves the directions (np.power(N2, 3): 10x the CPU)
        w2 *= N2
        w2 *= bw * bh / n
        zs = np.maximum(pz, z_s)  # the start plane, or the object point if it is nearer (module notes)
        t = (zs - z_ep) / N2  # back from the aim point along the ray, in double precision
        np.add(e2, t * L2, out=x2, casting="same_kind")
        np.add(g2, t * M2, out=y2, casting="same_kind")
        z2[:] = zs
    wl = np.full(total, wls[0], f4) if k == 1 else np.concatenate([wls[chs[:n]] for n in counts[order]]).astype(f4)
    rays = RayBatch(x, y, z, L.astype(f4), M.astype(f4), N.astype(f4), wl, np.ones(total, f4), np.zeros(total, np.uint8))
    x, y, ok, _ = _trace(cam, rays)
    x, y = x.astype(float), y.astype(float)
    sx0 = np.array([cam.film_point(*f)[0] for f, _, _, _ in jobs])
    sy0 = np.array([cam.film_point(*f)[1] for f, _, _, _ in jobs])
    for n in np.unique(counts):
        js = order[counts[order] == n]
        a, n = int(starts[js[0]]), int(n)
        ox, oy = x[a:a + len(js) * n].reshape(len(js), n), y[a:a + len(js) * n].reshape(len(js), n)
        ox += sx0[js][:, None]
        np.divide(ox, -cam.pitch_mm, out=ox)
        oy += sy0[js][:, None]
        np.divide(oy, cam.pitch_mm, out=oy)
    for c in (x, y, w):  # blocked rays: offset 0, weight 0 (a product, not a masked store: several times faster)
        c *= ok
    if not (np.isfinite(x.sum()) and np.isfinite(y.sum())):  # a blocked ray the tracer left at inf or NaN
        x[~ok] = 0.0
        y[~ok] = 0.0
    fans = []
    for (f, u, _, n), a in zip(jobs, starts):
        sl = slice(int(a), int(a) + n)
        fans.append(Fan(tuple(f), float(u), x[sl], y[sl], w[sl], chs[:n], ex[sl], ey[sl]))
    return fans


def _start_z(cam) -> float:
    """A plane before the lens's front element (its vertex less its semi-diameter, a bound on the sag of a
    front surface, and 1 mm)."""
    lens = cam.focused
    return float(cam.film_z - cam.front_from_film_mm - lens.surfaces[0].semi_diameter - 1.0)


def interpolate_fan(a: Fan, b: Fan, u: float, _maps: dict | None = None) -> Fan:
    """The fan at inverse depth ``u`` between fans ``a`` and ``b`` of one field node (same samples;
    module notes). ``u`` at an end returns that end. ``_maps``: a dict memoising the pupil-to-offset
    maps of fan pairs (several depths between the same two fans)."""
    if u == a.u:
        return a
    if u == b.u:
        return b
    s = (u - a.u) / (b.u - a.u)
    both = (a.w > 0) & (b.w > 0)
    ox = a.ox + s * (b.ox - a.ox)  # 0 where both are blocked (their offsets are 0)
    oy = a.oy + s * (b.oy - a.oy)
    only_a, only_b = (a.w > 0) & ~both, (b.w > 0) & ~both
    if (only_a | only_b).any():
        key = (id(a), id(b))
        if _maps is None or key not in _maps:
            got = _pupil_to_offset(a, b, both)
            if _maps is None:
                _maps = {}
            _maps[key] = got
        gx, gy = _maps[key]
        for only, end, t in ((only_a, a, s), (only_b, b, s - 1.0)):
            ox[only] = end.ox[only] + t * (gx[0] * end.ex[only] + gx[1] * end.ey[only] + gx[2])
            oy[only] = end.oy[only] + t * (gy[0] * end.ex[only] + gy[1] * end.ey[only] + gy[2])
    w = (1.0 - s) * a.w + s * b.w
    return Fan(a.field_px, float(u), ox, oy, w, a.ch, a.ex, a.ey)


def _pupil_to_offset(a: Fan, b: Fan, both):
    """The least-squares affine maps from aim point (ex, ey, 1) to the offset change b - a (x and y)."""
    idx = np.flatnonzero(both)[:4096]  # the first samples of the sequence are spread over the whole box
    if len(idx) < 3:
        return np.zeros(3), np.zeros(3)
    M = np.stack([a.ex[idx], a.ey[idx], np.ones(len(idx))], axis=1)
    g = np.linalg.lstsq(M, np.stack([b.ox[idx] - a.ox[idx], b.oy[idx] - a.oy[idx]], axis=1), rcond=None)[0]
    return g[:, 0], g[:, 1]


def distortion_jacobians(cam, fields_px, step_px: float = 4.0) -> np.ndarray:
    """(k, 2, 2): at each picture position, how the lens's image of the plane of focus moves on the
    film (px) per pixel the point moves in the render, d(film) / d(render), from the light's
    centroids of points ``step_px`` either side (the same samples for all four: their noise cancels).
    The identity for a lens without distortion; its inverse takes a kernel from the film's pixels to
    the render's, so that an ST map's redistortion gives the film's blur back, not squeezed twice."""
    pts = [(x + dx, y + dy) for x, y in fields_px for dx, dy in ((step_px, 0), (-step_px, 0), (0, step_px), (0, -step_px))]
    boxes = pupil_boxes(cam, [tuple(f) for f in fields_px], [cam.focus_u])
    fans = trace_fans(cam, [(p, cam.focus_u, boxes[i // 4], 1 << 11) for i, p in enumerate(pts)])
    out = np.empty((len(fields_px), 2, 2))
    for k, (x, y) in enumerate(fields_px):
        c = [np.array(fan_centroid(f)) + np.array(p) for f, p in zip(fans[4 * k: 4 * k + 4], pts[4 * k: 4 * k + 4])]
        out[k, :, 0] = (c[0] - c[1]) / (2 * step_px)
        out[k, :, 1] = (c[2] - c[3]) / (2 * step_px)
    return out


def fan_centroid(fan: Fan) -> tuple[float, float]:
    """The weighted mean offset of a fan's light (px)."""
    t = fan.w.sum()
    if not t > 0:
        return 0.0, 0.0
    # blocked rays: 0 x 0 (a product and a sum, not np.dot: BLAS wakes its threads for long vectors)
    return float((fan.w * fan.ox).sum() / t), float((fan.w * fan.oy).sum() / t)


def bin_fans(fans, channels: int, unwarps) -> list:
    """:func:`fan_centroid` and :func:`bin_fan` of fans of one sample count at once, each with its
    own ``unwarps[i]``: [(centre, (image, channel totals)), ...], the same numbers (the same sums in
    the same order: each fan's rows of one (fans, samples) block, their bins one bincount apart).
    For the many small fans of a frame's direct kernels, whose cost is numpy's per-call overhead."""
    w = np.stack([f.w for f in fans])
    ox, oy = np.stack([f.ox for f in fans]), np.stack([f.oy for f in fans])
    t = w.sum(axis=1)
    lit = t > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        cx = np.where(lit, (w * ox).sum(axis=1) / np.where(lit, t, 1.0), 0.0)
        cy = np.where(lit, (w * oy).sum(axis=1) / np.where(lit, t, 1.0), 0.0)
    tots = [np.bincount(f.ch, weights=f.w, minlength=channels)[:channels] for f in fans]
    dark = np.array([not tot.sum() > 0 for tot in tots])
    dx, dy = ox - cx[:, None], oy - cy[:, None]
    u = np.asarray(unwarps, dtype=float)
    dx, dy = u[:, 0, 0, None] * dx + u[:, 0, 1, None] * dy, u[:, 1, 0, None] * dx + u[:, 1, 1, None] * dy
    r = np.ceil(np.maximum(np.abs(dx).max(axis=1), np.abs(dy).max(axis=1)) + 0.5).astype(np.int64)
    r[dark] = 0
    if (r > 2048).any():
        raise OpticsError("the blur is over 4096 pixels across: give a nearer depth limit")
    n = 2 * r + 1
    dx += r[:, None]  # then + 0.5, as bin_fan
    dx += 0.5
    dy += r[:, None]
    dy += 0.5
    top = (n - 1)[:, None]
    flat = np.minimum(np.maximum(np.floor(dy).astype(np.int64), 0), top) * n[:, None] + \
        np.minimum(np.maximum(np.floor(dx).astype(np.int64), 0), top)
    if channels > 1:
        flat = flat * channels + fans[0].ch[None, :]
    size = n * n * channels
    start = np.cumsum(size) - size
    flat += start[:, None]
    flat[dark] = 0  # no light: bin_fan's unit kernel below
    img = np.bincount(flat.ravel(), weights=np.where(dark[:, None], 0.0, w).ravel(), minlength=int(size.sum()))
    out = []
    for i in range(len(fans)):
        if dark[i]:
            out.append(((0.0, 0.0) if not lit[i] else (float(cx[i]), float(cy[i])),
                        (np.ones((1, 1, channels)), np.ones(channels))))
            continue
        k = int(n[i])
        out.append(((float(cx[i]), float(cy[i])), (img[start[i]:start[i] + size[i]].reshape(k, k, channels), tots[i])))
    return out


def bin_fan(fan: Fan, centre: tuple[float, float], channels: int, unwarp=None) -> tuple[np.ndarray, np.ndarray]:
    """The fan binned on the picture's pixel grid around ``centre`` (px): (2R+1, 2R+1, channels) of
    summed weights, the centre pixel covering offsets within half a pixel of ``centre``; and each
    channel's total weight. ``unwarp`` (2 x 2) maps each offset first (from the film's pixels to the
    render's: :func:`distortion_jacobians`)."""
    w = fan.w
    tot = np.bincount(fan.ch, weights=w, minlength=channels)[:channels]  # blocked rays weigh 0
    if not tot.sum() > 0:  # no light: a unit kernel (the transmission, 0 there, darkens the pixel)
        return np.ones((1, 1, channels)), np.ones(channels)
    dx, dy = fan.ox - centre[0], fan.oy - centre[1]  # a blocked ray's (weight 0) lands at the pinhole image
    if unwarp is not None:
        dx, dy = unwarp[0, 0] * dx + unwarp[0, 1] * dy, unwarp[1, 0] * dx + unwarp[1, 1] * dy
    r = int(math.ceil(max(np.abs(dx).max(), np.abs(dy).max()) + 0.5))
    if r > 2048:
        raise OpticsError("the blur is over 4096 pixels across: give a nearer depth limit")
    n = 2 * r + 1
    dx += r  # then + 0.5: floor(dx + r + 0.5) as written, rounded the same
    dx += 0.5
    dy += r
    dy += 0.5
    flat = np.floor(dy).astype(np.int64).clip(0, n - 1) * n + np.floor(dx).astype(np.int64).clip(0, n - 1)
    if channels > 1:
        flat = flat * channels + fan.ch
    img = np.bincount(flat, weights=w, minlength=n * n * channels).reshape(n, n, channels)
    return img, tot
