"""The lens's own point spread functions for :mod:`physcam.analysis.defocus.render`: a (field x depth) stack.

Geometry (docs/defocus.md): the render is a pinhole picture taken from the lens's **entrance
pupil** with the lens's best-match pinhole focal length ``f_pin`` at this focus
(:attr:`physcam.optics.focusing.TechnicalPlanes.pinhole_focal_length_mm`, the
:attr:`physcam.onset.report.LensReport.pinhole` of the on-set report), on the same sensor. A
picture point (sx, sy) mm from the frame centre (x right, y up) at planar depth ``d`` mm (along
the optical axis, from the plane of the entrance pupil) is the object point (sx d / f_pin,
sy d / f_pin) in lens space, ``entrance_pupil_from_film + d`` in front of the film. The kernel is
that point's image traced by physcam's tracer (:func:`physcam.analysis.defocus.bokeh.bokeh_image`: the
focused prescription, the iris at the f-stop and its shape, cat's-eye vignetting, optionally three
wavelengths), binned on the picture's pixel grid around the pinhole's image of the point (so
distortion shows as the kernel's offset) and turned 180 deg (the lens inverts; the picture is
upright, as physcam's OSL camera renders it).

Brightness: a pinhole pixel holds radiance L; the real lens sends a surface patch's flux
L A Omega to the film, so a kernel sums to ``T = cos(theta) Omega(field, d) / Omega(axis, d)``
(Omega the traced solid angle of the passing rays, theta the object point's angle at the pupil):
a uniform wall renders 1 at the centre and its relative illumination elsewhere, as the OSL camera
normalises it.

Depth nodes are uniform in inverse depth ``u = 1/d`` (the blur diameter is linear in u), anchored
at the focus and spaced so the blur diameter ``b = k (u - u_focus)``, ``k = D_ep f_pin / p`` (p
the pixel pitch, D_ep the entrance pupil diameter), steps by ``step_px + step_rel |b|`` pixels:
node n sits at ``b_n = sign(n) step_px (exp(step_rel |n|) - 1) / step_rel`` (``n step_px`` when
``step_rel`` is 0), so large blurs, where one pixel more is invisible, need few nodes. The node
nearest u = 0 from above stands for infinity. Field nodes are the centres of ``tile`` x ``tile`` pixel tiles.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import InputError, OpticsError, require_finite, require_positive
from ...lens.prescription import Prescription
from ...optics.state import CameraState, takes_camera

__all__ = ["DefocusCamera", "defocus_camera", "Kernel", "KernelCache"]

#: rays traced per kernel pixel (Owen-scrambled Sobol points: a clean histogram at a few dozen per bin)
RAYS_PER_PIXEL = 48
#: the depth of the "infinity" node, mm (10 km: its blur differs from infinity's by
#: D_ep f_pin 1e-7 / p, 0.001 px for a 50 mm f/2.8 on 0.1 mm pixels). Not farther: from 1e9 mm the
#: traced rays lose precision and the kernel grows a halo tens of pixels wide
FAR_MM = 1.0e7


@dataclass
class Kernel:
    """One PSF on the picture grid: ``image`` (2R+1, 2R+1, channels), rows down and columns right,
    the pinhole's image of the point at the centre pixel; each channel sums to ``transmission``."""

    image: np.ndarray
    transmission: tuple[float, ...]
    depth_mm: float  # planar, from the entrance pupil
    field_px: tuple[float, float]  # (x, y) picture position (data-window pixels, y down) of the point

    @property
    def radius(self) -> int:
        return self.image.shape[0] // 2


@dataclass
class DefocusCamera:
    """The camera (lens, focus, stop) and the frame a render is defocused with (see the module notes)."""

    lens: Prescription
    camera: CameraState  # its focus mark from the film (.focus_mm here) and f-stop (.fstop)
    sensor_width_mm: float
    width: int  # display window, pixels
    height: int
    aperture: object = None
    dispersion: bool = False
    tile: int = 64
    step_px: float = 1.0
    step_rel: float = 0.05
    # derived
    film_z: float = 0.0
    stop_semi: float = 0.0
    focused: Prescription | None = None
    pupil_from_film_mm: float = 0.0
    front_from_film_mm: float = 0.0
    pinhole_mm: float = 0.0
    pupil_diameter_mm: float = 0.0
    wavelengths_nm: tuple[float, ...] = ()
    _memory: dict = field(default_factory=dict, repr=False)

    @property
    def focus_mm(self) -> float:
        """The camera's focus mark, from the film."""
        return self.camera.focus_from_film_mm

    @property
    def _traced(self) -> CameraState:
        """The camera the kernels trace: its focus, film and iris, this frame's iris shape, the design
        wavelength (a bokeh's primary; R, G, B when ``dispersion``)."""
        from dataclasses import replace

        return replace(self.camera, aperture=self.aperture, wavelengths_nm=(self.lens.wavelength_nm,), weights=(1.0,))

    @property
    def fstop(self) -> float:
        return self.camera.fstop

    @property
    def pitch_mm(self) -> float:
        return self.sensor_width_mm / self.width

    @property
    def focus_u(self) -> float:
        """Inverse planar depth (1/mm) of the plane of focus, from the entrance pupil."""
        return 1.0 / (self.focus_mm - self.pupil_from_film_mm) if math.isfinite(self.focus_mm) else 0.0

    @property
    def blur_per_u(self) -> float:
        """k: blur diameter (px) per unit of inverse depth (1/mm), thin lens at the entrance pupil."""
        return self.pupil_diameter_mm * self.pinhole_mm / self.pitch_mm

    def blur_px(self, depth_mm):
        """Thin-lens estimate of the blur diameter (px) at planar depth ``depth_mm`` from the pupil."""
        u = 1.0 / np.asarray(depth_mm, dtype=float)
        return self.blur_per_u * np.abs(u - self.focus_u)

    def node_index(self, u):
        """The continuous node index t of inverse depth(s) ``u`` (nodes at whole t; module notes)."""
        b = self.blur_per_u * (np.asarray(u, dtype=float) - self.focus_u)
        if self.step_rel <= 0:
            return b / self.step_px
        return np.sign(b) * np.log1p(self.step_rel * np.abs(b) / self.step_px) / self.step_rel

    def node_far(self) -> int:
        """Index of the farthest node (it stands for infinity)."""
        return -math.floor(-float(self.node_index(0.0)) + 1e-12) if self.focus_u > 0 else 0

    def node_u(self, n):
        """Inverse depth (1/mm) of node(s) ``n``; the farthest node is infinity (0)."""
        n = np.asarray(n)
        t = np.abs(n).astype(float)
        b = self.step_px * (np.expm1(self.step_rel * t) / self.step_rel if self.step_rel > 0 else t)
        return np.where(n <= self.node_far(), 0.0, self.focus_u + np.sign(n) * b / self.blur_per_u)

    def key(self) -> str:
        """A digest of everything the kernels depend on (the disk cache's folder name)."""
        ap = self.aperture
        ap = None if ap is None else [getattr(ap, k, None) for k in ("nsides", "angle_deg", "roundness", "density")]
        text = json.dumps([repr(self.lens), self.focus_mm, self.fstop, self.sensor_width_mm, self.width,
                           self.height, ap, self.dispersion, self.tile, self.step_px, self.step_rel, RAYS_PER_PIXEL], default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def film_point(self, x_px: float, y_px: float) -> tuple[float, float]:
        """Picture position (display-window pixels, y down; edges at integers) to mm from the
        frame centre, x right, y up."""
        return (x_px - self.width / 2) * self.pitch_mm, (self.height / 2 - y_px) * self.pitch_mm

    def kernel(self, x_px: float, y_px: float, depth_mm: float, *, rays_per_pixel: int = RAYS_PER_PIXEL) -> Kernel:
        """The PSF of the object point the pinhole sees at picture (x_px, y_px) at planar depth
        ``depth_mm`` (see the module notes); memoised."""
        from .bokeh import bokeh_image

        mkey = (round(x_px, 6), round(y_px, 6), float(depth_mm), rays_per_pixel)
        if mkey in self._memory:
            return self._memory[mkey]
        d = require_positive("depth", depth_mm)
        sx, sy = self.film_point(x_px, y_px)
        X, Y = sx * d / self.pinhole_mm, sy * d / self.pinhole_mm
        depth_film = self.pupil_from_film_mm + d
        kw = dict(fresnel=False, spectral=self.dispersion, backend="auto")
        pilot = bokeh_image(self._traced, depth_film, X, Y, rays=1000, pixels=8, **kw)
        x0, x1, y0, y1 = pilot.extent_mm
        p = self.pitch_mm
        # the pilot's window is the hits' box centre +- 1.2 x its larger half-span: the farthest hit
        # from the pinhole's image (-sx, -sy) lies within |centre offset| + that half-span
        half = 0.5 * (x1 - x0) / 1.2
        reach = 1.05 * max(abs(0.5 * (x0 + x1) + sx), abs(0.5 * (y0 + y1) + sy)) + 1.05 * half
        r = max(4, math.ceil(reach / p - 0.5) + 1)  # bokeh_image bins at least 8 px a side
        if r > 2048:
            raise OpticsError(f"the blur at depth {d:g} mm is over 4096 pixels across: give a nearer depth limit")
        h = (r + 0.5) * p
        n = 2 * r + 1
        rays = int(min(max(rays_per_pixel * n * n, 20_000), 4_000_000))
        b = bokeh_image(self._traced, depth_film, X, Y, rays=rays, pixels=n, extent_mm=(-sx - h, -sx + h, -sy - h, -sy + h),
                        **kw)
        img = b.image[:, ::-1, :]  # film (y up, x right) turned 180 deg: rows down, columns right
        axis = self._axis_total(d, kw)
        cos_t = d / math.sqrt(d * d + X * X + Y * Y)
        tot = img.sum(axis=(0, 1))
        trans = tuple(float(t / a * cos_t) if a > 0 else 0.0 for t, a in zip(tot, axis))
        with np.errstate(invalid="ignore", divide="ignore"):
            img = np.where(tot > 0, img / np.where(tot > 0, tot, 1.0) * np.array(trans), 0.0)
        k = Kernel(np.ascontiguousarray(_trim(img), dtype=np.float32), trans, d, (x_px, y_px))
        self._memory[mkey] = k
        return k

    def _axis_total(self, d, kw):
        """Omega(axis, d) per channel: the traced solid angle of a point on the axis at this depth."""
        from .bokeh import bokeh_image

        key = ("axis", float(d))
        if key not in self._memory:
            b = bokeh_image(self._traced, self.pupil_from_film_mm + d, rays=40_000, pixels=8, **kw)
            self._memory[key] = b.image.sum(axis=(0, 1))
        return self._memory[key]


def _trim(img: np.ndarray) -> np.ndarray:
    """``img`` cut to the smallest centred square holding all its light."""
    r = img.shape[0] // 2
    ys, xs = np.nonzero(img.sum(axis=2))
    if len(ys) == 0:
        return img[r:r + 1, r:r + 1]
    e = int(max(np.abs(ys - r).max(), np.abs(xs - r).max()))
    return img[r - e:r + e + 1, r - e:r + e + 1]


@takes_camera
def defocus_camera(camera: CameraState, *, width: int, height: int, aperture=None, dispersion: bool = False,
                   tile: int = 64, step_px: float = 1.0, step_rel: float = 0.05) -> DefocusCamera:
    """The :class:`DefocusCamera` of ``camera`` (a :class:`~physcam.optics.state.CameraState`: the lens
    focused at a mark from the film, its iris at an f-stop and its shape, on a sensor whose width is
    imaged on ``width`` x ``height`` pixels, the display window); ``aperture`` (an Aperture or a blade
    count) replaces the camera's iris shape; ``tile`` px per field node; the blur
    step between depth nodes is ``step_px + step_rel x`` the blur diameter (module notes)."""
    from ...optics.focusing import planes_of
    from .bokeh import RGB_WAVELENGTHS_NM

    if camera.film_from_analysis or not camera.iris_set:
        raise InputError("give focus_mm and fstop: a camera focused and stopped by hand, "
                         "physcam.optics.state.camera_state(lens, focus_mm=..., fstop=...)")
    if camera.sensor_mm is None:
        raise InputError("give the sensor: camera_state(lens, ..., sensor=...) (or sensor_mm=(width, height))")
    sw = require_positive("sensor width", camera.sensor_mm[0])
    for name, v in (("width", width), ("height", height)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 1 <= v <= 65536:
            raise InputError(f"image {name} must be a whole number of pixels from 1 to 65536, got {v!r}")
    if isinstance(tile, bool) or not isinstance(tile, (int, np.integer)) or not 8 <= tile <= 1024:
        raise InputError(f"tile must be a whole number of pixels from 8 to 1024, got {tile!r}")
    step = require_positive("depth step", step_px, unit="px")
    if not 0.1 <= step <= 16:
        raise InputError(f"the depth step must lie between 0.1 and 16 px of blur, got {step:g}")
    rel = require_finite("relative depth step", step_rel)
    if not 0 <= rel <= 0.5:
        raise InputError(f"the relative depth step must lie between 0 and 0.5 of the blur, got {rel:g}")
    cam, lens = camera, camera.lens
    # the planes at the mark from the camera's own focus solution, its iris (no focus solved again)
    tp = planes_of(cam.lens_model.focus_state(cam.focus_from_film_mm), stop_semi_diameter=cam.stop_semi_diameter)
    if tp.pinhole_focal_length_mm is None:
        raise OpticsError(f"{lens.name} has no best-match pinhole at this focus (its chief ray does not reach the film)")
    ap = _as_aperture(cam.aperture if aperture is None else aperture)
    return DefocusCamera(lens=lens, camera=cam, sensor_width_mm=sw,
                         width=int(width), height=int(height), aperture=ap, dispersion=bool(dispersion),
                         tile=int(tile), step_px=step, step_rel=rel, film_z=cam.film_z, stop_semi=cam.stop_semi_diameter,
                         focused=cam.focused, pupil_from_film_mm=tp.entrance_pupil_from_film_mm,
                         front_from_film_mm=tp.front_vertex_from_film_mm, pinhole_mm=tp.pinhole_focal_length_mm,
                         pupil_diameter_mm=tp.entrance_pupil_diameter_mm,
                         wavelengths_nm=RGB_WAVELENGTHS_NM if dispersion else (lens.wavelength_nm,))


def _as_aperture(aperture):
    from ...trace.aperture import Aperture

    if aperture is None or isinstance(aperture, Aperture):
        return aperture
    if isinstance(aperture, int) and not isinstance(aperture, bool):
        return Aperture(aperture)
    raise InputError(f"aperture must be a physcam.trace.aperture.Aperture or a blade count, got {aperture!r}")


class KernelCache:
    """Kernels by (field node, depth node), in memory and, with ``folder``, on disk (one ``.npz``
    per kernel under ``folder/<camera key>/``): the frames of a shot, and the Dask workers that
    render them, share it (a kernel is written atomically; two workers racing write the same)."""

    def __init__(self, camera: DefocusCamera, folder=None):
        self.camera = camera
        self.folder = None if folder is None else Path(folder) / camera.key()
        self._mem: dict = {}
        self.traced = 0
        self.loaded = 0

    def node_centre(self, tx: int, ty: int, shape, origin) -> tuple[float, float]:
        """Display-window pixel position of the centre of tile (tx, ty) of a data window of
        ``shape`` (h, w) whose corner is at display position ``origin`` (x, y)."""
        t = self.camera.tile
        h, w = shape
        x0, x1 = tx * t, min((tx + 1) * t, w)
        y0, y1 = ty * t, min((ty + 1) * t, h)
        return origin[0] + 0.5 * (x0 + x1), origin[1] + 0.5 * (y0 + y1)

    def get(self, centre: tuple[float, float], n: int) -> Kernel:
        key = (round(centre[0], 3), round(centre[1], 3), int(n))
        if key in self._mem:
            return self._mem[key]
        path = None
        if self.folder is not None:
            path = self.folder / f"k_{key[0]:.3f}_{key[1]:.3f}_{key[2]}.npz"
            if path.is_file():
                with np.load(path) as z:
                    k = Kernel(z["image"], tuple(z["transmission"]), float(z["depth"]), centre)
                self._mem[key] = k
                self.loaded += 1
                return k
        u = float(self.camera.node_u(n))
        k = self.camera.kernel(centre[0], centre[1], FAR_MM if u <= 0 else 1.0 / u)
        self.traced += 1
        if path is not None:
            _save_npz(path, k)
        self._mem[key] = k
        return k


def _save_npz(path: Path, k: Kernel) -> None:
    import io

    from ...errors import ExportError
    from ...io import atomic_write

    buf = io.BytesIO()
    np.savez(buf, image=k.image, transmission=np.array(k.transmission), depth=k.depth_mm)
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        atomic_write(path, buf.getvalue(), force=False)
    except ExportError:  # another worker wrote the same kernel first
        pass
