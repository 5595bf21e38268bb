"""The LED wall's inner frustum: where the tracked camera's view lands on the wall, frame by frame.

For each frame the eye is the **entrance pupil** (the camera's centre of projection,
docs/conventions.md) and the field of view is the **best-match pinhole at the current focus**
(``pinholeFocalLength``: it breathes with focus), over the sensor. A ray from the pupil through a
point (u, v) of the upright image (mm on the sensor, u right, v up) has the camera-space direction
(u, v, -f_pin) (USD camera space: -Z forward). The footprint is where the rays along the frame's four
edges (``samples_per_edge`` each, corners included) first hit the wall mesh (Möller-Trumbore ray /
triangle intersection over every triangle, Möller & Trumbore, J. Graphics Tools 2(1), 1997).

Two entrance pupils (an anamorphic, ``entrance_pupil_horizontal_mm``; docs/anamorphic.md): the lens
images a subject point's horizontal angle about the X meridian's pupil (at ``e_x`` in front of the
film) and its vertical angle about the Y meridian's (``e_y``). The points that land on the frame at
tangents (t_u, t_v) are then X = t_u (s - e_x), Y = t_v (s - e_y), Z = -s for every depth s in front
of the film: a straight ray of direction (t_u, t_v, -1) through (t_u (e_y - e_x), 0, -e_y). The left and
right edges' rays all pass through the vertical line through the X pupil, the top and bottom edges'
through the horizontal line through the Y pupil; with one pupil every ray leaves from it. The
projection camera (one eye, as a wall renderer has) sits at the Y pupil.

The frame's edges: OpenLensIO's screen point ε (mm on the sensor, x right, y down) looks along
x/z = squeeze (ε_x - ΔP_x) / F and y/z = (ε_y - ΔP_y) / F (OpenLensIO 1.0.1 eq. 3 with the projection
offset ΔP = ``projectionOffset``; an anamorphic's horizontal focal length is F / squeeze,
``static.camera.anamorphicSqueeze``). The distortion offset ΔC moves only the distortion centre, not
the frame, so the pinhole frustum does not use it.

Overscan, stated per frame in the output, about the centre of the frame's view in each axis:

* ``overscan`` (a fraction) with ``overscan_mode``: ``"tangent"`` (default) widens each half-width's
  **tangent** by (1 + overscan), the image plane grown by that factor (OpenLensIO's overscan factor Ω,
  section 2.1); ``"ndisplay"`` multiplies the half-**angle** by (1 + overscan), as Unreal's nDisplay
  inner-frustum overscan scales the camera's field of view (Epic, "In-Camera VFX" camera settings). At
  10 % on a 40° view the two give 44.0° and 43.6°;
* ``latency_s``: tracking latency. The camera turns ω rad/s (measured from this frame to the next)
  while the wall still shows the old view; each edge's angle is widened by ω x latency, so the picture
  the camera sees ``latency_s`` later is still inside the inner frustum.

Coordinates: the wall and the camera are read in USD world space (scene units); the footprint is
written in the same space as time-sampled USD: ``/Frustum/ProjectionCamera`` (a UsdGeomCamera at the
pupil with the widened apertures) and ``/Frustum/Footprint`` (a closed linear BasisCurves polygon).
A ray that misses the wall leaves its point on the ray at the wall's distance and is counted in
``physcam:frustum:missedRays``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, require_finite
from .sample import shown

__all__ = ["WallMesh", "wall_from_usd", "frustum_directions", "edge_directions", "frame_tangents", "intersect_mesh", "FrustumFrame", "frustum_frames",
           "write_frustum_usd", "write_wall"]

#: a footprint polygon's points per frame edge: from 1 (corners only) to this
MAX_SAMPLES_PER_EDGE = 256


@dataclass(frozen=True)
class WallMesh:
    """Triangles (n, 3, 3) in world space (scene units), with the stage's metres per unit."""

    triangles: np.ndarray
    meters_per_unit: float

    @property
    def size(self) -> float:
        pts = self.triangles.reshape(-1, 3)
        return float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))


def wall_from_usd(file, path: str | None = None) -> WallMesh:
    """The LED wall: the Mesh at ``path`` (default the only Mesh) of a USD file, triangulated in world space."""
    from pathlib import Path

    from .. import usd as _usd  # noqa: F401  (one line naming the 'usd' extra when usd-core is missing)

    from pxr import Usd, UsdGeom

    p = Path(file) if isinstance(file, (str, Path)) else None
    if p is None or not p.is_file():
        raise InputError(f"no USD file {file!r} for the LED wall")
    try:
        stage = Usd.Stage.Open(str(p))
    except Exception:  # noqa: BLE001 - pxr raises Tf errors of several kinds
        stage = None
    if stage is None:
        raise InputError(f"{p}: not a USD file USD can open")
    meshes = [m for m in stage.Traverse() if m.IsA(UsdGeom.Mesh)]
    if path is not None:
        meshes = [m for m in meshes if str(m.GetPath()) == path]
    if len(meshes) != 1:
        raise InputError(f"{p}: {len(meshes)} meshes {'at ' + path if path else ''}; name the wall with --wall-path")
    mesh = UsdGeom.Mesh(meshes[0])
    pts = np.array(mesh.GetPointsAttr().Get() or [], dtype=float)
    counts = list(mesh.GetFaceVertexCountsAttr().Get() or [])
    idx = list(mesh.GetFaceVertexIndicesAttr().Get() or [])
    if len(pts) < 3 or not counts or sum(counts) != len(idx) or (idx and max(idx) >= len(pts)):
        raise InputError(f"{p}: the wall mesh has no usable faces")
    m = np.array(UsdGeom.Xformable(mesh).ComputeLocalToWorldTransform(Usd.TimeCode.Default()))
    world = np.c_[pts, np.ones(len(pts))] @ m
    world = world[:, :3] / world[:, 3:4]
    tris, k = [], 0
    for n in counts:
        face = idx[k:k + n]
        k += n
        for j in range(1, n - 1):  # fan triangulation (the wall's faces are convex quads)
            tris.append((face[0], face[j], face[j + 1]))
    if len(tris) > 2_000_000:
        raise InputError(f"{p}: the wall has {len(tris)} triangles; at most 2,000,000")
    tri = world[np.array(tris)]
    if not np.all(np.isfinite(tri)):
        raise InputError(f"{p}: the wall mesh has points that are not finite")
    return WallMesh(tri, UsdGeom.GetStageMetersPerUnit(stage))


def edge_directions(tan_u, tan_v, samples_per_edge: int = 8) -> np.ndarray:
    """Camera-space directions (k, 3), z = -1, around the frame whose edges lie at the tangents
    ``tan_u`` = (left, right) and ``tan_v`` = (bottom, top), counter-clockwise from the bottom-left."""
    if isinstance(samples_per_edge, bool) or not isinstance(samples_per_edge, int) \
            or not 1 <= samples_per_edge <= MAX_SAMPLES_PER_EDGE:
        raise InputError(f"samples per edge must be 1..{MAX_SAMPLES_PER_EDGE}, got {shown(samples_per_edge)}")
    (u0, u1), (v0, v1) = tan_u, tan_v
    s = (np.linspace(-1.0, 1.0, samples_per_edge + 1)[:-1] + 1.0) / 2.0
    edges = [np.c_[u0 + s * (u1 - u0), np.full_like(s, v0)], np.c_[np.full_like(s, u1), v0 + s * (v1 - v0)],
             np.c_[u1 - s * (u1 - u0), np.full_like(s, v1)], np.c_[np.full_like(s, u0), v1 - s * (v1 - v0)]]
    uv = np.concatenate(edges)
    return np.c_[uv, np.full(len(uv), -1.0)]


def frame_tangents(f_pin_mm, sensor_mm, squeeze: float = 1.0, projection_offset_mm=(0.0, 0.0)):
    """((left, right), (bottom, top)) tangents of the frame's edges seen from the pupil (module notes:
    squeeze (ε_x - ΔP_x) / F across, (ε_up + ΔP_y) / F up, ΔP in OpenLensIO's y-down screen)."""
    from .frames import _pair

    f = require_finite("pinhole focal length", f_pin_mm)
    if f <= 0:
        raise InputError(f"pinhole focal length must be > 0 mm, got {f:g}")
    w, h = _pair("sensor size (mm)", sensor_mm)
    dx, dy = _pair("projection offset (mm)", projection_offset_mm)
    sq = require_finite("anamorphic squeeze", squeeze)
    if not 0.1 <= sq <= 10.0:
        raise InputError(f"anamorphic squeeze must lie between 0.1 and 10, got {sq:g}")
    return ((sq * (-w / 2 - dx) / f, sq * (w / 2 - dx) / f), ((-h / 2 + dy) / f, (h / 2 + dy) / f))


def _overscan(lo_hi, pad, o, mode):
    """Edge tangents (lo, hi) widened by the latency margin ``pad`` (rad, each edge) and the overscan
    ``o`` about the view's centre, by tangent or by angle (module notes)."""
    a_lo, a_hi = math.atan(lo_hi[0]) - pad, math.atan(lo_hi[1]) + pad
    if mode == "ndisplay":
        c, half = (a_lo + a_hi) / 2, (a_hi - a_lo) / 2 * (1 + o)
        a_lo, a_hi = c - half, c + half
        if a_lo <= -math.pi / 2 or a_hi >= math.pi / 2:
            return None
        return math.tan(a_lo), math.tan(a_hi)
    if a_lo <= -math.pi / 2 or a_hi >= math.pi / 2:
        return None
    t_lo, t_hi = math.tan(a_lo), math.tan(a_hi)
    c, half = (t_lo + t_hi) / 2, (t_hi - t_lo) / 2 * (1 + o)
    return c - half, c + half


def frustum_directions(f_pin_mm, sensor_mm, samples_per_edge: int = 8, widen=(1.0, 1.0)) -> np.ndarray:
    """Camera-space directions (k, 3) around the frame's edge, counter-clockwise from the bottom-left
    corner (u, v on the upright image; ``widen`` multiplies the half-widths' tangents)."""
    f = require_finite("pinhole focal length", f_pin_mm)
    if f <= 0:
        raise InputError(f"pinhole focal length must be > 0 mm, got {f:g}")
    from .frames import _pair

    w, h = _pair("sensor size (mm)", sensor_mm)
    if isinstance(samples_per_edge, bool) or not isinstance(samples_per_edge, int) \
            or not 1 <= samples_per_edge <= MAX_SAMPLES_PER_EDGE:
        raise InputError(f"samples per edge must be 1..{MAX_SAMPLES_PER_EDGE}, got {shown(samples_per_edge)}")
    hu, hv = w / 2 * widen[0], h / 2 * widen[1]
    s = np.linspace(-1.0, 1.0, samples_per_edge + 1)[:-1]
    edges = [np.c_[s * hu, np.full_like(s, -hv)], np.c_[np.full_like(s, hu), s * hv],
             np.c_[-s * hu, np.full_like(s, hv)], np.c_[np.full_like(s, -hu), -s * hv]]
    uv = np.concatenate(edges)
    return np.c_[uv, np.full(len(uv), -f)]


def intersect_mesh(origin, directions, triangles) -> np.ndarray:
    """Distance t (k,) along each ray ``origin + t d`` to its first hit on ``triangles`` (n, 3, 3);
    inf where a ray misses (Möller-Trumbore, module notes). ``origin``: one point (3,) for every ray,
    or one per ray (k, 3)."""
    try:
        o = np.asarray(origin, dtype=float)
        d = np.atleast_2d(np.asarray(directions, dtype=float))
        tri = np.asarray(triangles, dtype=float)
    except (TypeError, ValueError):
        raise InputError("origin (3,), directions (k, 3) and triangles (n, 3, 3) must be arrays of numbers") from None
    if o.shape not in ((3,), (len(d), 3)) or d.ndim != 2 or d.shape[1] != 3 or tri.ndim != 3 \
            or tri.shape[1:] != (3, 3):
        raise InputError(f"origin (3,) or (k, 3), directions (k, 3) and triangles (n, 3, 3), got {o.shape}, "
                         f"{d.shape}, {tri.shape}")
    v0, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    out = np.full(len(d), np.inf)
    tvec = o - v0 if o.ndim == 1 else None  # (n, 3)
    qvec = np.cross(tvec, e1) if o.ndim == 1 else None  # (n, 3)
    for i, di in enumerate(d):
        if o.ndim == 2:
            tvec = o[i] - v0
            qvec = np.cross(tvec, e1)
        pvec = np.cross(di, e2)
        det = np.einsum("ij,ij->i", e1, pvec)
        ok = np.abs(det) > 1e-14
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        u = np.einsum("ij,ij->i", tvec, pvec) * inv
        v = (qvec @ di) * inv
        t = np.einsum("ij,ij->i", e2, qvec) * inv
        hit = ok & (u >= -1e-12) & (v >= -1e-12) & (u + v <= 1 + 1e-12) & (t > 1e-9)
        if hit.any():
            out[i] = t[hit].min()
    return out


@dataclass(frozen=True)
class FrustumFrame:
    """One frame's inner frustum: time code, pupil (world, scene units), camera rotation (USD, 3 x 3),
    widening of the half-widths (u, v), footprint points (k, 3) and how many rays missed."""

    time_code: float
    pupil: np.ndarray
    rotation: np.ndarray
    f_pin_mm: float
    sensor_mm: tuple[float, float]
    widen: tuple[float, float]
    pad_deg: float
    footprint: np.ndarray
    missed: int
    #: ((left, right), (bottom, top)) tangents of the widened frustum's edges (camera space)
    tangents: tuple = ((0.0, 0.0), (0.0, 0.0))
    #: an anamorphic's horizontal (X) pupil, world; ``pupil`` is then the vertical (Y) one. None: one pupil
    pupil_horizontal: np.ndarray | None = None


def _angle_between(r0, r1) -> float:
    c = (np.trace(r0.T @ r1) - 1.0) / 2.0
    return math.acos(max(-1.0, min(1.0, c)))


def frustum_frames(frames, wall: WallMesh, *, overscan: float = 0.1, latency_s: float = 0.0,
                   samples_per_edge: int = 8, meters_per_unit: float | None = None,
                   overscan_mode: str = "tangent") -> list[FrustumFrame]:
    """The inner frustum of each tracked frame (:class:`~physcam.live.frames.TrackedFrame`, e.g. from
    :func:`physcam.live.usd_io.frames_from_usd`) on ``wall`` (module notes); ``overscan_mode``
    "tangent" or "ndisplay"."""
    from .frames import TrackedFrame, rotation_matrix

    if not isinstance(wall, WallMesh):
        from ..errors import WrongTypeError

        raise WrongTypeError("wall must be a WallMesh (physcam.live.frustum.wall_from_usd)")
    frames = list(frames) if hasattr(frames, "__iter__") and not isinstance(frames, (str, bytes)) else None
    if not frames or not all(isinstance(f, TrackedFrame) for f in frames):
        from ..errors import WrongTypeError

        raise WrongTypeError("frames must be a non-empty list of TrackedFrame")
    o = require_finite("overscan", overscan)
    lat = require_finite("latency", latency_s)
    if not 0.0 <= o <= 10.0 or not 0.0 <= lat <= 10.0:
        raise InputError("overscan must lie in [0, 10] (a fraction) and latency in [0, 10] s")
    if overscan_mode not in ("tangent", "ndisplay"):
        raise InputError(f"overscan mode is tangent or ndisplay, got {overscan_mode!r}")
    mpu = wall.meters_per_unit if meters_per_unit is None else require_finite("meters per unit", meters_per_unit)
    c = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])  # OpenTrackIO stage -> USD Y-up
    rots = [c @ rotation_matrix(*f.rotation_deg) @ c.T for f in frames]
    times = [0.0 if f.time_ns is None or frames[0].time_ns is None else
             (f.time_ns - frames[0].time_ns) / 1e9 for f in frames]
    rate = float(frames[0].rate) if frames[0].rate else 24.0
    out = []
    for i, f in enumerate(frames):
        if f.pinhole_focal_length_mm is None or f.sensor_mm is None:
            raise InputError(f"frame {i} has no pinhole focal length or sensor size")
        j = min(i + 1, len(frames) - 1)
        k = j - 1 if j == i else i
        dt = (times[j] - times[k]) if j != k and times[j] > times[k] else (1.0 / rate)
        omega = _angle_between(rots[k], rots[j]) / dt if j != k else 0.0
        pad = omega * lat
        f_pin, (w, h) = f.pinhole_focal_length_mm, f.sensor_mm
        tu, tv = frame_tangents(f_pin, (w, h), 1.0 if f.squeeze is None else f.squeeze,
                                f.projection_offset_mm or (0.0, 0.0))
        tu_w, tv_w = _overscan(tu, pad, o, overscan_mode), _overscan(tv, pad, o, overscan_mode)
        if tu_w is None or tv_w is None:
            raise InputError(f"frame {i}: the overscan and latency margin open the frustum past 180 degrees")
        widen = ((tu_w[1] - tu_w[0]) / (tu[1] - tu[0]), (tv_w[1] - tv_w[0]) / (tv[1] - tv[0]))
        film = c @ np.asarray(f.translation_m) / mpu
        eye_mm = f.entrance_pupil_mm or 0.0
        pupil = film + rots[i] @ np.array([0.0, 0.0, -eye_mm / 1000.0 / mpu])
        cam_dirs = edge_directions(tu_w, tv_w, samples_per_edge)
        origins, pupil_x = pupil, None
        if f.entrance_pupil_horizontal_mm is not None:  # two pupils: each edge ray's own origin (module notes)
            ex = f.entrance_pupil_horizontal_mm / 1000.0 / mpu
            pupil_x = film + rots[i] @ np.array([0.0, 0.0, -ex])
            shift = cam_dirs[:, 0] * (eye_mm / 1000.0 / mpu - ex)  # t_u (e_y - e_x), along camera X
            origins = pupil + np.outer(shift, rots[i][:, 0])
        dirs = cam_dirs @ rots[i].T
        norm = np.linalg.norm(dirs, axis=1, keepdims=True)
        dirs /= norm
        t = intersect_mesh(origins, dirs, wall.triangles)
        missed = int(np.isinf(t).sum())
        t = np.where(np.isinf(t), wall.size, t)
        fc = round(float(times[i] * rate), 6)
        out.append(FrustumFrame(fc, pupil, rots[i], f_pin, (w, h), widen, math.degrees(pad),
                                origins + t[:, None] * dirs, missed, (tu_w, tv_w), pupil_x))
    return out


def write_frustum_usd(file, frustum, *, meters_per_unit: float, fps: float, force: bool = False):
    """The frames' projection camera and footprint polygon as time-sampled USD (module notes)."""
    from .. import usd as _usd  # noqa: F401  (one line naming the 'usd' extra when usd-core is missing)
    from pxr import Gf, Sdf, UsdGeom, Vt

    from ..export.usdgeom import mm_to_tenths_of_scene_unit
    from ..usd.author import new_stage, save_stage

    frustum = list(frustum)
    if not frustum or not all(isinstance(f, FrustumFrame) for f in frustum):
        from ..errors import WrongTypeError

        raise WrongTypeError("frustum must be a non-empty list of FrustumFrame (frustum_frames)")
    stage = new_stage(meters_per_unit, fps, up_axis="Y")
    stage.SetStartTimeCode(frustum[0].time_code)
    stage.SetEndTimeCode(frustum[-1].time_code)
    UsdGeom.Xform.Define(stage, "/Frustum")
    stage.SetDefaultPrim(stage.GetPrimAtPath("/Frustum"))
    cam = UsdGeom.Camera.Define(stage, "/Frustum/ProjectionCamera")
    cam.GetPrim().SetDocumentation("The LED wall's inner frustum: the tracked camera's pinhole at its entrance "
                                   "pupil, apertures widened by the stated overscan and latency margin.")
    xf = UsdGeom.Xformable(cam)
    op_t, op_m = xf.AddTranslateOp(), xf.AddOrientOp(UsdGeom.XformOp.PrecisionDouble)
    curve = UsdGeom.BasisCurves.Define(stage, "/Frustum/Footprint")
    curve.CreateTypeAttr(UsdGeom.Tokens.linear)
    curve.CreateWrapAttr(UsdGeom.Tokens.periodic)
    n = len(frustum[0].footprint)
    curve.CreateCurveVertexCountsAttr(Vt.IntArray([n]))
    curve.CreateWidthsAttr(Vt.FloatArray([0.01 / meters_per_unit]))
    prim = curve.GetPrim()
    a_miss = prim.CreateAttribute("physcam:frustum:missedRays", Sdf.ValueTypeNames.Int, True)
    a_widen = prim.CreateAttribute("physcam:frustum:widen", Sdf.ValueTypeNames.Double2, True)
    a_pad = prim.CreateAttribute("physcam:frustum:latencyMarginDeg", Sdf.ValueTypeNames.Double, True)
    a_px = None
    if any(fr.pupil_horizontal is not None for fr in frustum):  # an anamorphic's pan pivot, beside the eye
        a_px = prim.CreateAttribute("physcam:frustum:horizontalPupil", Sdf.ValueTypeNames.Point3d, True)
    tenths = lambda mm: mm_to_tenths_of_scene_unit(mm, meters_per_unit)  # noqa: E731
    for fr in frustum:
        t = fr.time_code
        op_t.Set(Gf.Vec3d(*map(float, fr.pupil)), t)
        q = Gf.Matrix3d(*fr.rotation.T.flatten().tolist()).ExtractRotation().GetQuat()
        op_m.Set(Gf.Quatd(q.GetReal(), Gf.Vec3d(q.GetImaginary())), t)
        cam.GetFocalLengthAttr().Set(tenths(fr.f_pin_mm), t)
        (u0, u1), (v0, v1) = fr.tangents
        cam.GetHorizontalApertureAttr().Set(tenths((u1 - u0) * fr.f_pin_mm), t)
        cam.GetVerticalApertureAttr().Set(tenths((v1 - v0) * fr.f_pin_mm), t)
        cam.GetHorizontalApertureOffsetAttr().Set(tenths((u0 + u1) / 2 * fr.f_pin_mm), t)
        cam.GetVerticalApertureOffsetAttr().Set(tenths((v0 + v1) / 2 * fr.f_pin_mm), t)
        curve.GetPointsAttr().Set(Vt.Vec3fArray([Gf.Vec3f(*map(float, p)) for p in fr.footprint]), t)
        a_miss.Set(int(fr.missed), t)
        a_widen.Set(Gf.Vec2d(*fr.widen), t)
        a_pad.Set(float(fr.pad_deg), t)
        if a_px is not None:
            a_px.Set(Gf.Vec3d(*map(float, fr.pupil if fr.pupil_horizontal is None else fr.pupil_horizontal)), t)
    return save_stage(stage, file, force=force)


def write_wall(file, *, kind: str = "flat", width_m: float = 12.0, height_m: float = 5.0, distance_m: float = 6.0,
               radius_m: float = 8.0, segments: int = 96, meters_per_unit: float = 0.01, force: bool = False):
    """An LED wall mesh for examples and tests: ``flat`` (a plane ``distance_m`` in front of the stage
    origin along OpenTrackIO's +Y, centred, from the floor up) or ``curved`` (an arc of a vertical
    cylinder of ``radius_m`` about the origin, ``width_m`` of arc length)."""
    from .. import usd as _usd  # noqa: F401  (one line naming the 'usd' extra when usd-core is missing)
    from pxr import Gf, UsdGeom, Vt

    from ..usd.author import new_stage, save_stage

    if kind not in ("flat", "curved"):
        raise InputError(f"a wall is flat or curved, got {kind!r}")
    w, h, d, r = (require_finite(n, v) for n, v in (("width", width_m), ("height", height_m),
                                                     ("distance", distance_m), ("radius", radius_m)))
    if not (0 < w <= 1000 and 0 < h <= 1000 and 0 < d <= 1000 and 0 < r <= 1000):
        raise InputError("wall width, height, distance and radius must lie in (0, 1000] m")
    if isinstance(segments, bool) or not isinstance(segments, int) or not 1 <= segments <= 4096:
        raise InputError(f"segments must be 1..4096, got {shown(segments)}")
    if kind == "curved" and w / r >= 2 * math.pi:
        raise InputError("a curved wall's arc must be shorter than the whole circle (width < 2 pi radius)")
    mpu = meters_per_unit
    cols = segments + 1 if kind == "curved" else 2
    pts = []
    for row in (0.0, h):
        for j in range(cols):
            u = j / (cols - 1)
            if kind == "flat":
                x, y = -w / 2 + u * w, d
            else:
                a = (u - 0.5) * w / r
                x, y = r * math.sin(a), r * math.cos(a)
            pts.append(Gf.Vec3f(x / mpu, row / mpu, -y / mpu))  # OpenTrackIO (x, y, z) -> USD (x, z, -y)
    counts = [4] * (cols - 1)
    idx = []
    for j in range(cols - 1):
        idx += [j, j + 1, cols + j + 1, cols + j]
    stage = new_stage(mpu, 24.0, up_axis="Y")
    UsdGeom.Xform.Define(stage, "/Stage")
    stage.SetDefaultPrim(stage.GetPrimAtPath("/Stage"))
    mesh = UsdGeom.Mesh.Define(stage, "/Stage/LEDWall")
    mesh.CreatePointsAttr(Vt.Vec3fArray(pts))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray(counts))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray(idx))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    mesh.GetPrim().SetDocumentation(f"A {kind} LED wall written by physcam live wall.")
    return save_stage(stage, file, force=force)
