"""The lens's own point spread functions for :mod:`physcam.analysis.defocus.render`: a (field x depth) stack.

Geometry (docs/defocus.md): the render is a pinhole picture taken from the lens's **entrance
pupil** with the lens's best-match pinhole focal length ``f_pin`` at this focus
(:attr:`physcam.optics.focusing.TechnicalPlanes.pinhole_focal_length_mm`, the
:attr:`physcam.onset.report.LensReport.pinhole` of the on-set report), on the same sensor. A
picture point (sx, sy) mm from the frame centre (x right, y up) at planar depth ``d`` mm (along
the optical axis, from the plane of the entrance pupil) is the object point (sx d / f_pin,x,
sy d / f_pin,y) in lens space, ``entrance_pupil_from_film + d`` in front of the film. For an
anamorphic lens the pinhole sits at the Y meridian's entrance pupil with that meridian's ``f_pin``,
and its X focal length frames the plane of focus as the lens's X meridian does (from its own
pupil): ``f_pin,x = f_pin(X) s / (s - delta)``, s the focus distance from the Y pupil and delta how
far the X pupil lies in front of it (a Blender camera: the Y focal length, pixel aspect
``f_pin,y / f_pin,x``). A kernel is that point's image traced by physcam's tracer (the focused
prescription, the iris at the f-stop and its shape, cat's-eye vignetting, optionally three
wavelengths), binned on the picture's pixel grid around the lens's image of the point's field
position **on the plane of focus** (:mod:`physcam.analysis.defocus.field`: the output keeps the
pinhole's geometry, distortion is the ST map's) and turned 180 deg (the lens inverts; the picture
is upright, as physcam's OSL camera renders it).

Brightness: a pinhole pixel holds radiance L; the real lens sends a surface patch's flux
L A Omega to the film, so a kernel carries ``T = cos(theta) Omega(field, d) / Omega(axis, d)``
(Omega the traced solid angle of the passing rays, theta the object point's angle at the pupil):
a uniform wall renders 1 at the centre and its relative illumination elsewhere, as the OSL camera
normalises it. Kernels are stored with a unit sum per channel; T is read per pixel
(:class:`~physcam.analysis.defocus.field.FieldTable`).

Depth nodes are uniform in inverse depth ``u = 1/d`` (the blur diameter is linear in u), anchored
at the focus and spaced so the blur diameter ``b = k (u - u_focus)``, ``k = D_ep f_pin / p`` (p
the pixel pitch, D_ep the entrance pupil diameter; the larger meridian's for an anamorphic), steps
by ``step_px + step_rel |b|`` pixels: node n sits at ``b_n = sign(n) step_px (exp(step_rel |n|) -
1) / step_rel`` (``n step_px`` when ``step_rel`` is 0), so large blurs, where one pixel more is
invisible, need few nodes. The node nearest u = 0 from above stands for infinity. Rays are traced
only at the **ladder** nodes (every :data:`LADDER_STEP`-th node, and infinity) and interpolated
in u between them, sample by sample (:mod:`physcam.analysis.defocus.trace`: the defocus part of a
ray's landing point is linear in u; measured error under 0.02 px over 32 nodes on the double
Gauss at 2K); field nodes are spaced by how fast the kernel changes
(:mod:`physcam.analysis.defocus.field`) and interpolated bilinearly.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, OpticsError, require_finite, require_positive
from ...lens.prescription import Prescription
from ...optics.state import CameraState, takes_camera
from .trace import FAR_MM

__all__ = ["DefocusCamera", "defocus_camera", "Kernel", "KernelCache", "FAR_MM", "LADDER_STEP"]

#: rays are traced at every LADDER_STEP-th depth node (module notes)
LADDER_STEP = 8
#: samples per lit kernel pixel, and the most and fewest samples of a fan (powers of two)
SAMPLES_PER_PX, MAX_SAMPLES, MIN_SAMPLES = 8.0, 1 << 16, 1 << 12
#: depth nodes whose thin-lens blur is at most this (px) get kernels traced at each tile corner they
#: are used at, not blended between field nodes: a small aberrated kernel changes its shape and its
#: orientation (coma turns with the azimuth) faster than a few field nodes follow (issue 47)
DIRECT_BLUR_PX = 16.0
#: what the disk cache's files are laid out as and the field grid's rules (part of the camera key)
CACHE_FORMAT = "physcam-defocus-kernels/5"


@dataclass
class Kernel:
    """One PSF on the picture grid: ``image`` (2R+1, 2R+1, channels), rows down and columns right,
    the lens's image of the point's field position on the plane of focus at the centre pixel (the
    pinhole's image moved by ``offset_px``, the lens's distortion there); each channel sums to
    ``transmission``."""

    image: np.ndarray
    transmission: tuple[float, ...]
    depth_mm: float  # planar, from the entrance pupil
    field_px: tuple[float, float]  # (x, y) picture position (display-window pixels, y down) of the point
    offset_px: tuple[float, float] = (0.0, 0.0)

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
    pinhole_mm: float = 0.0  # Y (and X for a spherical lens)
    pupil_diameter_mm: float = 0.0
    pinhole_x_mm: float = 0.0
    pupil_diameter_x_mm: float = 0.0
    wavelengths_nm: tuple[float, ...] = ()
    ladder_step: int = LADDER_STEP
    _memo: dict = field(default_factory=dict, repr=False, compare=False)

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
        """k: blur diameter (px) per unit of inverse depth (1/mm), thin lens at the entrance pupil
        (the larger of the two meridians')."""
        return max(self.pupil_diameter_mm * self.pinhole_mm, self.pupil_diameter_x_mm * self.pinhole_x_mm) / self.pitch_mm

    @property
    def blur_per_u_minor(self) -> float:
        """The same for the meridian of the smaller blur (an anamorphic's oval is narrow one way)."""
        return min(self.pupil_diameter_mm * self.pinhole_mm, self.pupil_diameter_x_mm * self.pinhole_x_mm) / self.pitch_mm

    def blur_px(self, depth_mm):
        """Thin-lens estimate of the blur diameter (px) at planar depth ``depth_mm`` from the pupil."""
        u = 1.0 / np.asarray(depth_mm, dtype=float)
        return self.blur_per_u * np.abs(u - self.focus_u)

    def blur_px_at(self, n):
        """The thin-lens blur diameter (px) at depth node(s) ``n``."""
        return self.blur_per_u * np.abs(self.node_u(n) - self.focus_u)

    def node_index(self, u):
        """The continuous node index t of inverse depth(s) ``u`` (nodes at whole t; module notes)."""
        b = self.blur_per_u * (np.asarray(u, dtype=float) - self.focus_u)
        if self.step_rel <= 0:
            return b / self.step_px
        return np.sign(b) * np.log1p(self.step_rel * np.abs(b) / self.step_px) / self.step_rel

    def node_far(self) -> int:
        """Index of the farthest node (it stands for infinity)."""
        if "far" not in self._memo:
            self._memo["far"] = -math.floor(-float(self.node_index(0.0)) + 1e-12) if self.focus_u > 0 else 0
        return self._memo["far"]

    def node_u(self, n):
        """Inverse depth (1/mm) of node(s) ``n``; the farthest node is infinity (0)."""
        if isinstance(n, (int, np.integer)) and not isinstance(n, bool):  # one node: memoised (thousands of calls a frame)
            key = ("u", int(n))
            if key not in self._memo:
                self._memo[key] = np.float64(self._node_u(np.asarray(n)))
            return self._memo[key]
        return self._node_u(np.asarray(n))

    def _node_u(self, n):
        t = np.abs(n).astype(float)
        b = self.step_px * (np.expm1(self.step_rel * t) / self.step_rel if self.step_rel > 0 else t)
        return np.where(n <= self.node_far(), 0.0, self.focus_u + np.sign(n) * b / self.blur_per_u)

    def ladder(self, n: int) -> tuple[int, int]:
        """The ladder nodes (traced; module notes) at or around depth node ``n``."""
        key = ("ladder", int(n))
        if key not in self._memo:
            self._memo[key] = self._ladder(int(n))
        return self._memo[key]

    def _ladder(self, n: int) -> tuple[int, int]:
        n, far, k = int(n), self.node_far(), self.ladder_step
        if n <= far:
            return far, far
        a = max(k * math.floor(n / k), far)
        return (a, a) if a == n else (a, max(a + 1, k * math.floor(n / k) + k))

    def ladder_weight(self, n: int) -> tuple[float, float]:
        """The weights of the two ladder nodes around ``n`` (linear in u)."""
        key = ("weight", int(n))
        if key in self._memo:
            return self._memo[key]
        a, b = self.ladder(n)
        if a == b:
            return 1.0, 0.0
        ua, ub, u = (float(self.node_u(m)) for m in (a, b, n))
        s = (u - ua) / (ub - ua)
        self._memo[key] = (1.0 - s, s)
        return 1.0 - s, s

    def samples(self, a: int, b: int) -> int:
        """Samples per fan for the ladder interval a..b (a power of two, from the larger blur)."""
        key = ("samples", int(a), int(b))
        if key not in self._memo:
            self._memo[key] = self._samples(a, b)
        return self._memo[key]

    def _samples(self, a: int, b: int) -> int:
        blur = float(max(self.blur_px_at(a), self.blur_px_at(b))) + 2.0
        want = SAMPLES_PER_PX * 0.25 * math.pi * blur * blur
        return int(min(MAX_SAMPLES, max(MIN_SAMPLES, 1 << max(0, math.ceil(math.log2(want))))))

    def key(self) -> str:
        """A digest of everything the kernels depend on (the disk cache's folder name)."""
        ap = self.aperture
        ap = None if ap is None else [getattr(ap, k, None) for k in ("nsides", "angle_deg", "roundness", "density")]
        text = json.dumps([repr(self.lens), self.focus_mm, self.fstop, self.sensor_width_mm, self.width,
                           self.height, ap, self.dispersion, self.step_px, self.step_rel, self.ladder_step,
                           SAMPLES_PER_PX, MAX_SAMPLES, MIN_SAMPLES, CACHE_FORMAT], default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def film_point(self, x_px: float, y_px: float) -> tuple[float, float]:
        """Picture position (display-window pixels, y down; edges at integers) to mm from the
        frame centre, x right, y up."""
        return (x_px - self.width / 2) * self.pitch_mm, (self.height / 2 - y_px) * self.pitch_mm

    def kernels(self, points) -> list[Kernel]:
        """The PSFs of the object points the pinhole sees at picture positions ``points`` (x_px,
        y_px, planar depth mm), each traced at its own position and depth (not interpolated), with
        its transmission T (module notes), centred on its light's centroid (``offset_px`` from the
        pinhole's image); traced in one batch."""
        from .field import _trim, box_depths
        from .trace import bin_fan, distortion_jacobians, fan_centroid, pupil_boxes, trace_fans

        pts = [(float(x), float(y)) for x, y, _ in points]
        ds = [min(require_positive("depth", d), FAR_MM) for _, _, d in points]
        axis = (self.width / 2, self.height / 2)
        boxes = pupil_boxes(self, pts + [axis], box_depths(self))
        jobs = []
        for p, d, box in zip(pts, ds, boxes):
            t = float(self.node_index(1.0 / d))
            n = self.samples(math.floor(t), math.ceil(t))
            jobs += [(p, 1.0 / d, box, n), (axis, 1.0 / d, boxes[-1], n)]
        fans = trace_fans(self, jobs)
        unwarps = np.linalg.inv(distortion_jacobians(self, pts))
        out, ch = [], len(self.wavelengths_nm)
        for i, ((x, y), d) in enumerate(zip(pts, ds)):
            fan, ax_fan = fans[2 * i], fans[2 * i + 1]
            centre = fan_centroid(fan)
            img, tot = bin_fan(fan, centre, ch, unwarps[i])
            ax = np.bincount(ax_fan.ch, weights=ax_fan.w, minlength=ch)[:ch]
            sx, sy = self.film_point(x, y)
            cos_t = d / math.sqrt(d * d + (sx * d / self.pinhole_x_mm) ** 2 + (sy * d / self.pinhole_mm) ** 2)
            trans = tuple(float(t / a * cos_t) if a > 0 else 0.0 for t, a in zip(tot, ax))
            with np.errstate(invalid="ignore", divide="ignore"):
                img = np.where(tot > 0, img / np.where(tot > 0, tot, 1.0) * np.array(trans), 0.0)
            out.append(Kernel(np.ascontiguousarray(_trim(img), dtype=np.float32), trans, d, (x, y), centre))
        return out

    def kernel(self, x_px: float, y_px: float, depth_mm: float) -> Kernel:
        """The PSF of the object point the pinhole sees at picture (x_px, y_px) at planar depth
        ``depth_mm`` (:meth:`kernels`)."""
        return self.kernels([(x_px, y_px, depth_mm)])[0]


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
    stop_semi = cam.with_aperture(ap).iris_corner_semi  # a bladed iris of the round one's area (docs/conventions.md)
    fx, dx = _x_meridian(lens, cam.focus_from_film_mm, cam.fstop, tp)
    return DefocusCamera(lens=lens, camera=cam, sensor_width_mm=sw,
                         width=int(width), height=int(height), aperture=ap, dispersion=bool(dispersion),
                         tile=int(tile), step_px=step, step_rel=rel, film_z=cam.film_z, stop_semi=stop_semi,
                         focused=cam.focused, pupil_from_film_mm=tp.entrance_pupil_from_film_mm,
                         front_from_film_mm=tp.front_vertex_from_film_mm, pinhole_mm=tp.pinhole_focal_length_mm,
                         pupil_diameter_mm=tp.entrance_pupil_diameter_mm, pinhole_x_mm=fx, pupil_diameter_x_mm=dx,
                         wavelengths_nm=RGB_WAVELENGTHS_NM if dispersion else (lens.wavelength_nm,))


def _x_meridian(lens, focus_mm, fstop, tp) -> tuple[float, float]:
    """The render's X focal length and the X entrance pupil's diameter (module notes): the Y
    meridian's for a spherical lens; for an anamorphic, its X pinhole seen from the Y pupil, so that
    it frames the plane of focus as the lens does."""
    from ...optics.focusing import technical_planes

    if not lens.is_anamorphic:
        return tp.pinhole_focal_length_mm, tp.entrance_pupil_diameter_mm
    tx = technical_planes(lens, focus_mm, fstop=fstop, axis="x")
    if tx.pinhole_focal_length_mm is None:
        raise OpticsError(f"{lens.name} has no best-match pinhole in X at this focus (its chief ray does not reach the film)")
    delta = tx.entrance_pupil_from_film_mm - tp.entrance_pupil_from_film_mm
    s = focus_mm - tp.entrance_pupil_from_film_mm
    scale = s / (s - delta) if math.isfinite(s) else 1.0
    return tx.pinhole_focal_length_mm * scale, tx.entrance_pupil_diameter_mm


def _place(x, y, n) -> tuple[float, float, int]:
    """The key of a tile corner's kernel: picture position (px, to a thousandth) and depth node."""
    return round(float(x), 3), round(float(y), 3), int(n)


def _ready_tracer() -> None:
    """Load the JIT tracer now (when numba is installed and ``PHYSCAM_BACKEND`` allows it): a frame's
    kernels are millions of rays, so the numpy kernel's budget for short jobs
    (:mod:`physcam.trace.kernels`, "auto") would only be spent before numba loads anyway. Both
    kernels give the same rays."""
    from ...trace.kernels import resolve_backend

    resolve_backend("auto")


def _as_aperture(aperture):
    from ...trace.aperture import Aperture

    if aperture is None or isinstance(aperture, Aperture):
        return aperture
    if isinstance(aperture, int) and not isinstance(aperture, bool):
        return Aperture(aperture)
    raise InputError(f"aperture must be a physcam.trace.aperture.Aperture or a blade count, got {aperture!r}")


class KernelCache:
    """Kernels by (field node, depth node), in memory and, with ``folder``, on disk under
    ``folder/<camera key>/`` (:mod:`physcam.analysis.defocus.cache`: stack files written whole,
    checked when read): the frames of a shot, and the Dask workers that render them, share it.

    :meth:`prepare` traces what a frame needs in batches (module notes); :meth:`tile_kernel` is a
    tile's kernel, the bilinear blend of its four field nodes' (unit sum per channel);
    :meth:`transmission` is T per pixel. ``traced`` and ``loaded`` count node kernels made from
    traced rays and read from disk."""

    def __init__(self, camera: DefocusCamera, folder=None):
        from pathlib import Path

        from ...errors import require_type

        require_type("camera", camera, DefocusCamera, "physcam.analysis.defocus.kernels.defocus_camera(lens, ...)")
        self.camera = camera
        self.folder = None if folder is None else Path(folder) / camera.key()
        self.traced = 0
        self.loaded = 0
        self._fractions = None
        self._kernels: dict = {}
        self._table = None
        self._tiles: dict = {}
        self._direct: dict = {}
        self._places: dict = {}
        self._read = False

    # ---- the field grid -----------------------------------------------------------------------
    def _load(self) -> None:
        """Read the disk cache once (damaged files warn and are traced again)."""
        if self._read:
            return
        self._read = True
        if self.folder is None:
            return
        from .cache import read_stacks
        from .field import FieldTable, _table_positions

        fractions, kernels, table, direct = read_stacks(self.folder, self.camera.key(), CACHE_FORMAT,
                                                len(self.camera.wavelengths_nm))
        if fractions is None:
            return
        self._fractions = tuple(float(f) for f in fractions)
        self._kernels.update(kernels)
        self._direct.update(direct)
        self.loaded += len(kernels) + len(direct)
        radial, qx, qy = _table_positions(self.camera)
        if table is not None and table[:2] == (radial, len(qx)):
            self._table = FieldTable(radial, qx, qy, dict(table[2]))

    @property
    def fractions(self) -> tuple[float, ...]:
        """The field nodes' fractions of the half-frame (:func:`physcam.analysis.defocus.field.field_fractions`)."""
        self._load()
        if self._fractions is None:
            from .field import field_fractions

            _ready_tracer()
            self._fractions = field_fractions(self.camera)
        return self._fractions

    @property
    def grid(self) -> tuple[np.ndarray, np.ndarray]:
        """The field nodes' columns and rows (display px)."""
        from .field import grid_nodes

        if getattr(self, "_grid", None) is None or self._grid[0] != self.fractions:
            self._grid = (self.fractions, grid_nodes(self.camera, self.fractions))
        return self._grid[1]

    @staticmethod
    def _cell(nodes: np.ndarray, x: float) -> list[tuple[int, float]]:
        """The nodes around ``x`` and their linear weights (clamped at the ends)."""
        import bisect

        i = min(max(bisect.bisect_right(nodes.tolist(), x) - 1, 0), len(nodes) - 2)
        w = min(max((x - float(nodes[i])) / float(nodes[i + 1] - nodes[i]), 0.0), 1.0)
        return [(i, 1.0 - w)] + ([(i + 1, w)] if w > 0 else [])

    def nodes_of(self, x: float, y: float) -> list[tuple[int, int, float]]:
        """The field nodes (column, row) whose kernels blend into the kernel at picture (x, y), with weights."""
        cols, rows = self.grid
        cx, cy = self._cell(cols, float(x)), self._cell(rows, float(y))
        return [(i, j, wi * wj) for i, wi in cx for j, wj in cy if wi * wj > 0]

    # ---- tracing ------------------------------------------------------------------------------
    def prepare(self, needed, progress=None, direct=()) -> None:
        """Make every node kernel of ``needed`` ((column, row, depth node) triples), every kernel of
        ``direct`` ((x, y, depth node) of a small blur: :meth:`trace_direct`) and the transmission
        table at their depths: read from disk, else traced in batches; the new ones are written to
        the folder as one stack file."""
        from .field import field_table

        self._load()
        cam = self.camera
        needed, direct = set(needed), list(direct)
        ladder = {m for _, _, n in [*needed, *direct] for m in cam.ladder(n)} | {0}
        old_table = set() if self._table is None else set(self._table.transmission)
        if needed - set(self._kernels) or ladder - old_table or {_place(*p) for p in direct} - set(self._direct):
            _ready_tracer()
        self._table = field_table(cam, self._table, ladder)
        missing = sorted(k for k in needed if k not in self._kernels)
        new = self._trace(missing, progress) if missing else {}
        self._kernels.update(new)
        self.traced += len(new)
        new_direct = self.trace_direct(direct)
        if self.folder is not None:
            from .cache import write_stack

            t = self._table
            rows = {n: t.transmission[n] for n in set(t.transmission) - old_table}
            self.folder.mkdir(parents=True, exist_ok=True)
            write_stack(self.folder, cam.key(), CACHE_FORMAT, self.fractions, new, (t.radial, len(t.qx), rows),
                        new_direct)

    def _trace(self, missing, progress) -> dict:
        """Node kernels of ``missing`` from fans traced at their ladder nodes, field node by field
        node in batches of about 4 million rays."""
        from .field import box_depths, node_kernel
        from .trace import distortion_jacobians, pupil_boxes, trace_fans

        cam = self.camera
        cols, rows = self.grid
        by_node: dict = {}
        for c, r, n in missing:
            by_node.setdefault((c, r), []).append(n)
        plans = []
        for (c, r), ns in sorted(by_node.items()):
            need: dict = {}
            for n in ns:
                a, b = cam.ladder(n)
                k = cam.samples(a, b)
                for m in (a, b):
                    need[m] = max(need.get(m, 0), k)
            plans.append(((c, r), (float(cols[c]), float(rows[r])), need, ns))
        out, done = {}, 0
        box_us = box_depths(cam)
        while plans:
            batch, total = [], 0
            while plans and (not batch or total + sum(plans[0][2].values()) <= 4 << 20):
                batch.append(plans.pop(0))
                total += sum(batch[-1][2].values())
            boxes = pupil_boxes(cam, [p for _, p, _, _ in batch], box_us)
            jobs = [(p, float(cam.node_u(m)), box, k) for (_, p, need, _), box in zip(batch, boxes)
                    for m, k in sorted(need.items())]
            fans = iter(trace_fans(cam, jobs))
            unwarps = iter(np.linalg.inv(distortion_jacobians(cam, [p for _, p, _, _ in batch])))
            for (cr, p, need, ns) in batch:
                unwarp = next(unwarps)
                got = {m: next(fans) for m in sorted(need)}
                maps, cut = {}, {}
                for n in ns:
                    a, b = cam.ladder(n)
                    k = cam.samples(a, b)
                    if (a, b) not in cut:  # one prefix pair per interval, so its pupil map is fitted once
                        cut[(a, b)] = (got[a].prefix(k), got[b].prefix(k))
                    img, _ = node_kernel(cam, *cut[(a, b)], n, maps, unwarp)
                    out[cr + (n,)] = img
                done += len(ns)
                if progress is not None:
                    progress(done, len(missing))
        return out

    def trace_direct(self, points) -> dict:
        """Trace, in one batch, the kernels at picture positions and depth nodes ``points`` ((x, y, n)
        triples) of a small blur (:data:`DIRECT_BLUR_PX`), each at its own place and its node's own
        depth, so that :meth:`tile_kernel` reads them instead of blending field nodes; returns the new ones."""
        from .field import box_depths, direct_kernels
        from .trace import distortion_jacobians, pupil_boxes, trace_fans

        cam = self.camera
        todo = sorted({_place(x, y, n) for x, y, n in points} - set(self._direct))
        places = sorted({(x, y) for x, y, _ in todo} - set(self._places))
        if places:  # a place's sampling box and unwarp serve all its depths (box_depths: one set per camera)
            boxes = pupil_boxes(cam, places, box_depths(cam))
            self._places.update(zip(places, zip(boxes, np.linalg.inv(distortion_jacobians(cam, places)))))
        for b in range(0, len(todo), 512):
            part = todo[b:b + 512]
            fans = trace_fans(cam, [((x, y), float(cam.node_u(n)), self._places[(x, y)][0], cam.samples(n, n))
                                    for x, y, n in part])
            self._direct.update(zip(part, direct_kernels(cam, fans, [self._places[key[:2]][1] for key in part])))
        self.traced += len(todo)
        return {k: self._direct[k] for k in todo}

    # ---- what defocus reads -------------------------------------------------------------------
    def node_kernel(self, col: int, row: int, n: int) -> np.ndarray:
        """The kernel of field node (col, row) at depth node ``n`` (unit sum per channel)."""
        key = (int(col), int(row), int(n))
        if key not in self._kernels:
            self.prepare([key])
        return self._kernels[key]

    def tile_kernel(self, x: float, y: float, n: int) -> np.ndarray:
        """The kernel at picture (x, y), depth node ``n``: its field nodes' kernels blended
        bilinearly (unit sum per channel)."""
        key = (round(float(x), 3), round(float(y), 3), int(n))
        if key in self._direct:
            return self._direct[key]
        if key not in self._tiles:
            parts = [(w, self.node_kernel(c, r, n)) for c, r, w in self.nodes_of(x, y)]
            size = max(k.shape[0] for _, k in parts)
            out = np.zeros((size, size, parts[0][1].shape[2]), dtype=np.float32)
            for w, k in parts:
                p = (size - k.shape[0]) // 2
                out[p:p + k.shape[0], p:p + k.shape[0]] += np.float32(w) * k
            self._tiles[key] = out
        return self._tiles[key]

    def scaled_kernel(self, x: float, y: float, n: int, s: int, scale) -> np.ndarray:
        """:meth:`tile_kernel` made ``s`` times coarser by ``scale(kernel, s)`` (memoised)."""
        key = (round(float(x), 3), round(float(y), 3), int(n), int(s))
        if key not in self._tiles:
            self._tiles[key] = scale(self.tile_kernel(x, y, n), s)
        return self._tiles[key]

    def transmission(self, x, y, n: int) -> np.ndarray:
        """T (..., channels) at picture positions (x, y) (arrays) and depth node ``n``."""
        if self._table is None or any(m not in self._table.transmission for m in self.camera.ladder(n)):
            from .field import field_table

            self._load()
            self._table = field_table(self.camera, self._table, set(self.camera.ladder(n)) | {0})
        return self._table.transmission_at(self.camera, x, y, n)

    def node_centre(self, tx: int, ty: int, shape, origin) -> tuple[float, float]:
        """Display-window pixel position of the centre of tile (tx, ty) of a data window of
        ``shape`` (h, w) whose corner is at display position ``origin`` (x, y)."""
        t = self.camera.tile
        h, w = shape
        x0, x1 = tx * t, min((tx + 1) * t, w)
        y0, y1 = ty * t, min((ty + 1) * t, h)
        return origin[0] + 0.5 * (x0 + x1), origin[1] + 0.5 * (y0 + y1)

    def get(self, centre: tuple[float, float], n: int) -> Kernel:
        """The kernel at picture position ``centre``, depth node ``n``, each channel summing to T there."""
        self.prepare({(c, r, int(n)) for c, r, _ in self.nodes_of(*centre)})
        t = self.transmission(np.array(centre[0]), np.array(centre[1]), n)
        u = float(self.camera.node_u(n))
        img = self.tile_kernel(centre[0], centre[1], n) * t.reshape(1, 1, -1)
        return Kernel(img, tuple(float(v) for v in np.ravel(t)), FAR_MM if u <= 0 else 1.0 / u, tuple(centre))
