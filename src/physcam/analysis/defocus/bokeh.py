"""PSF / bokeh image of a point light, accumulated in a fixed-size histogram in chunks.

The light sits at lateral position (``x_mm``, ``y_mm``) and ``depth_mm`` in front of the film
plane (docs/conventions.md: lens-space z = film_z - depth). Rays leave it toward points spread
uniformly over the front element's clear disk: shuffled Owen-scrambled Sobol points
(:mod:`physcam.trace.lowdiscrepancy`; ``seed`` sets the scrambling; one sequence per wavelength)
mapped to the disk by r = R sqrt(u), phi = 2 pi v. An image binned from them is as clean as one
from several times as many independent random rays (docs/ray-tracing.md, "Bokeh sampling").
Each ray carries the solid angle it stands for, dA cos^3(theta) / dz^2 (dz the axial distance
from the light to the front vertex plane), times Fresnel transmission. Rays are traced to the film in chunks of ``chunk``
and binned into a ``pixels`` x ``pixels`` image, so memory stays bounded (about 0.2 KB per ray
in a chunk: 1e8 rays in chunks of 1e6 use well under 1 GB). The image shows cat's-eye
vignetting off axis, the aperture shape (``aperture`` at the stop) and, with ``spectral``,
colour fringes (three channels at 620, 550 and 460 nm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import InputError, OpticsError, require_finite, require_positive
from ...optics.state import CameraState, takes_camera
from ...figures import styled

__all__ = ["BokehImage", "bokeh_image", "RGB_WAVELENGTHS_NM", "tone_map", "scale_bar_pixels", "write_bokeh_photo"]

RGB_WAVELENGTHS_NM = (620.0, 550.0, 460.0)


@dataclass
class BokehImage:
    """``image`` (pixels, pixels, channels) of relative irradiance; ``extent_mm`` = (x0, x1, y0, y1) on the film."""

    lens_name: str
    image: np.ndarray
    extent_mm: tuple[float, float, float, float]
    wavelengths_nm: tuple[float, ...]
    rays_traced: int
    rays_passed: int
    film_z_mm: float

    def to_dict(self) -> dict:
        tot = self.image.sum()
        ys, xs = np.indices(self.image.shape[:2])
        x0, x1, y0, y1 = self.extent_mm
        px = (x1 - x0) / self.image.shape[1]
        py = (y1 - y0) / self.image.shape[0]
        e = self.image.sum(axis=2)
        cx = float((e * (x0 + (xs + 0.5) * px)).sum() / tot) if tot > 0 else None
        cy = float((e * (y0 + (ys + 0.5) * py)).sum() / tot) if tot > 0 else None
        return {"lens": self.lens_name, "wavelengths_nm": list(self.wavelengths_nm), "extent_mm": list(self.extent_mm),
                "pixels": list(self.image.shape[:2]), "rays_traced": self.rays_traced,
                "rays_passed": self.rays_passed, "film_z_mm": self.film_z_mm, "centroid_mm": [cx, cy]}

    @styled
    def plot(self, path=None, *, force: bool = False):
        """The film-millimetre plot: the image (peak white) on film x and y axes."""
        from ...figures import fit_title, pyplot

        plt = pyplot()

        img = self.image / max(self.image.max(), 1e-300)
        if img.shape[2] == 1:
            img = np.repeat(img, 3, axis=2)
        fig, ax = plt.subplots(figsize=(4.4, 4.4))
        ax.imshow(img, origin="lower", extent=self.extent_mm, interpolation="nearest")
        ax.set_xlabel("film x (mm)")
        ax.set_ylabel("film y (mm)")
        ax.set_title(fit_title(f"{self.lens_name}: bokeh", 3.6))
        fig.tight_layout()
        if path is None:
            return fig
        from ...figures import save_figure

        return save_figure(fig, path, force=force)


@takes_camera
def bokeh_image(
    camera: CameraState,
    depth_mm: float,
    x_mm: float = 0.0,
    y_mm: float = 0.0,
    *,
    rays: int = 250_000,
    pixels: int = 256,
    extent_mm: tuple[float, float, float, float] | None = None,
    spectral: bool = False,
    fresnel: bool = True,
    chunk: int = 1_000_000,
    progress=None,
    seed: int = 0,
    backend: str = "auto",
    precision: str = "double",
) -> BokehImage:
    """Image of a point light through ``camera`` on the film (see module notes).

    ``camera``: a :class:`~physcam.optics.state.CameraState` (its focused lens, film plane, iris, iris
    shape and primary wavelength; a camera built from a bare lens leaves the film at the paraxial image
    of infinity). Its iris shape (a :class:`~physcam.trace.aperture.Aperture`: blades, angle,
    roundness, density) shapes the stop, so the bokeh shows the iris polygon and its brightness ramp.
    ``progress`` (optional) is called as ``progress(rays_done, rays)`` after each chunk.
    ``precision="single"`` traces the rays in float32 (faster; its error against double on every
    bundled lens is in docs/ray-tracing.md); the image is accumulated in double either way.
    """
    from ...trace import paraxial_image_z
    from ...trace.kernels import backend_for_job
    from .._camera import ray_view

    lens, _, film_z, stop_semi_diameter, aperture, wl, _ = ray_view(camera)
    depth = require_positive("light distance (depth_mm, --light)", depth_mm)
    x_mm = require_finite("light x", x_mm)
    y_mm = require_finite("light y", y_mm)
    _check_counts(rays, pixels, chunk)
    if film_z is None:
        film_z = paraxial_image_z(lens)
    z_src = film_z - depth
    if z_src >= -1e-9:
        raise InputError(
            f"the light at {depth:g} mm from the film is not in front of the lens (front vertex is "
            f"{film_z:g} mm from the film); give a larger light distance"
        )
    if precision not in ("double", "single"):
        raise InputError(f"precision must be 'double' or 'single', got {precision!r}")
    wls = RGB_WAVELENGTHS_NM if spectral else (wl,)
    src = _PointLight(x_mm, y_mm, z_src, lens.surfaces[0].semi_diameter, wls, seed,
                      np.float64 if precision == "double" else np.float32)
    backend = backend_for_job(backend, (rays + (0 if extent_mm is not None else 20_000))
                              * (len(lens.surfaces) + 1))
    trace = dict(film_z=film_z, stop_semi_diameter=stop_semi_diameter, aperture=aperture, backend=backend)
    head = None
    if extent_mm is None:  # a pilot trace sizes the window (in double: it sets the image's frame)
        extent_mm, head = _pilot_extent(lens, src, trace, depth, fresnel)
        if src.dtype is not np.float64 or min(rays, chunk) <= PILOT_RAYS:
            head = None  # the pilot's rays are not the image's first rays
    x0, x1, y0, y1 = (float(v) for v in extent_mm)
    if not (x1 > x0 and y1 > y0):
        raise InputError(f"bokeh extent must have x1 > x0 and y1 > y0, got {extent_mm}")
    img, passed = _accumulate(lens, src, trace, (x0, x1, y0, y1), rays, pixels, chunk, fresnel, progress, head)
    img = img.reshape(pixels, pixels, len(wls)) * (np.pi * src.r_front**2 / (z_src * z_src) / rays)
    return BokehImage(lens.name, img, (x0, x1, y0, y1), tuple(wls), rays, passed, float(film_z))


def _check_counts(rays, pixels, chunk) -> None:
    for name, v, lo, hi, span in (("rays", rays, 1, 10**11, "1 and 1e11"), ("pixels", pixels, 8, 4096, "8 and 4096"),
                                  ("chunk", chunk, 1000, 10**7, "1000 and 1e7")):
        if not lo <= v <= hi:
            raise InputError(f"bokeh {name} must lie between {span}, got {v:g}")


class _PointLight:
    """The light at (x, y, z_src) (lens space) and the rays it sends to points uniform on the front
    element's disk of radius ``r_front``: Owen-scrambled Sobol points, one sequence per wavelength (ray
    i goes to wavelength i mod k, as point i // k of that wavelength's sequence): module notes."""

    def __init__(self, x_mm, y_mm, z_src, r_front, wls, seed, dtype):
        from ...trace.lowdiscrepancy import random_seed

        self.x, self.y, self.z_src, self.r_front, self.dtype = x_mm, y_mm, z_src, r_front, dtype
        rng = np.random.default_rng(seed)
        self.seeds = [random_seed(rng) for _ in wls]
        self.wl_of = np.asarray(wls, dtype=np.float64)
        self.k = len(wls)

    def points(self, n, start):
        """(u, v, channel) of rays ``start`` .. ``start + n``."""
        from ...trace.lowdiscrepancy import owen_sobol_2d

        k = self.k
        if k == 1:
            u, v = owen_sobol_2d(n, start, self.seeds[0])
            return u, v, np.zeros(n, dtype=np.intp)
        u, v, ch = np.empty(n), np.empty(n), np.empty(n, dtype=np.intp)
        for c in range(k):
            i0 = start + (c - start) % k  # the first ray of this chunk that goes to wavelength c
            cnt = len(range(i0, start + n, k))
            if cnt:
                sl = slice(i0 - start, None, k)
                u[sl], v[sl] = owen_sobol_2d(cnt, i0 // k, self.seeds[c])
                ch[sl] = c
        return u, v, ch

    def batch(self, n, start, dt=None):
        """Rays ``start`` .. ``start + n`` as a RayBatch in ``dt`` (default the light's precision), and
        their channels. Built column by column (the arithmetic of RayBatch.from_arrays, without its
        checks: every number here is finite and every direction has dz = -z_src > 0), in one pass per column."""
        from ...trace import RayBatch

        dt = self.dtype if dt is None else dt
        x_mm, y_mm, z_src = self.x, self.y, self.z_src
        u, phi, ch = self.points(n, start)
        r = np.sqrt(u)
        r *= self.r_front
        phi *= 2 * np.pi
        px = np.cos(phi)
        px *= r
        py = np.sin(phi)
        py *= r
        dx, dy, dzn, w = _unit_directions(px - x_mm, py - y_mm, -z_src)
        wl = self.wl_of[ch] if self.k > 1 else np.full(n, self.wl_of[0])

        def col(a):
            return a if dt is np.float64 else np.asarray(a, dtype=dt)

        def const(v):
            return np.full(n, v, dtype=dt)

        if dt is np.float64:
            b = RayBatch(const(x_mm), const(y_mm), const(z_src), dx, dy, dzn, wl, w, np.zeros(n, dtype=np.uint8))
        else:
            # single precision: start each ray where it crosses the front vertex plane (its target
            # point, exact) rather than at the light: intersecting the first surface from a light
            # a metre away would cost float32 the digits that 1 - c^2 h^2 keeps out of c^2 z^2
            b = RayBatch(col(px), col(py), const(0.0), col(dx), col(dy), col(dzn),
                         col(wl), col(w), np.zeros(n, dtype=np.uint8))
        return b, ch


def _unit_directions(dx, dy, dz):
    """(dx, dy, dz) normalised in place, and cos^3 of each ray's angle to the axis (its solid-angle
    weight). Scaled by the largest component before squaring (no overflow for a light far away)."""
    big = np.maximum(np.abs(dx), np.abs(dy))
    np.maximum(big, dz, out=big)
    dx /= big
    dy /= big
    dzn = dz / big
    s2 = dx * dx
    s2 += dy * dy
    s2 += dzn * dzn
    np.sqrt(s2, out=s2)
    dx /= s2
    dy /= s2
    dzn /= s2
    return dx, dy, dzn, dzn**3


#: Rays of the pilot trace that frames the image (:func:`_pilot_extent`).
PILOT_RAYS = 20_000


def _pilot_extent(lens, src, trace, depth, fresnel):
    """A square window on the film around where the first :data:`PILOT_RAYS` rays (in double) land, 20 %
    margin; and those rays traced (as the image traces them: with ``fresnel``) and their channels."""
    from ...trace import trace_to_film

    pilot, ch = src.batch(PILOT_RAYS, 0, np.float64)
    pr = trace_to_film(lens, pilot, fresnel=fresnel, in_place=True, **trace)
    if not pr.ok.any():
        raise OpticsError(f"no light from ({src.x:g}, {src.y:g}) mm at depth {depth:g} mm reaches the film")
    xs, ys = pr.x[pr.ok], pr.y[pr.ok]
    cx, cy = 0.5 * (xs.min() + xs.max()), 0.5 * (ys.min() + ys.max())
    half = 0.6 * max(xs.max() - xs.min(), ys.max() - ys.min(), 0.01)
    return (cx - half, cx + half, cy - half, cy + half), (pr, ch)


def _accumulate(lens, src, trace, extent, rays, pixels, chunk, fresnel, progress, head=None):
    """Trace ``rays`` in chunks and bin their weights into a flat (pixels, pixels, channels) histogram
    over ``extent``; returns it and the count of rays that reached the film. ``head`` (the pilot's
    traced rays and channels, fewer than a chunk): the first rays, already traced (issue 47: the
    pilot's 20 000 rays were traced twice); each ray's trace is its own, and its bin and weight go
    into the first chunk's sum in the same order, so the image is the same."""
    from ...trace import trace_to_film

    x0, x1, y0, y1 = extent
    nch = src.k
    img = np.zeros(pixels * pixels * nch)

    def bins(out, ch):
        """The flat bins and weights of the rays of ``out`` that land in the image."""
        ix = np.floor((out.x - x0) / (x1 - x0) * pixels).astype(np.int64)
        iy = np.floor((out.y - y0) / (y1 - y0) * pixels).astype(np.int64)
        inside = out.ok & (ix >= 0) & (ix < pixels) & (iy >= 0) & (iy < pixels)
        return (iy[inside] * pixels + ix[inside]) * nch + ch[inside], out.weight[inside]

    passed = 0
    done = 0
    while done < rays:
        n = min(chunk, rays - done)
        k = 0 if head is None or done else head[1].size
        b, ch = src.batch(n - k, done + k)
        out = trace_to_film(lens, b, fresnel=fresnel, in_place=True, **trace)
        flat, weight = bins(out, ch)
        passed += int(out.ok.sum())
        if k:
            (hf, hw), passed = bins(*head), passed + int(head[0].ok.sum())
            flat, weight = np.concatenate((hf, flat)), np.concatenate((hw, weight))
        img += np.bincount(flat, weights=weight, minlength=img.size)
        done += n
        if progress is not None:
            progress(done, rays)
    return img, passed


# ---- bokeh as a photograph -----------------------------------------------------------------------
def tone_map(rgb: np.ndarray, *, exposure: float = 1.0) -> np.ndarray:
    """Linear relative irradiance (h, w, 3) as sRGB-encoded values in 0..1 for a PNG: scaled so the
    99.5th percentile of the lit pixels is 1 (times ``exposure``), rolled off as 1 - exp(-x) (highlights
    saturate as on film, nothing clips hard) and encoded with the sRGB transfer function (IEC 61966-2-1)."""
    lit = rgb[rgb > 0]
    ref = float(np.percentile(lit, 99.5)) if lit.size else 1.0
    x = rgb * (exposure / max(ref, 1e-300))
    y = 1.0 - np.exp(-2.0 * x)
    return np.where(y <= 0.0031308, 12.92 * y, 1.055 * np.power(np.clip(y, 0.0, 1.0), 1 / 2.4) - 0.055)


def scale_bar_pixels(image_width_mm: float, pixel_pitch_um: float) -> int:
    """A round length (1, 2 or 5 times a power of ten) in sensor pixels of ``pixel_pitch_um`` for a
    scale bar about a quarter as wide as an image ``image_width_mm`` wide on the film."""
    across = image_width_mm * 1000.0 / pixel_pitch_um
    target = max(across / 4.0, 1.0)
    p = 10 ** math.floor(math.log10(target))
    return int(max(m * p for m in (1, 2, 5) if m * p <= target) if p >= 1 else 1)


def write_bokeh_photo(img: BokehImage, path, *, pixel_pitch_um: float, sensor_name: str = "", exposure: float = 1.0,
                      force: bool = False) -> list:
    """The bokeh as a photograph of the highlight: ``path`` with ``.exr`` (linear relative irradiance,
    RGB: the three wavelengths of a spectral image, else grey; 32-bit float, the film extent and pixel
    size in its header) and ``.png`` (:func:`tone_map`, with a scale bar in pixels of a sensor of
    ``pixel_pitch_um``). Returns both paths. Rows top first: film +y up, as the camera sees it."""
    from pathlib import Path

    from ...errors import require_positive, require_type
    from ...io import check_writable
    from ..distortion.stmap import write_map_exr

    require_type("img", img, BokehImage, "physcam.analysis.defocus.bokeh.bokeh_image(lens, ...)")
    pitch = require_positive("pixel pitch", pixel_pitch_um, unit="um")
    base = Path(path)
    base = base.with_suffix("") if base.suffix.lower() in (".exr", ".png") else base
    exr, png = base.with_name(base.name + ".exr"), base.with_name(base.name + ".png")
    for p in (exr, png):
        check_writable(p, force=force)
    rgb = img.image if img.image.shape[2] == 3 else np.repeat(img.image, 3, axis=2)
    rgb = np.ascontiguousarray(rgb[::-1])  # row 0 on top
    x0, x1, y0, y1 = img.extent_mm
    attrs = {"physcam_film_extent_mm": " ".join(f"{v:.6g}" for v in img.extent_mm),
             "physcam_pixel_mm": float((x1 - x0) / rgb.shape[1]), "physcam_lens": img.lens_name,
             "physcam_wavelengths_nm": " ".join(f"{w:g}" for w in img.wavelengths_nm)}
    write_map_exr(rgb, exr, attrs, force=force)
    _write_photo_png(tone_map(rgb, exposure=exposure), png, x1 - x0, pitch, sensor_name, force)
    return [exr, png]


def _write_photo_png(srgb, path, width_mm, pitch_um, sensor_name, force):
    """``srgb`` (0..1) as an 8-bit PNG, enlarged to at least 512 pixels, with the scale bar and its label."""
    from PIL import Image, ImageDraw

    from ...io import staged

    im = Image.fromarray((np.clip(srgb, 0, 1) * 255 + 0.5).astype(np.uint8), "RGB")
    k = max(1, math.ceil(512 / im.width))
    im = im.resize((im.width * k, im.height * k), Image.NEAREST)
    n = scale_bar_pixels(width_mm, pitch_um)
    bar = n * pitch_um / 1000.0 / width_mm * im.width
    d = ImageDraw.Draw(im)
    y = im.height - 24
    d.rectangle([16, y, 16 + round(bar), y + 5], fill=(255, 255, 255))
    label = f"{n} px" + (f" of {sensor_name}" if sensor_name else "") + f" ({pitch_um:g} µm pitch)"
    d.text((16, y - 20), label, fill=(255, 255, 255), font=_label_font())
    with staged(path, force=force, suffix=".png") as tmp:
        im.save(tmp, format="png")
    return path


def _label_font():
    """The figures' font (DejaVu Sans, shipped with matplotlib) at 14 px for the PNG's scale bar label."""
    from matplotlib.font_manager import findfont
    from PIL import ImageFont

    try:
        return ImageFont.truetype(findfont("DejaVu Sans"), 14)
    except OSError:  # no TrueType support in this Pillow: its own bitmap font
        return ImageFont.load_default()
