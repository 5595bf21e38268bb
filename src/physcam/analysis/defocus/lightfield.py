"""Light-field (plenoptic) images: the raw sensor image behind a microlens array, sub-aperture
views, synthetic refocusing (shift-and-add), and the disparity between views in closed form.

The camera is a :class:`~physcam.trace.microlens.PlenopticCamera` (main lens + array + sensor;
docs/microlens.md). Subjects are placed by their distance **in front of the sensor** (the film
plane, docs/conventions.md) and their lateral position (mm, lens-space x right, y up).

Images are arrays of rows top (+y) to bottom and columns left (-x) to right, the sensor seen from
behind the camera; like any camera's film they hold the scene upside down (rotate 180 degrees to
view). A sub-aperture view has one pixel per lenslet in the same orientation.

**Rendering.** A point: rays from the point to a disk around the main lens's paraxial entrance
pupil (``margin`` times its radius), weighted by the solid angle they stand for, traced forward
(:func:`~physcam.trace.microlens.trace_to_sensor`) and binned. A textured plane: ``spp`` rays per
sensor pixel, from a random point in the pixel to a random point on the lenslet whose sub-image
holds the pixel, traced backward through the array and the main lens to the plane; each carries the
plane's texture times the film-side weight cos^4(theta) A / b^2 (pbrt-v4's ``RealisticCamera``).

**Sub-aperture views** (Ng et al., "Light field photography with a hand-held plenoptic camera",
Stanford CTSR 2005-02): the pixel at offset o from each sub-image's centre sees the main lens
through one small patch of its exit pupil; collecting that pixel under every lenslet gives the
picture through that patch. Centres: :func:`~physcam.trace.microlens.subimage_centres`; raw
pixels are sampled bilinearly at centre + o.

**Disparity, in closed form** (:func:`view_disparity`). Let the exit pupil lie D in front of the
array plane and the sensor b = f_mu behind it (thin lenslets in focus at infinity). A lenslet maps
incoming slope to sensor position: a ray at height x on the lenslet centred at c leaves with slope
s - (x - c)/f_mu and lands at x + b (s - (x - c)/f_mu) = c + b s; a ray from exit-pupil point U has
s = (x - U)/D, so the pixel at offset o from the sub-image centre c (1 + b/D) sees U = -o D / b,
whatever the lenslet. A point whose image forms D' behind the exit pupil sends the ray through U to
the array at x(U) = X' D/D' + U (1 - D/D') (similar triangles between pupil and image). So in view o
the point moves by -o (D/b)(1 - D/D'): with pixel pitch q = p / n (n pixels per lenslet of pitch p),
one view step shifts it by

    slope = -(D / (n b)) (1 - D / D')    lenslets per view step,

the same in x and y (image rows run down as y does up, and so do view rows). A point imaged on the
array (D' = D) does not move; one imaged behind it (a closer subject, D' > D) moves against the view
index, one in front of it with it. For a thin main lens the exit pupil is the lens, D = s'_0 (the
array's distance from the lens) and D' = s' (1/s + 1/s' = 1/f). Shift-and-add refocusing to that
subject samples view o at k + slope o and averages (Ng 2005, eq. 2 discretised).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, OpticsError, require_finite, require_positive, require_type
from ...trace.microlens import PlenopticCamera, subimage_centres, trace_from_sensor, trace_to_sensor
from ...trace.rays import OK, RayBatch
from ...figures import styled

__all__ = ["LightField", "render_point", "render_plane", "render_planes", "subaperture_views", "refocus", "view_disparity",
           "view_mask", "checkerboard", "light_field_figure"]

#: rays per traced chunk (bounds the memory of a render)
CHUNK = 1 << 18
#: most rays one render traces
MAX_RAYS = 50_000_000


def _camera(camera) -> PlenopticCamera:
    return require_type("camera", camera, PlenopticCamera, "build one with physcam.trace.microlens.plenoptic_camera")


def _count(name: str, value, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 1 <= value <= hi:
        raise InputError(f"{name} must be a whole number from 1 to {hi}, got {value!r}")
    return int(value)


def _z_of(camera: PlenopticCamera, distance_mm) -> float:
    d = require_positive("distance from the sensor", distance_mm)
    z = camera.z_sensor - d
    if not z < 0.0:
        raise InputError(f"a subject {d:g} mm from the sensor would be inside the camera (the main lens's front is "
                         f"{camera.z_sensor:g} mm from it)")
    return z


@dataclass
class LightField:
    """A raw light-field image (``raw``: rows x columns, see module notes) and where it came from;
    ``rays_used`` counts the rays that reached the sensor (a point, traced forward) or met the
    subject (planes, traced backward)."""

    camera: PlenopticCamera
    raw: np.ndarray
    subject: str
    rays_traced: int
    rays_used: int
    notes: list = field(default_factory=list)

    def views(self, centres=None) -> np.ndarray:
        """:func:`subaperture_views` of this image."""
        return subaperture_views(self.camera, self.raw, centres=centres)

    def to_dict(self) -> dict:
        c = self.camera
        a = c.array
        return {"subject": self.subject, "lens": c.main.name, "lenslets": [a.count_x, a.count_y],
                "pitch_mm": [a.pitch_x, a.pitch_y], "pixels_per_lenslet": c.pixels_per_lenslet,
                "resolution": list(c.resolution), "sensor_offset_mm": a.sensor_offset_mm,
                "film_to_lens_mm": c.film_to_lens_mm,
                "lenslet": a.lenslet.name if a.lenslet is not None else f"thin, f = {a.focal_length_mm:g} mm",
                "rays_traced": self.rays_traced, "rays_used": self.rays_used,
                "total": float(self.raw.sum()), "notes": list(self.notes)}


def _bin(camera: PlenopticCamera, x, y, w, image) -> int:
    """Add weights ``w`` of sensor hits (x, y) into ``image`` (rows top to bottom); returns how many landed."""
    W, H = camera.array.film_width_mm, camera.array.film_height_mm
    nx, ny = camera.resolution
    col = np.floor((x + W / 2.0) / W * nx)
    row = np.floor((H / 2.0 - y) / H * ny)
    ok = (col >= 0) & (col < nx) & (row >= 0) & (row < ny) & np.isfinite(w) & (w > 0)
    k = row[ok].astype(np.int64) * nx + col[ok].astype(np.int64)
    image += np.bincount(k, weights=w[ok], minlength=nx * ny).reshape(ny, nx)
    return int(ok.sum())


def render_point(camera, distance_mm: float, x_mm: float = 0.0, y_mm: float = 0.0, *, rays: int = 400_000,
                 seed: int = 0, margin: float = 1.3, backend: str = "auto") -> LightField:
    """The raw image of a point light ``distance_mm`` in front of the sensor at lateral (x, y) mm.

    Rays aim at a disk ``margin`` times the paraxial entrance pupil's radius around the axis, on the
    entrance-pupil plane (module notes); each weighs the solid angle it stands for, so the image is
    the irradiance from a unit-intensity point (relative units, integrated over each pixel).
    """
    from ...optics.paraxial import gaussian

    cam = _camera(camera)
    n = _count("rays", rays, MAX_RAYS)
    z0 = _z_of(cam, distance_mm)
    x0, y0 = require_finite("x", x_mm), require_finite("y", y_mm)
    m = require_positive("margin", margin, unit="")
    g = gaussian(cam.main, object_z=z0, film_z=cam.z_array)
    file_stop = cam.main.surfaces[cam.main.stop_index].semi_diameter
    r_ep = 0.5 * g.entrance_pupil_diameter * cam.stop_semi_diameter / file_stop * m
    z_ep = g.z_entrance_pupil
    if not z_ep > z0:
        raise OpticsError(f"the point ({distance_mm:g} mm from the sensor) lies behind the entrance pupil")
    rng = np.random.default_rng(seed)
    nx, ny = cam.resolution
    image = np.zeros((ny, nx))
    landed = 0
    area = math.pi * r_ep * r_ep
    for a in range(0, n, CHUNK):
        k = min(CHUNK, n - a)
        r = r_ep * np.sqrt(rng.random(k))
        phi = 2.0 * math.pi * rng.random(k)
        ax, ay = r * np.cos(phi), r * np.sin(phi)
        d = np.stack([ax - x0, ay - y0, np.full(k, z_ep - z0)], axis=1)
        dist2 = (d * d).sum(axis=1)
        w = area * (z_ep - z0) / np.sqrt(dist2) / dist2 / n  # dA cos(theta) / r^2 per ray
        b = RayBatch.from_arrays(np.array([[x0, y0, z0]]), d, cam.main.wavelength_nm, w)
        out = trace_to_sensor(cam, b, backend=backend)
        ok = out.flag == OK
        landed += _bin(cam, out.x[ok], out.y[ok], out.weight[ok], image)
    lf = LightField(cam, image, f"point {distance_mm:g} mm from the sensor at ({x0:g}, {y0:g}) mm", n, landed)
    if landed == 0:
        lf.notes.append("no ray reached the sensor: the point is outside the field or the array")
    return lf


def checkerboard(squares: int = 8, pixels_per_square: int = 16) -> np.ndarray:
    """A black-and-white checkerboard texture (rows x columns in 0..1), with a grey top-left
    square so that its orientation shows."""
    s = _count("squares", squares, 256)
    p = _count("pixels per square", pixels_per_square, 256)
    if s * p > 8192:
        raise InputError("the checkerboard would be more than 8192 pixels wide")
    iy, ix = np.indices((s * p, s * p)) // p
    t = ((ix + iy) % 2).astype(np.float64)
    t[:p, :p] = 0.5
    return t


def _plane(item, i):
    """(texture, distance, width, (cx, cy)) of one plane given to :func:`render_planes`."""
    if isinstance(item, (str, bytes)) or not hasattr(item, "__len__") or len(item) not in (3, 4):
        raise InputError(f"plane {i} must be (texture, distance_mm, width_mm) or (texture, distance_mm, width_mm, "
                         "(x_mm, y_mm))")
    texture = item[0]
    tex = np.asarray(texture, dtype=np.float64) if not isinstance(texture, (str, bytes)) else None
    if tex is None or tex.ndim != 2 or min(tex.shape) < 1 or not np.isfinite(tex).all() or (tex < 0).any():
        raise InputError(f"plane {i}: the texture must be a 2-D array of finite radiances >= 0")
    if tex.size > 1 << 26:
        raise InputError(f"plane {i}: the texture must have at most 2^26 pixels")
    d = require_positive("plane distance", item[1])
    w = require_positive("plane width", item[2])
    c = (0.0, 0.0) if len(item) == 3 else item[3]
    if isinstance(c, (str, bytes)) or not hasattr(c, "__len__") or len(c) != 2:
        raise InputError(f"plane {i}: the centre must be (x_mm, y_mm)")
    return tex, d, w, (require_finite("plane centre x", c[0]), require_finite("plane centre y", c[1]))


def render_planes(camera, planes, *, spp: int = 4, seed: int = 0, backend: str = "auto") -> LightField:
    """The raw image of flat textured subjects facing the camera (module notes): ``planes`` is a list
    of ``(texture, distance_mm, width_mm[, (x_mm, y_mm)])``, each ``distance_mm`` in front of the
    sensor, ``width_mm`` wide (its height follows the texture's aspect) and centred at (x, y) (default
    the axis). A ray takes the nearest plane it meets inside its texture (the others are occluded);
    outside every texture the scene is black.

    ``texture``: a 2-D array of radiances (rows top (+y) to bottom, columns left (-x) to right, seen
    from the camera). ``spp`` rays per sensor pixel are traced backward.
    """
    cam = _camera(camera)
    if isinstance(planes, (str, bytes)) or not hasattr(planes, "__len__") or not 1 <= len(planes) <= 64:
        raise InputError("planes must be a list of 1 to 64 (texture, distance_mm, width_mm) items")
    items = sorted((_plane(p, i) for i, p in enumerate(planes)), key=lambda t: t[1])
    k = _count("spp", spp, 4096)
    zs = [_z_of(cam, d) for _, d, _, _ in items]
    a = cam.array
    nx, ny = cam.resolution
    if nx * ny * k > MAX_RAYS:
        raise InputError(f"{nx} x {ny} pixels x {k} samples is more than {MAX_RAYS} rays; lower spp")
    qx, qy = cam.pixel_size
    W, H = a.film_width_mm, a.film_height_mm
    # the sub-image magnification: sub-image centre = m * lenslet centre (fitted over the array)
    cx, cy = subimage_centres(cam)
    lx, ly = a.centres(*np.meshgrid(np.arange(a.count_x), np.arange(a.count_y)))
    den = float((lx * lx + ly * ly).sum())
    mag = float((cx * lx + cy * ly).sum() / den) if den > 0 else 1.0
    rng = np.random.default_rng(seed)
    image = np.zeros(nx * ny)
    traced = 0
    hit = 0
    for s0 in range(0, nx * ny * k, CHUNK):
        p = np.arange(s0, min(s0 + CHUNK, nx * ny * k)) // k  # the pixel of each sample
        m = p.size
        col, row = p % nx, p // nx
        xs = -W / 2.0 + (col + rng.random(m)) * qx
        ys = H / 2.0 - (row + rng.random(m)) * qy
        # the lenslet whose sub-image holds the pixel, and a random point on its cell
        ix, iy, _ = a.index_at(xs / mag, ys / mag)
        ccx, ccy = a.cell_centres(ix, iy)
        tx = ccx + (rng.random(m) - 0.5) * a.pitch_x
        ty = ccy + (rng.random(m) - 0.5) * a.pitch_y
        b = a.sensor_offset_mm
        d = np.stack([tx - xs, ty - ys, np.full(m, -b)], axis=1)
        cos_t = b / np.sqrt((d * d).sum(axis=1))
        w = cos_t**4 * a.pitch_x * a.pitch_y / (b * b)
        start = np.stack([xs, ys, np.full(m, cam.z_sensor)], axis=1)
        rays = RayBatch.from_arrays(start, d, cam.main.wavelength_nm, w)
        out = trace_from_sensor(cam, rays, backend=backend)
        ok = np.flatnonzero((out.flag == OK) & (out.N < 0))
        val = np.zeros(ok.size)
        todo = np.ones(ok.size, dtype=bool)
        for (tex, _, w_mm, (pcx, pcy)), z_obj in zip(items, zs):
            h_mm = w_mm * tex.shape[0] / tex.shape[1]
            t = (z_obj - out.z[ok]) / out.N[ok]
            px = out.x[ok] + t * out.L[ok] - pcx
            py = out.y[ok] + t * out.M[ok] - pcy
            tc = np.floor((px + w_mm / 2.0) / w_mm * tex.shape[1])
            tr = np.floor((h_mm / 2.0 - py) / h_mm * tex.shape[0])
            inside = todo & (tc >= 0) & (tc < tex.shape[1]) & (tr >= 0) & (tr < tex.shape[0])
            val[inside] = tex[tr[inside].astype(np.int64), tc[inside].astype(np.int64)]
            todo &= ~inside
        image += np.bincount(p[ok], weights=out.weight[ok] * val, minlength=nx * ny)
        traced += m
        hit += int((~todo).sum())
    what = "plane" if len(items) == 1 else f"{len(items)} planes"
    dists = ", ".join(f"{d:g}" for _, d, _, _ in items)
    return LightField(cam, image.reshape(ny, nx) / k, f"{what} {dists} mm from the sensor", traced, hit)


def render_plane(camera, texture, distance_mm: float, width_mm: float, *, spp: int = 4, seed: int = 0,
                 backend: str = "auto") -> LightField:
    """:func:`render_planes` of one plane centred on the axis."""
    return render_planes(camera, [(texture, distance_mm, width_mm)], spp=spp, seed=seed, backend=backend)


def _bilinear(img: np.ndarray, r: np.ndarray, c: np.ndarray) -> np.ndarray:
    """``img`` sampled at fractional (row, column) positions of pixel centres; 0 outside."""
    ny, nx = img.shape
    r0 = np.floor(r)
    c0 = np.floor(c)
    fr, fc = r - r0, c - c0
    out = np.zeros(r.shape)
    for dr, wr in ((0, 1.0 - fr), (1, fr)):
        for dc, wc in ((0, 1.0 - fc), (1, fc)):
            rr, cc = r0 + dr, c0 + dc
            ok = (rr >= 0) & (rr < ny) & (cc >= 0) & (cc < nx)
            v = np.zeros(r.shape)
            v[ok] = img[rr[ok].astype(np.int64), cc[ok].astype(np.int64)]
            out += wr * wc * v
    return out


def subaperture_views(camera, raw, *, centres=None) -> np.ndarray:
    """Sub-aperture views of the raw image ``raw``: shape (n, n, count_y, count_x) for n pixels
    per lenslet; ``views[j, i]`` collects the pixel at offset (i - (n-1)/2, j - (n-1)/2) pixels
    (columns right, rows down) from each sub-image's centre (module notes). ``centres``: the
    (cx, cy) of :func:`~physcam.trace.microlens.subimage_centres` (computed when None)."""
    cam = _camera(camera)
    img = np.asarray(raw, dtype=np.float64) if not isinstance(raw, (str, bytes)) else None
    nx, ny = cam.resolution
    if img is None or img.shape != (ny, nx):
        raise InputError(f"the raw image must be an array of {ny} x {nx} pixels (this camera's sensor)")
    cx, cy = subimage_centres(cam) if centres is None else (np.asarray(centres[0]), np.asarray(centres[1]))
    a = cam.array
    if cx.shape != (a.count_y, a.count_x) or cy.shape != cx.shape:
        raise InputError("centres must be two (count_y, count_x) arrays")
    n = cam.pixels_per_lenslet
    qx, qy = cam.pixel_size
    W, H = a.film_width_mm, a.film_height_mm
    # view rows run top (+y) to bottom: lenslet row iy = count_y - 1 - r
    cx, cy = cx[::-1], cy[::-1]
    views = np.zeros((n, n, a.count_y, a.count_x))
    h = (n - 1) / 2.0
    for j in range(n):
        for i in range(n):
            x = cx + (i - h) * qx
            y = cy - (j - h) * qy
            views[j, i] = _bilinear(img, (H / 2.0 - y) / qy - 0.5, (x + W / 2.0) / qx - 0.5)
    return views


def view_mask(camera) -> np.ndarray:
    """(n, n) booleans: the sub-aperture views whose pixel (with its bilinear neighbours) lies wholly
    inside every sub-image, the exit pupil's image of diameter XP b / D (paraxial, at the camera's
    stop). Views outside it mix in the neighbouring lenslet's sub-image or see no pupil at all."""
    from ...optics.paraxial import gaussian

    cam = _camera(camera)
    g = gaussian(cam.main, film_z=cam.z_array)
    stop = cam.main.surfaces[cam.main.stop_index].semi_diameter
    xp = g.exit_pupil_diameter * cam.stop_semi_diameter / stop
    D = cam.z_array - g.z_exit_pupil
    if not D > 0:
        raise OpticsError("the main lens's exit pupil lies behind the microlens array")
    r_px = 0.5 * xp * cam.array.sensor_offset_mm / D / max(cam.pixel_size)
    n = cam.pixels_per_lenslet
    c = (n - 1) / 2.0
    j, i = np.indices((n, n))
    return np.hypot(i - c, j - c) + 1.0 <= r_px


def refocus(views, slope: float, *, mask=None) -> np.ndarray:
    """Shift-and-add refocusing: the mean over views of view (i, j) sampled at (row + slope (j - c),
    column + slope (i - c)), c the central view (module notes). ``slope`` in lenslets per view step:
    :func:`view_disparity` of the distance to bring into focus (0 keeps the array's focus).
    ``mask`` ((n, n) booleans, e.g. :func:`view_mask`) keeps only those views."""
    v = np.asarray(views, dtype=np.float64) if not isinstance(views, (str, bytes)) else None
    if v is None or v.ndim != 4 or v.shape[0] != v.shape[1] or v.shape[0] < 1:
        raise InputError("views must be an (n, n, rows, columns) array from subaperture_views")
    sl = require_finite("slope", slope)
    n = v.shape[0]
    c = (n - 1) / 2.0
    keep = np.ones((n, n), dtype=bool) if mask is None else np.asarray(mask)
    if keep.shape != (n, n) or keep.dtype != bool or not keep.any():
        raise InputError(f"mask must be an ({n}, {n}) array of booleans keeping at least one view")
    rows, cols = np.indices(v.shape[2:], dtype=np.float64)
    acc = np.zeros(v.shape[2:])
    used = 0
    for j in range(n):
        for i in range(n):
            if not keep[j, i]:
                continue
            acc += _bilinear(v[j, i], rows + sl * (j - c), cols + sl * (i - c))
            used += 1
    return acc / max(used, 1)


def view_disparity(camera, distance_mm: float) -> float:
    """The closed-form shift of a subject ``distance_mm`` in front of the sensor between neighbouring
    sub-aperture views, in lenslets per view step: -(D / (n b)) (1 - D / D') (module notes), with D
    and D' the paraxial distances from the main lens's exit pupil to the array and to the subject's
    image, b the sensor offset and n the pixels per lenslet. Exact for thin lenslets focused at
    infinity (b = f_mu) and a paraxial main lens."""
    from ...optics.paraxial import gaussian

    cam = _camera(camera)
    z0 = _z_of(cam, distance_mm)
    g = gaussian(cam.main, object_z=z0, film_z=cam.z_array)
    D = cam.z_array - g.z_exit_pupil
    Dp = g.z_image - g.z_exit_pupil
    if not (D > 0 and math.isfinite(Dp) and Dp != 0):
        raise OpticsError("the subject's image or the exit pupil leaves no disparity to compute")
    return -(D / (cam.pixels_per_lenslet * cam.array.sensor_offset_mm)) * (1.0 - D / Dp)


@styled
def light_field_figure(field_, *, views_shown: int = 3, refocus_slopes=(), path=None, force: bool = False):
    """A figure of the raw light field (and a zoom on its centre), a row of sub-aperture views and
    optional refocused images (``refocus_slopes``: (label, slope) pairs). All images are rotated
    180 degrees to show the scene upright. Saved to ``path`` (.png/.svg/.pdf) or returned."""
    lf = require_type("field_", field_, LightField, "render one with render_point or render_plane")
    k = _count("views shown", views_shown, 9)
    from ...figures import pyplot

    plt = pyplot()
    cam = lf.camera
    views = lf.views()
    mask = view_mask(cam)
    if not mask.any():
        mask = None
    n = cam.pixels_per_lenslet
    c = (n - 1) // 2
    picks = sorted({int(round(c + (t - (k - 1) / 2.0) * (c / max((k - 1) / 2.0, 1.0) * 0.75))) for t in range(k)})
    slopes = list(refocus_slopes)
    cols = max(len(picks), len(slopes), 2)
    fig, axes = plt.subplots(3 if slopes else 2, cols, figsize=(2.3 * cols, 2.4 * (3 if slopes else 2)))
    axes = np.atleast_2d(axes)
    for ax in axes.ravel():
        ax.set_axis_off()
    def up(im):  # the sensor's image rotated to upright, shown with gamma 1/2 (points stay visible)
        im = np.asarray(im)[::-1, ::-1]
        return np.sqrt(np.clip(im, 0.0, None) / max(float(im.max()), 1e-300))

    raw = up(lf.raw)
    axes[0, 0].imshow(raw, cmap="gray", interpolation="nearest")
    axes[0, 0].set_title("raw light field", fontsize=8)
    ny, nx = raw.shape
    zw = min(nx, ny, 8 * n)
    r0, c0 = (ny - zw) // 2, (nx - zw) // 2
    axes[0, 1].imshow(raw[r0:r0 + zw, c0:c0 + zw], cmap="gray", interpolation="nearest")
    axes[0, 1].set_title(f"centre, {zw // n} x {zw // n} lenslets", fontsize=8)
    for t, i in enumerate(picks):
        axes[1, t].imshow(up(views[c, i]), cmap="gray", interpolation="nearest")
        axes[1, t].set_title(f"view {i - c:+d} px", fontsize=8)
    for t, (label, s) in enumerate(slopes):
        axes[2, t].imshow(up(refocus(views, s, mask=mask)), cmap="gray", interpolation="nearest")
        axes[2, t].set_title(str(label), fontsize=8)
    fig.suptitle(f"{cam.main.name}:\n{lf.subject} (upright, gamma 1/2)", fontsize=8)
    fig.tight_layout()
    if path is None:
        return fig
    from ...figures import save_figure

    return save_figure(fig, path, force=force)
