"""Tracked frames read back from a PhysicalCamera in USD (a recording, an animated camera, any shot).

At each time sample the camera body's world transform is computed by USD (its whole op stack and
parents), so any PhysicalCamera physcam wrote can be played out or used for the LED-wall frustum:
the film plane's centre and orientation come from the body (its origin is the film plane centre,
docs/usd.md), turned into OpenTrackIO's Z-up stage ((x, y, z) = USD's (x, -z, y) on a Y-up stage;
a Z-up stage is read as it is) and into pan/tilt/roll. Lens values are the PhysicalCamera's own
(mm): ``lens:main:pinholeFocalLength`` (else the lens model's focal length), the lens model's
``focusDistance``, ``lens:main:fStop``, ``lens:main:entrancePupilDistance`` (and an anamorphic's
``horizontalEntrancePupilDistance``, the pan pivot), the sensor aperture,
and the recorded ``physcam:live:*`` attributes when present: ``anamorphicSqueeze`` (else the lens
model's ``squeeze``), ``projectionOffset`` and ``distortionOffset`` (else the projection offset of the
PhysicalCamera's ``sensor:main:shift``: (-shift x, shift y), docs/live.md).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from ..errors import InputError
from .frames import TrackedFrame, pan_tilt_roll

__all__ = ["frames_from_usd", "camera_prim_path"]


def camera_prim_path(stage, path: str | None = None) -> str:
    """``path``, or the only PhysicalCamera on the stage."""
    from .. import usd as _usd  # noqa: F401  (one line naming the 'usd' extra when usd-core is missing)
    from pxr import Sdf

    from ..usd.plugin import require_stage

    require_stage(stage)
    if path is not None:
        prim = stage.GetPrimAtPath(Sdf.Path(path)) if Sdf.Path.IsValidPathString(path) else None
        if not prim or prim.GetTypeName() != "PhysicalCamera":
            raise InputError(f"no PhysicalCamera at {path}")
        return path
    cams = [p for p in stage.Traverse() if p.GetTypeName() == "PhysicalCamera"]
    if len(cams) != 1:
        raise InputError(f"the file has {len(cams)} PhysicalCameras; name one with --path")
    return str(cams[0].GetPath())


def _times(prim, attrs) -> list[float]:
    times: set[float] = set()
    for a in attrs:
        if a:
            times.update(a.GetTimeSamples())
    from .. import usd as _usd  # noqa: F401  (one line naming the 'usd' extra when usd-core is missing)
    from pxr import UsdGeom

    xf = UsdGeom.Xformable(prim)
    for op in xf.GetOrderedXformOps():
        times.update(op.GetAttr().GetTimeSamples())
    return sorted(times) or [0.0]


def frames_from_usd(file, path: str | None = None, *, max_frames: int = 144_000) -> list[TrackedFrame]:
    """One :class:`TrackedFrame` per time sample of the PhysicalCamera at ``path`` in ``file`` (module
    notes); times stamped from the stage's timeCodesPerSecond, the first at 0."""
    from pathlib import Path

    import physcam.usd  # noqa: F401 - registers the schema
    from .. import usd as _usd  # noqa: F401  (one line naming the 'usd' extra when usd-core is missing)
    from pxr import Usd, UsdGeom

    p = Path(file) if isinstance(file, (str, Path)) else None
    if p is None or not p.is_file():
        raise InputError(f"no USD file {file!r}")
    try:
        stage = Usd.Stage.Open(str(p))
    except Exception as exc:  # noqa: BLE001 - pxr raises Tf errors of several kinds
        raise InputError(f"{p}: not a USD file USD can open ({str(exc).splitlines()[0][:120]})") from None
    if stage is None:
        raise InputError(f"{p}: not a USD file USD can open")
    cam = stage.GetPrimAtPath(camera_prim_path(stage, path))
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    z_up = UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z
    tcps = stage.GetTimeCodesPerSecond()
    if not (math.isfinite(tcps) and tcps > 0):
        raise InputError(f"{p}: timeCodesPerSecond must be > 0")
    rate = Fraction(tcps).limit_denominator(1001)
    lp = "lens:main:"
    get = cam.GetAttribute
    rel = cam.GetRelationship(lp + "lensModel")
    model = stage.GetPrimAtPath(rel.GetTargets()[0]) if rel and rel.GetTargets() else None
    a_pin, a_fstop, a_pupil = get(lp + "pinholeFocalLength"), get(lp + "fStop"), get(lp + "entrancePupilDistance")
    a_focal = model.GetAttribute("focalLength") if model else None
    a_focus = model.GetAttribute("focusDistance") if model else None
    a_ap = get("sensor:main:aperture")
    a_seq, a_tc = get("physcam:live:sequenceNumber"), get("physcam:live:timecode")
    a_model, a_rad, a_tan = (get("physcam:live:distortionModel"), get("physcam:live:distortionRadial"),
                             get("physcam:live:distortionTangential"))
    a_sq, a_proj, a_doff = (get("physcam:live:anamorphicSqueeze"), get("physcam:live:projectionOffset"),
                            get("physcam:live:distortionOffset"))
    a_model_sq = model.GetAttribute("squeeze") if model else None
    a_pupil_x = get(lp + "horizontalEntrancePupilDistance")  # an anamorphic's pan pivot, when authored
    a_shift = get("sensor:main:shift")
    times = _times(cam, [a_pin, a_fstop, a_pupil, a_focal, a_focus, a_seq])
    if len(times) > max_frames:
        raise InputError(f"{p}: {len(times)} time samples; at most {max_frames}")
    xf = UsdGeom.Xformable(cam)
    c = np.eye(3) if z_up else np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])  # OpenTrackIO -> USD
    out = []
    t0 = times[0]

    def val(a, t):
        if not a or not a.HasAuthoredValue():
            return None
        v = a.Get(Usd.TimeCode(t))
        return None if v is None else v

    for t in times:
        m = np.array(xf.ComputeLocalToWorldTransform(Usd.TimeCode(t))).T  # column-vector form
        rot_usd = m[:3, :3]
        scale = np.linalg.norm(rot_usd, axis=0)
        if np.any(scale <= 0) or not np.all(np.isfinite(m)):
            raise InputError(f"{p}: the camera's transform at time {t:g} is degenerate")
        rot = c.T @ (rot_usd / scale) @ c
        film = c.T @ m[:3, 3] * mpu
        pin = val(a_pin, t)
        if pin is None:
            pin = val(a_focal, t)
        dist = None
        radial = val(a_rad, t)
        if radial is not None and len(radial):
            dist = {"model": str(val(a_model, t) or "Brown-Conrady D-U"), "radial": [float(v) for v in radial]}
            tang = val(a_tan, t)
            if tang is not None and len(tang):
                dist["tangential"] = [float(v) for v in tang]
        ap = val(a_ap, t)
        seq = val(a_seq, t)
        sq = val(a_sq, t)
        sq = val(a_model_sq, t) if sq is None else sq
        proj, doff = val(a_proj, t), val(a_doff, t)
        if proj is None and val(a_shift, t) is not None:
            shift = val(a_shift, t)
            proj = (-float(shift[0]), float(shift[1])) if any(shift) else None
        proj = None if proj is None else (float(proj[0]) + 0.0, float(proj[1]) + 0.0)
        doff = None if doff is None else (float(doff[0]), float(doff[1]))
        out.append(TrackedFrame(
            time_ns=int(round((t - t0) / tcps * 1e9)), sequence_number=None if seq is None else int(seq),
            timecode=val(a_tc, t) or None, rate=rate,
            translation_m=tuple(float(v) for v in film), rotation_deg=pan_tilt_roll(rot),
            pinhole_focal_length_mm=None if pin is None else float(pin),
            focus_from_film_mm=None if val(a_focus, t) is None else float(val(a_focus, t)),
            fstop=None if val(a_fstop, t) is None else float(val(a_fstop, t)),
            entrance_pupil_mm=None if val(a_pupil, t) is None else float(val(a_pupil, t)),
            entrance_pupil_horizontal_mm=None if val(a_pupil_x, t) is None else float(val(a_pupil_x, t)),
            distortion=dist, sensor_mm=None if ap is None else (float(ap[0]), float(ap[1])),
            nominal_focal_length_mm=None if val(a_focal, t) is None else float(val(a_focal, t)),
            squeeze=None if sq is None else float(sq), projection_offset_mm=proj, distortion_offset_mm=doff))
    return out
