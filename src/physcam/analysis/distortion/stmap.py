"""Distortion over the full 2-D field at any focus, and ST-maps for compositing (docs/analyses.md).

**The field.** The lens (a camera state, :mod:`physcam.optics.state`) is focused at its mark (mm from the film plane, as
:func:`physcam.optics.focusing.focus` does it: unit or internal focusing). For film points on a
coarse regular grid covering the sensor (about one node per 32 pixels, edges included), the real
chief ray is traced backward from the film through the centre of the stop
(:func:`physcam.analysis._chief.aim_from_film`) and out to the object plane at the focus distance
(at infinity focus: its direction). The ideal image of that object point is the one of physcam's
best-match pinhole at that focus: focal length ``GaussianData.pinhole_focal_length`` and centre
of projection at the entrance pupil, per meridian (X and Y differ for anamorphic lenses)::

    ideal (mm, upright picture) = f_pin,x X / (z_obj - z_ep,x),  f_pin,y Y / (z_obj - z_ep,y)   (signs: see code)

Between the nodes the mapping is interpolated by cubic convolution (Keys 1981, a = -1/2, third
order accurate, with Keys' boundary rule), separably on the regular grid. Its error is measured,
not assumed: real chief rays are traced at every grid cell's centre and compared with the
interpolant (``interpolation_error_px``); likewise the inverse map (``inverse_error_px``).

**At a stop.** A chief ray is where a small stop images a point. With the iris set to an f-stop (a
:class:`~physcam.optics.state.CameraState` made with ``fstop``, or ``fstop`` with a Prescription)
the field is the lens's **centroid** distortion at that f-stop (the state's iris,
``CameraState.stop_semi_diameter``): each node's real position is the energy
centroid of its object point's blur (:func:`physcam.analysis.centroid.image_centroids`), found by
aiming the chief ray from the node, measuring the centroid's offset from the node and aiming again
from the node moved back by that offset (the offset changes slowly across the field, so one step
leaves a residual of its square). Every field says which stop it is for (``fstop``, None: chief
rays) and its **residual there**: RMS and largest distance, in plate pixels, between the
interpolated field and independently traced positions at every grid cell's centre (chief rays for a
chief-ray field, centroids at the stop for a centroid field), ``residual_px``.

**Pixels.** Plate pixel coordinates are continuous, x from the left edge, y from the bottom edge
of the upright picture (the film image turned by 180 degrees); pixel (i, j) has its centre at
(i + 0.5, j + 0.5). Scale: ``width_px / sensor_width_mm`` and ``height_px / sensor_height_mm``.

**ST-maps** (compositing convention, Nuke's STMap node): an output pixel takes its colour from
the input image at (R width_in, G height_in), R = u and G = v normalised 0..1, origin bottom-left,
pixel centres at (i + 0.5) / width; B = 0.

* The **undistortion map** turns the plate (distorted, width x height) into the undistorted image
  of (width + 2 ox) x (height + 2 oy) pixels: the overscan ox, oy is the smallest symmetric
  margin whose bounding box keeps the ideal position of every plate pixel. Its R, G are
  normalised to the plate; outside the plate's ideal image they lie outside 0..1 (no source).
  Its EXR file carries its own frame (the OpenEXR and Nuke convention): display window = the
  plate's frame (0, 0)-(width - 1, height - 1), data window = the overscanned region
  (-ox, -oy)-(width + ox - 1, height + oy - 1).
* **Desqueezed** (``desqueeze=True``, an anamorphic lens): the undistorted image is the round pinhole's,
  in square pixels: width' = round(width x a) columns, a = f_pin,y / f_pin,x at this focus (the pixel
  aspect of physcam's 3DE4 anamorphic fits), its overscan in those pixels. A column x' of it is the
  squeezed ideal position x' width / width' (so its pixels are square to 0.5 / width'). The
  undistortion map turns the squeezed plate into that picture in one STMap; the distortion map is
  unchanged (its values are normalised, and the desqueezed frame is the squeezed one stretched).
* The **distortion map** (width x height) turns such an undistorted image back into the plate;
  its R, G are normalised to the undistorted image's frame, which is the plate's (its display
  window): values below 0 and above 1 reach into the overscan (its data window). OpenImageIO's
  ``st_warp`` and Nuke's STMap read a source's coordinates so (tests/analysis/distortion/test_stmap_windows.py).

Map arrays are image arrays: row 0 is the top row (as in EXR and PNG files).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import ExportError, InputError, OpticsError, require_positive
from ...lens.prescription import Prescription
from ...optics.state import CameraState, takes_camera

__all__ = ["DistortionField", "distortion_field", "apply_stmap", "write_stmaps", "write_map_exr", "write_map_png", "MAX_SIDE_PX", "MAX_PIXELS"]

#: Largest width or height (pixels) and largest frame (pixels) a map is made for.
MAX_SIDE_PX = 8192
MAX_PIXELS = 36_000_000
#: The farthest the ideal (pinhole) image of the frame may reach, in frame half-sizes from the centre.
MAX_PINHOLE_REACH = 3.0
#: Grid spacing (pixels) of the traced chief rays and of the inverse's nodes.
NODE_SPACING_PX = 32.0
#: Rows of a map computed at once (an 8K map is built and encoded in blocks: docs/performance.md).
ROW_BLOCK = 256


def _keys_weights(s):
    """Cubic-convolution weights (n, 4) for offsets s in a cell (a = -1/2)."""
    s2, s3 = s * s, s * s * s
    return 0.5 * np.stack([-s3 + 2 * s2 - s, 3 * s3 - 5 * s2 + 2, -3 * s3 + 4 * s2 + s, s3 - s2], axis=-1)


def _pad(g, axis):
    """Keys' boundary rule: one extra node each side along ``axis``, f(-1) = 3 f0 - 3 f1 + f2."""
    g = np.moveaxis(g, axis, 0)
    lo = 3 * g[0] - 3 * g[1] + g[2]
    hi = 3 * g[-1] - 3 * g[-2] + g[-3]
    return np.moveaxis(np.concatenate([lo[None], g, hi[None]]), 0, axis)


def _cell(t, n):
    """Cell index (into the padded nodes' first of four) and offset for node coordinates t (n nodes)."""
    i = np.clip(np.floor(t), 0, n - 2).astype(int)
    return i, t - i  # offsets beyond [0, 1] extrapolate with the edge cell's cubic


def _matrix(t, n):
    """(len(t), n + 2) interpolation matrix onto the padded nodes."""
    i, s = _cell(np.asarray(t, dtype=float), n)
    m = np.zeros((i.size, n + 2))
    w = _keys_weights(s)
    rows = np.arange(i.size)
    for k in range(4):
        m[rows, i + k] += w[:, k]
    return m


class _Grid:
    """A vector field (ny, nx, 2) on a regular grid of nodes x0 + k dx, y0 + l dy, interpolated."""

    def __init__(self, values, x0, dx, y0, dy):
        self.ny, self.nx = values.shape[:2]
        self.p = _pad(_pad(np.asarray(values, dtype=float), 0), 1)
        self.x0, self.dx, self.y0, self.dy = x0, dx, y0, dy

    def at(self, x, y):
        """Values (n, 2) at scattered points."""
        ix, sx = _cell((np.asarray(x, float) - self.x0) / self.dx, self.nx)
        iy, sy = _cell((np.asarray(y, float) - self.y0) / self.dy, self.ny)
        wx, wy = _keys_weights(sx), _keys_weights(sy)
        out = np.zeros((ix.size, 2))
        for a in range(4):
            for b in range(4):
                out += (wy[:, a] * wx[:, b])[:, None] * self.p[iy + a, ix + b]
        return out

    def row_blocks(self, width, height, origin=(0.0, 0.0), rows=ROW_BLOCK):
        """Values at pixel centres origin + (i + 0.5, j + 0.5), rows top first, as (first row, [x values,
        y values], each (n, width)) for blocks of ``rows`` rows: a full 8K frame of float64 pairs would be
        0.5 GB. Separable: every padded row of nodes is interpolated across the frame once ((ny + 2, width)
        per channel), then a block's rows mix only the few node rows their cubic reaches (a band of
        ``rows`` / dy + 4): the dense product over every node row and column cost ~20x the arithmetic
        (one pass over an 8K frame 2.3 -> 0.65 s CPU; docs/performance.md). The two arrays of a block are
        written into the same two buffers block after block (valid until the next block is asked for): a new
        16 MB pair per block of an 8K frame was mapped fresh from the system each time and faulted in page by
        page (the same products, bit for bit; an 8K field 3.60 -> 3.33 s CPU, docs/performance.md, round 20)."""
        mx = _matrix((origin[0] + np.arange(width) + 0.5 - self.x0) / self.dx, self.nx)
        across = [self.p[:, :, c] @ mx.T for c in range(2)]
        my = _matrix((origin[1] + np.arange(height) + 0.5 - self.y0) / self.dy, self.ny)[::-1]  # top row first
        buffers = [np.empty((min(rows, height), width)) for _ in across]
        for r0 in range(0, height, rows):
            m = my[r0:r0 + rows]
            used = np.flatnonzero(m.any(axis=0))
            lo, hi = (used[0], used[-1] + 1) if used.size else (0, 1)
            band = np.ascontiguousarray(m[:, lo:hi])  # my[::-1]'s negative strides would keep matmul off BLAS
            yield r0, [np.matmul(band, a[lo:hi], out=b[:len(band)]) for a, b in zip(across, buffers)]

    def fill(self, out, scale, offset=(0.0, 0.0), origin=(0.0, 0.0)):
        """Write (value + offset) / scale into channels 0 and 1 of the image ``out`` (h, w, >= 2), block by block."""
        h, w = out.shape[:2]
        for r0, v in self.row_blocks(w, h, origin):
            for c in range(2):
                v[c] += offset[c]
                v[c] /= scale[c]
                out[r0:r0 + v[c].shape[0], :, c] = v[c]


def _nodes(extent_px, spacing=NODE_SPACING_PX):
    n = max(5, int(math.ceil(extent_px / spacing)) + 1)
    return n, extent_px / (n - 1)


@dataclass
class DistortionField:
    """Real against ideal pixel positions over the frame of ``camera`` at its focus, and the two ST-maps."""

    lens_name: str
    camera: CameraState  # the camera mapped: its focus (.focus_from_film_mm) and iris (.fstop below)
    wavelength_nm: float
    sensor_mm: tuple[float, float]
    size_px: tuple[int, int]  # plate width, height
    pinhole_focal_length_mm: tuple[float, float]  # (x, y) meridians
    entrance_pupil_from_film_mm: tuple[float, float]
    overscan_px: tuple[int, int]  # ox, oy: the undistorted image is (w + 2 ox) x (h + 2 oy)
    grid_nodes: tuple[int, int]
    interpolation_error_px: float  # max |interpolated - traced| ideal position at the grid cells' centres
    inverse_error_px: float  # max |D(U(q)) - q| at the inverse grid cells' centres
    max_distortion_px: float  # largest |ideal - real| over the traced nodes
    residual_px: tuple[float, float]  # (RMS, max) |field - traced| at the cell centres, at that stop
    distortion_stmap: np.ndarray | None = field(repr=False)  # (h, w, 3) float32; None when made without maps
    undistortion_stmap: np.ndarray | None = field(repr=False)  # (h + 2 oy, w + 2 ox, 3) float32; or None
    notes: list[str] = field(default_factory=list)
    _forward: _Grid | None = field(default=None, repr=False)
    #: Every traced chief ray (grid nodes and cell centres): real and ideal plate pixels (n, 2) each
    traced_real_px: np.ndarray | None = field(default=None, repr=False)
    traced_ideal_px: np.ndarray | None = field(default=None, repr=False)
    #: The undistorted picture's frame (its EXR display window), px: the plate's, or desqueezed (module notes)
    undistorted_frame_px: tuple[int, int] | None = None

    @property
    def focus_from_film_mm(self) -> float:
        """The camera's focus mark in front of the film (inf at infinity)."""
        return self.camera.focus_from_film_mm

    @property
    def fstop(self) -> float | None:
        """The stop whose centroids the field maps (the camera's iris set to an f-stop); None: chief rays (a
        small stop)."""
        return self.camera.fstop if self.camera.iris_set else None

    @property
    def frame_px(self) -> tuple[int, int]:
        """The undistorted picture's frame (width, height) px, without the overscan: the plate's, or
        the desqueezed one (module notes)."""
        return self.undistorted_frame_px or self.size_px

    def ideal_from_real(self, xy_px) -> np.ndarray:
        """Ideal (undistorted) plate pixel positions (n, 2) of real ones (interpolated field)."""
        p = np.atleast_2d(np.asarray(xy_px, dtype=float))
        return self._forward.at(p[:, 0], p[:, 1])

    def to_dict(self) -> dict:
        return {
            "lens": self.lens_name,
            "focus_from_film_mm": None if math.isinf(self.focus_from_film_mm) else self.focus_from_film_mm,
            "wavelength_nm": self.wavelength_nm, "sensor_mm": list(self.sensor_mm), "size_px": list(self.size_px),
            "pinhole_focal_length_mm": {"x": self.pinhole_focal_length_mm[0], "y": self.pinhole_focal_length_mm[1]},
            "entrance_pupil_from_film_mm": {"x": self.entrance_pupil_from_film_mm[0],
                                            "y": self.entrance_pupil_from_film_mm[1]},
            "overscan_px": list(self.overscan_px),
            "undistorted_frame_px": list(self.frame_px),
            "undistorted_size_px": [self.frame_px[0] + 2 * self.overscan_px[0], self.frame_px[1] + 2 * self.overscan_px[1]],
            "desqueeze": self.frame_px[0] / self.size_px[0],
            "grid_nodes": list(self.grid_nodes), "interpolation_error_px": self.interpolation_error_px,
            "inverse_error_px": None if math.isnan(self.inverse_error_px) else self.inverse_error_px,
            "maps": self.distortion_stmap is not None, "max_distortion_px": self.max_distortion_px,
            "fstop": self.fstop,
            "map_for": "chief rays (a small stop)" if self.fstop is None else
            f"the blur centroids at f/{self.fstop:g}",
            "residual_px": {"rms": self.residual_px[0], "max": self.residual_px[1]},
            "convention": "ST-map: R = u, G = v, 0..1, origin bottom-left, pixel centres at (i + 0.5) / width; B = 0",
            "notes": list(self.notes),
        }


def _size(name, v) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 16 <= v <= MAX_SIDE_PX:
        raise InputError(f"the {name} must be a whole number of pixels from 16 to {MAX_SIDE_PX}, got {v!r}")
    return int(v)


def _real_to_ideal(q, gx, gy, st, film_xy, wl, backend, objects=False):
    """Trace chief rays backward from film points (n, 2) mm; ideal upright picture mm (n, 2) and ok.
    With ``objects``, also the object points (or light directions at infinity) and where the chief
    rays cross the Y meridian's entrance-pupil plane (for :func:`physcam.analysis.centroid.image_centroids`)."""
    from ...trace import RayBatch, trace_through
    from .._chief import aim_from_film

    aimed = aim_from_film(q, film_xy, st.film_z, wavelength_nm=wl, backend=backend)
    out = trace_through(q, RayBatch.from_arrays(aimed.start, aimed.direction, wl), reverse=True, backend=backend)
    ok = aimed.ok & out.ok & (out.N < -1e-9)
    N = np.where(ok, out.N, -1.0)
    if math.isinf(st.object_z):  # the object point lies along the ray: its tangents
        tx, ty = out.L / -N, out.M / -N
    else:
        t = (st.object_z - out.z) / N
        X, Y = out.x + t * out.L, out.y + t * out.M
        tx = X / (gx.z_entrance_pupil - st.object_z)
        ty = Y / (gy.z_entrance_pupil - st.object_z)
    # the upright picture is the film image turned by 180 degrees: a scene point at +X lands at -x
    # on the film and at +x in the picture, at f_pin tan(angle) from the centre
    ideal = np.stack([gx.pinhole_focal_length * tx, gy.pinhole_focal_length * ty], axis=1)
    if not objects:
        return np.where(ok[:, None], ideal, 0.0), ok
    s = (gy.z_entrance_pupil - out.z) / N  # the backward ray's parameter at the pupil plane
    crossing = np.stack([out.x + s * out.L, out.y + s * out.M], axis=1)
    if math.isinf(st.object_z):
        obj = -np.stack([out.L, out.M, N], axis=1)  # the light travels the other way
    else:
        obj = np.stack([X, Y, np.full(X.shape, st.object_z)], axis=1)
    return np.where(ok[:, None], ideal, 0.0), ok, np.where(ok[:, None], obj, 0.0), crossing


@dataclass
class _PlateRays:
    """Backward chief rays from plate pixels of a focused lens, or blur centroids at a stop (module notes)."""

    name: str
    q: Prescription
    gx: object
    gy: object
    st: object
    wl: float
    backend: str
    w_px: int
    h_px: int
    sensor: tuple
    iris: float | None

    @property
    def sx(self):
        return self.w_px / self.sensor[0]  # pixels per mm

    @property
    def sy(self):
        return self.h_px / self.sensor[1]

    def film_of(self, px, py):
        """Plate pixels -> film mm (the film image is the picture turned by 180 deg)."""
        return np.stack([-(px - self.w_px / 2) / self.sx, -(py - self.h_px / 2) / self.sy], axis=1)

    def chief(self, px, py):
        """Ideal plate px of the chief rays from plate pixels, with their object points and stop crossings."""
        ideal, ok, obj, crossing = _real_to_ideal(self.q, self.gx, self.gy, self.st, self.film_of(px, py), self.wl,
                                                  self.backend, objects=True)
        if not ok.all():
            i = int(np.argmin(ok))
            W, H = self.sensor
            raise OpticsError(
                f"at focus {self.st.focus_from_film_mm:g} mm no chief ray leaves {self.name!r} from the film point "
                f"({px[i]:.0f}, {py[i]:.0f}) px of a {W:g} x {H:g} mm sensor: the lens does not cover it; "
                "give a smaller sensor")
        return (np.stack([ideal[:, 0] * self.sx + self.w_px / 2, ideal[:, 1] * self.sy + self.h_px / 2], axis=1),
                obj, crossing)

    def centroid_px(self, obj, crossing):
        """Where the stopped-down lens images the object points, plate px."""
        from ..centroid import image_centroids

        q, g, st, iris = self.q, self.gy, self.st, self.iris
        r_ep = g.entrance_pupil_diameter / 2 * iris / q.surfaces[q.stop_index].semi_diameter
        c = image_centroids(q, st.film_z, obj, at_infinity=math.isinf(st.object_z), crossing=crossing,
                            z_ep=g.z_entrance_pupil, pupil_radius=r_ep, stop_semi_diameter=iris,
                            wavelength_nm=self.wl, backend=self.backend)
        return np.stack([-c[:, 0] * self.sx + self.w_px / 2, -c[:, 1] * self.sy + self.h_px / 2], axis=1)

    def trace(self, px, py):
        """Ideal plate px of the real positions at plate pixels: chief rays, or centroids at the stop."""
        ideal, obj, crossing = self.chief(px, py)
        if self.iris is None:
            return ideal
        # aim again from the node moved back by its centroid's offset: the centroid then lands on the node
        off = self.centroid_px(obj, crossing) - np.stack([px, py], axis=1)
        return self.chief(px - off[:, 0], py - off[:, 1])[0]

    def residual(self, px, py, ideal_at):
        """(RMS, max) plate px between the field and traced positions at the stop (module notes)."""
        if self.iris is None:
            d = ideal_at(px, py) - self.trace(px, py)
        else:  # independent of the aiming above: each object point's own centroid, mapped by the field
            ideal, obj, crossing = self.chief(px, py)
            c = self.centroid_px(obj, crossing)
            d = ideal_at(c[:, 0], c[:, 1]) - ideal
        e = np.hypot(d[:, 0], d[:, 1])
        return float(np.sqrt(np.mean(e * e))), float(e.max())


def _require_pinhole_reach(rays: _PlateRays, nodes) -> None:
    """Refuse a fisheye on this sensor: its pinhole image would put the frame's edge far outside it.

    At 90 degrees off axis the pinhole image is infinitely far; no pinhole-based map or model represents that.
    """
    w_px, h_px = rays.w_px, rays.h_px
    reach = float(max(np.abs(nodes[..., 0] - w_px / 2).max() / (w_px / 2), np.abs(nodes[..., 1] - h_px / 2).max() / (h_px / 2)))
    if reach > MAX_PINHOLE_REACH:
        W, H = rays.sensor
        r_mm = float(np.hypot((nodes[..., 0] - w_px / 2) / rays.sx, (nodes[..., 1] - h_px / 2) / rays.sy).max())
        angle = math.degrees(math.atan(r_mm / float(rays.gy.pinhole_focal_length)))
        raise OpticsError(
            f"{rays.name!r} sees up to {angle:.1f} deg off axis on a {W:g} x {H:g} mm sensor: its pinhole image would "
            f"reach {reach:.1f} times the frame's half-size, so no pinhole-based distortion map or model represents "
            "it (a fisheye); give a smaller sensor")


def _overscan_px(fwd: _Grid, nodes, w_px: int, h_px: int, xscale: float = 1.0) -> tuple[int, int]:
    """The symmetric margin (ox, oy) whose box keeps the ideal position of every plate pixel; ``xscale``:
    the undistorted picture's columns per plate column (desqueezed: width' / width).

    The pixels' ideal positions in blocks of rows, then again into the map: never a float64 frame whole.
    """
    edges = np.concatenate([nodes[0], nodes[-1], nodes[:, 0], nodes[:, -1]])
    lo, hi = edges.min(axis=0), edges.max(axis=0)
    for _, (bx, by) in fwd.row_blocks(w_px, h_px):
        lo = np.minimum(lo, [bx.min(), by.min()])
        hi = np.maximum(hi, [bx.max(), by.max()])
    ox = int(math.ceil(xscale * max(0.0, -lo[0], hi[0] - w_px) - 1e-9))
    oy = int(math.ceil(max(0.0, -lo[1], hi[1] - h_px) - 1e-9))
    W2, H2 = round(w_px * xscale) + 2 * ox, h_px + 2 * oy
    if W2 * H2 > 4 * MAX_PIXELS or W2 > 4 * MAX_SIDE_PX or H2 > 4 * MAX_SIDE_PX:
        raise OpticsError(f"the undistorted frame would be {W2} x {H2} px: the distortion is too strong for an ST-map")
    return ox, oy


def _invert_field(fwd: _Grid, qx, qy, w_px: int, h_px: int, name: str):
    """Real plate px whose ideal positions are (qx, qy): Newton on the interpolated forward field."""
    r = np.stack([qx, qy], axis=1).astype(float)
    goal = r.copy()
    h = 0.25
    for _ in range(30):
        f = fwd.at(r[:, 0], r[:, 1]) - goal
        if np.abs(f).max() < 1e-7:
            break
        fx = (fwd.at(r[:, 0] + h, r[:, 1]) - fwd.at(r[:, 0] - h, r[:, 1])) / (2 * h)
        fy = (fwd.at(r[:, 0], r[:, 1] + h) - fwd.at(r[:, 0], r[:, 1] - h)) / (2 * h)
        det = fx[:, 0] * fy[:, 1] - fy[:, 0] * fx[:, 1]
        if not (np.abs(det) > 1e-9).all():
            raise OpticsError(f"the distortion of {name!r} folds the picture over: it has no undistortion map")
        step = np.stack([(fy[:, 1] * f[:, 0] - fy[:, 0] * f[:, 1]) / det,
                         (-fx[:, 1] * f[:, 0] + fx[:, 0] * f[:, 1]) / det], axis=1)
        r -= np.clip(step, -0.25 * max(w_px, h_px), 0.25 * max(w_px, h_px))
    return r


def _undistortion_map(fwd: _Grid, overscan, w_px: int, h_px: int, name: str, frame_w: int | None = None):
    """(undistortion ST-map, its worst round-trip error in px of the map): the inverse field at nodes over
    the overscanned frame (coordinates in the undistorted picture's pixels: -ox .. frame_w + ox; a
    desqueezed frame_w is the squeezed ideal position times frame_w / w_px)."""
    ox, oy = overscan
    frame_w = w_px if frame_w is None else frame_w
    s = frame_w / w_px  # undistorted columns per plate column
    W2, H2 = frame_w + 2 * ox, h_px + 2 * oy
    mx, ex = _nodes(W2)
    my, ey = _nodes(H2)
    QX, QY = np.meshgrid(np.arange(mx) * ex - ox, np.arange(my) * ey - oy)
    inv_nodes = _invert_field(fwd, QX.ravel() / s, QY.ravel(), w_px, h_px, name).reshape(my, mx, 2)
    if not np.isfinite(inv_nodes).all():
        raise OpticsError(f"the undistortion of {name!r} did not converge: no map written")
    inv = _Grid(inv_nodes, -ox, ex, -oy, ey)
    kx, ky = np.meshgrid((np.arange(mx - 1) + 0.5) * ex - ox, (np.arange(my - 1) + 0.5) * ey - oy)
    back = fwd.at(*inv.at(kx.ravel(), ky.ravel()).T)
    inv_err = float(np.hypot((back[:, 0] - kx.ravel() / s) * s, back[:, 1] - ky.ravel()).max())
    umap = np.zeros((H2, W2, 3), dtype=np.float32)
    inv.fill(umap, (w_px, h_px), origin=(-ox, -oy))
    return umap, inv_err


def _field_notes(fstop) -> list[str]:
    """What the field's pinhole and real positions are, for the result's notes."""
    return ["pinhole focal length: the paraxial one at this focus (GaussianData.pinhole_focal_length), "
            "camera at the entrance pupil",
            "real positions: chief rays (a small stop); at a working aperture give the f-stop (centroids)"
            if fstop is None else f"real positions: the blur centroids at f/{fstop:g} (the iris sized at infinity "
            "focus)"]


def _desqueezed_width(w_px: int, g, notes: list) -> int:
    """The desqueezed picture's width, px: round(w_px a), a = f_pin,y / f_pin,x (module notes)."""
    a = float(g["y"].pinhole_focal_length / g["x"].pinhole_focal_length)
    frame_w = round(w_px * a)
    if frame_w == w_px:
        notes.append(f"desqueeze: the lens is not anamorphic (pinhole f_y / f_x = {a:.5f}): the picture is its own")
    else:
        notes.append(f"desqueezed: the undistorted picture is {frame_w} px wide, the round pinhole's in square "
                     f"pixels (pinhole f_y / f_x = {a:.5f} at this focus)")
    if frame_w > 4 * MAX_SIDE_PX:
        raise OpticsError(f"the desqueezed picture would be {frame_w} px wide: give a smaller resolution")
    return frame_w


def _sensor(camera) -> tuple[float, float]:
    """The camera's sensor (width, height) mm."""
    if camera.sensor_mm is None:
        raise InputError("give the sensor: camera_state(lens, ..., sensor=...) (or sensor_mm=(width, height))")
    return camera.sensor_mm


@takes_camera
def distortion_field(
    camera: CameraState,
    *,
    width_px: int,
    height_px: int,
    wavelength_nm: float | None = None,
    method: str = "auto",
    backend: str = "auto",
    maps: bool = True,
    desqueeze: bool = False,
) -> DistortionField:
    """Real distortion of ``camera`` (a :class:`~physcam.optics.state.CameraState`: the lens focused,
    its iris, on its sensor) over a ``width_px`` x ``height_px`` frame, with its distortion and
    undistortion ST-maps (module notes).

    The wavelength is ``wavelength_nm`` or the camera's primary one; ``method`` the lens's focusing
    (auto, unit, internal) at that wavelength.
    ``maps=False`` traces the same chief rays but makes no ST-maps (the map fields and the overscan
    are then None and (0, 0)): what fitting models and tables across focus need. An iris set to an
    f-stop gives the centroid distortion there instead of the chief rays' (module notes, "At a stop").
    ``desqueeze=True`` makes the undistortion map for the desqueezed picture of an anamorphic lens
    (module notes; a spherical lens's picture is its own, said in the notes).
    """
    from ...optics.focusing import focus, focus_method
    from ...optics.paraxial import gaussian

    w_px, h_px = _size("width", width_px), _size("height", height_px)
    if w_px * h_px > MAX_PIXELS:
        raise InputError(f"a {w_px} x {h_px} frame has more than {MAX_PIXELS:,} pixels: give a smaller resolution")
    cam = camera
    W, H = _sensor(cam)
    lens = cam.lens
    if method != "auto" and method != focus_method(lens):
        raise InputError(f"the camera is focused already, by its lens's own {focus_method(lens)} focusing: "
                         "give a camera focused by that lens, not another method here")
    wl = cam.wavelengths_nm[0] if wavelength_nm is None else require_positive("wavelength", wavelength_nm, unit="nm")
    st = focus(lens, cam.focus_from_film_mm, method=method, axis="y", wavelength_nm=wl)
    q = st.prescription
    g = {a: gaussian(q, axis=a, wavelength_nm=wl, object_z=st.object_z, film_z=st.film_z) for a in ("x", "y")}
    for a in ("x", "y"):
        if g[a].pinhole_focal_length is None or not g[a].efl > 0:
            raise OpticsError(f"lens {lens.name!r} has no best-match pinhole in {a.upper()} at this focus")
    fstop = cam.fstop if cam.iris_set else None
    iris = cam.stop_semi_diameter if cam.iris_set else None
    rays = _PlateRays(lens.name, q, g["x"], g["y"], st, wl, backend, w_px, h_px, (W, H), iris)

    # forward field: real plate position -> ideal plate position, traced at the nodes
    nx, dx = _nodes(w_px)
    ny, dy = _nodes(h_px)
    X, Y = np.meshgrid(np.arange(nx) * dx, np.arange(ny) * dy)
    nodes = rays.trace(X.ravel(), Y.ravel()).reshape(ny, nx, 2)
    fwd = _Grid(nodes, 0.0, dx, 0.0, dy)
    cx, cy = np.meshgrid((np.arange(nx - 1) + 0.5) * dx, (np.arange(ny - 1) + 0.5) * dy)
    exact = rays.trace(cx.ravel(), cy.ravel())
    _require_pinhole_reach(rays, nodes)
    interp_err = float(np.hypot(*(fwd.at(cx.ravel(), cy.ravel()) - exact).T).max())
    resid = rays.residual(cx.ravel(), cy.ravel(), lambda x, y: fwd.at(x, y))
    max_dist = float(np.hypot(nodes[..., 0] - X, nodes[..., 1] - Y).max())
    traced_real = np.concatenate([np.stack([X.ravel(), Y.ravel()], axis=1), np.stack([cx.ravel(), cy.ravel()], axis=1)])
    traced_ideal = np.concatenate([nodes.reshape(-1, 2), exact])

    notes = _field_notes(fstop)
    frame_w = _desqueezed_width(w_px, g, notes) if desqueeze else w_px
    overscan, inv_err, dmap, umap = (0, 0), math.nan, None, None
    if maps:
        overscan = _overscan_px(fwd, nodes, w_px, h_px, frame_w / w_px)
        dmap = np.zeros((h_px, w_px, 3), dtype=np.float32)
        fwd.fill(dmap, (w_px, h_px))  # normalised to the plate's frame (module notes)
        umap, inv_err = _undistortion_map(fwd, overscan, w_px, h_px, lens.name, frame_w)
        if not (np.isfinite(dmap).all() and np.isfinite(umap).all()):
            raise OpticsError(f"the ST-maps of {lens.name!r} have non-finite values: no map written")
    zf = st.film_z
    return DistortionField(
        lens.name, cam, float(wl), (W, H), (w_px, h_px),
        (float(g["x"].pinhole_focal_length), float(g["y"].pinhole_focal_length)),
        (float(zf - g["x"].z_entrance_pupil), float(zf - g["y"].z_entrance_pupil)),
        overscan, (nx, ny), interp_err, inv_err, max_dist, resid, dmap, umap, notes, fwd,
        traced_real, traced_ideal, (frame_w, h_px))


def apply_stmap(image, stmap, *, overscan=(0, 0)) -> np.ndarray:
    """Resample ``image`` (h, w) or (h, w, c) through ``stmap`` (H, W, >= 2; R = u, G = v, module notes).

    ``overscan`` (ox, oy): the image is a frame of (w - 2 ox) x (h - 2 oy) pixels with that margin
    around it (an undistorted image, its data window larger than its display window), and u, v are
    normalised to the frame. Output pixel (row, col) takes the bilinear sample of ``image`` at
    (u fw + ox, v fh + oy), fw, fh the frame's size (origin bottom-left, pixel centres at half
    integers); samples outside the image are 0. Returns float64 (H, W[, c]).
    """
    img = np.asarray(image, dtype=float)
    m = np.asarray(stmap, dtype=float)
    if img.ndim not in (2, 3) or img.shape[0] < 1 or img.shape[1] < 1:
        raise InputError(f"the image must be an (h, w) or (h, w, channels) array, got shape {img.shape}")
    if m.ndim != 3 or m.shape[2] < 2:
        raise InputError(f"the ST-map must be an (h, w, 2 or more) array, got shape {m.shape}")
    if not np.isfinite(m[..., :2]).all():
        raise InputError("the ST-map has non-finite values")
    h, w = img.shape[:2]
    ox, oy = (int(v) for v in overscan)
    if ox < 0 or oy < 0 or 2 * ox >= w or 2 * oy >= h:
        raise InputError(f"the overscan {overscan!r} must be whole pixels >= 0 leaving a frame inside the "
                         f"{w} x {h} image")
    fw, fh = w - 2 * ox, h - 2 * oy
    c = img.reshape(h, w, -1).shape[2]
    # the image inside a border of zeros, one pixel wide, its rows flattened: a tap outside the image reads
    # the border (the taps' products and sums as before; gathered by flat index, 2.5x faster on 1920 x 1080)
    pad = np.zeros((h + 2, w + 2, c))
    pad[1:-1, 1:-1] = img.reshape(h, w, c)
    pad = pad.reshape(-1, c)
    x = m[..., 0] * fw + ox - 0.5  # column coordinate of the sample
    y = h - (m[..., 1] * fh + oy) - 0.5  # row coordinate (rows top first)
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    x0 = np.clip(x0, -2, w).astype(np.int64) + 1  # columns of the padded image; the border at 0 and w + 1
    y0 = np.clip(y0, -2, h).astype(np.int64) + 1
    out = np.zeros(m.shape[:2] + (c,))
    for dy_, wy in ((0, 1 - fy), (1, fy)):
        row = np.minimum(y0 + dy_, h + 1) * (w + 2)
        for dx_, wx in ((0, 1 - fx), (1, fx)):
            out += wy * wx * np.take(pad, row + np.minimum(x0 + dx_, w + 1), axis=0)
    return out if img.ndim == 3 else out[..., 0]


def write_map_exr(rgb: np.ndarray, path, attributes=None, *, overscan=(0, 0), force: bool = False) -> Path:
    """``rgb`` (h, w, 3) as a 32-bit float RGB scanline EXR at ``path``, written by OpenEXR into
    the atomic write's temporary (never held encoded in memory); ``attributes``: extra header entries
    (strings and floats). PIZ compression, lossless: against ZIP, a 4.6K map writes in 0.7x the CPU to a
    0.84x file and reads in 1.25x (docs/performance.md, "ST-maps written with PIZ"). ``overscan`` (ox, oy): ``rgb`` is a frame with that margin around it; the
    display window is the frame, the data window the whole array (OpenEXR's "Technical Introduction",
    data and display windows; y grows downward)."""
    from ...extras import require_extra
    from ...io import staged

    rgb = _map_array(rgb)
    require_extra("exr", "writing ST-maps as EXR")
    import OpenEXR

    h, w = rgb.shape[:2]
    ox, oy = overscan
    header = {"compression": OpenEXR.PIZ_COMPRESSION, "type": OpenEXR.scanlineimage, **(attributes or {}),
              "displayWindow": (np.array([0, 0], np.int32), np.array([w - 2 * ox - 1, h - 2 * oy - 1], np.int32)),
              "dataWindow": (np.array([-ox, -oy], np.int32), np.array([w - ox - 1, h - oy - 1], np.int32))}
    with staged(path, force=force, suffix=".exr") as tmp, \
            OpenEXR.File(header, {"RGB": np.ascontiguousarray(rgb, dtype=np.float32)}) as f:
        f.write(str(tmp))
    return Path(path)


def _map_array(rgb) -> np.ndarray:
    """``rgb`` checked as an (h, w, 3) map of finite numbers (a sentence, not an AttributeError)."""
    a = rgb if isinstance(rgb, np.ndarray) else None
    if a is None or a.ndim != 3 or a.shape[2] != 3 or min(a.shape[:2]) < 1:
        from ...errors import WrongTypeError

        raise WrongTypeError(f"an ST-map is an (h, w, 3) numpy array, got {rgb!r:.60}")
    return a


def _preview(rgb: np.ndarray) -> np.ndarray:
    """``rgb`` (h, w, 3) in 0..1 as 8-bit values, converted in blocks of rows (no float copy of the frame),
    each block's clip, scale and rounding offset in one buffer of the block's type, reused block after block
    (the same operations on the same type as ``np.clip(block, 0.0, 1.0) * 255.0 + 0.5``, without its three
    new arrays a block: the same bytes)."""
    out = np.empty(rgb.shape, dtype=np.uint8)
    buf = np.empty((min(ROW_BLOCK, rgb.shape[0]),) + rgb.shape[1:], dtype=np.clip(rgb[:1, :1], 0.0, 1.0).dtype)
    for r0 in range(0, rgb.shape[0], ROW_BLOCK):
        b = np.clip(rgb[r0:r0 + ROW_BLOCK], 0.0, 1.0, out=buf[:min(ROW_BLOCK, rgb.shape[0] - r0)])
        b *= 255.0
        b += 0.5
        out[r0:r0 + ROW_BLOCK] = b
    return out


def write_map_png(rgb: np.ndarray, path, *, force: bool = False) -> Path:
    """An 8-bit RGB PNG preview of ``rgb`` (h, w, 3) in 0..1, row 0 on top, at ``path``. Pillow directly
    (what matplotlib's imsave calls, less its colour-mapping pass and alpha channel: 2-3x faster on a
    2048-pixel map, which a characterization run writes by the hundred)."""
    from PIL import Image

    from ...io import staged

    rgb = _map_array(rgb)
    with staged(path, force=force, suffix=".png") as tmp:
        Image.fromarray(_preview(rgb), "RGB").save(tmp, format="png")
    return Path(path)


def write_stmaps(result: DistortionField, folder, *, force: bool = False) -> list[Path]:
    """Write ``distortion.exr``, ``undistortion.exr`` and a PNG preview beside each into ``folder``.

    ``undistortion.exr``'s display window is the undistorted picture's frame (the plate's, or the
    desqueezed one) and its data window the overscanned region (module notes); ``distortion.exr`` is the plate's size, both windows alike.

    Each EXR's header says which stop the map is for and its residual there: ``physcamMapFor`` (text),
    ``physcamFStop`` (0 for a chief-ray map), ``physcamResidualRmsPx``, ``physcamResidualMaxPx``,
    ``physcamLens``.

    Every name is checked before anything is written, so an existing file (without ``force``)
    leaves the folder as it was. Each file is encoded straight into its atomic write's temporary
    and put in place before the next is encoded (an 8K pair peaks under 2 GiB: docs/performance.md).
    Returns the paths written.
    """
    from ...io import check_writable

    if not isinstance(result, DistortionField):
        raise InputError(f"write_stmaps takes a DistortionField, got {type(result).__name__}")
    if result.distortion_stmap is None:
        raise InputError("this distortion field was made without maps (maps=False): nothing to write")
    d = Path(folder)
    if d.exists() and not d.is_dir():
        raise ExportError(f"{str(d)!r} exists and is not a folder: give a folder for the ST-maps")
    items = [("distortion", result.distortion_stmap, (0, 0)),
             ("undistortion", result.undistortion_stmap, tuple(result.overscan_px))]
    said = result.to_dict()
    attributes = {"physcamMapFor": said["map_for"], "physcamFStop": float(result.fstop or 0.0),
                  "physcamResidualRmsPx": float(result.residual_px[0]),
                  "physcamResidualMaxPx": float(result.residual_px[1]), "physcamLens": result.lens_name}
    for name, _, _ in items:
        for ext in ("exr", "png"):
            check_writable(d / f"{name}.{ext}", force=force)
    written = []
    for name, rgb, overscan in items:  # each file written before the next is encoded: one in memory at a time
        written.append(write_map_exr(rgb, d / f"{name}.exr", attributes, overscan=overscan, force=force))
        written.append(write_map_png(rgb, d / f"{name}.png", force=force))
    return written
