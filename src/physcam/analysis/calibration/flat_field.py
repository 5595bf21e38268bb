"""Relative illumination measured from flat-field frames (docs/calibrate.md).

A flat field is a picture of a uniform, diffuse light source filling the lens (a light box, an
evenly lit white card out of focus) at the stop being characterized. The frames are averaged;
the picture is divided into rings about the measured principal point; each ring's mean over the
centre ring's is the **relative illumination** at that image height (mm on the sensor from the
optical axis), the quantity :func:`physcam.analysis.image_quality.illumination.relative_illumination` predicts
from a prescription. The uncertainty of a ring is the standard deviation of its value over the
frames divided by the square root of their number (with one frame: the spread of the ring's
pixels over the square root of their count). The sensor's own response (microlens acceptance
angle, its cos^4 share) is in the measurement and not in the prediction of the lens alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from .chart import MAX_IMAGE_PIXELS, check_pixels, image_size, read_gray

__all__ = ["MeasuredIllumination", "measure_illumination"]

#: Rings from the axis to the frame's farthest corner
RINGS = 12


@dataclass
class MeasuredIllumination:
    """Relative illumination against image height (mm from the principal point), with its uncertainty."""

    frames: list[str]
    height_mm: np.ndarray
    relative: np.ndarray
    std: np.ndarray

    def to_dict(self) -> dict:
        return {"frames": list(self.frames),
                "points": [{"image_height_mm": float(h), "relative_illumination": float(r), "std": float(s)}
                           for h, r, s in zip(self.height_mm, self.relative, self.std)],
                "definition": "ring mean over the centre ring's, rings about the measured principal point"}


def measure_illumination(paths, size_px, sensor_mm, principal_point_px, *, rings: int = RINGS,
                         max_pixels: int = MAX_IMAGE_PIXELS) -> MeasuredIllumination:
    """Relative illumination of the flat-field frames ``paths`` (module notes); ``principal_point_px``
    in OpenCV pixels (x right, y down, pixel centres at whole numbers). Every frame's size is read
    from its header before anything is decoded (:func:`.calibrate_chart.read_gray`, ``max_pixels``);
    the frames are reduced to their ring sums one at a time, a band of rows at a time."""
    from .calibrate import _pair

    if isinstance(paths, (str, bytes)) or not hasattr(paths, "__iter__"):
        raise InputError(f"give the flat-field frames' file names, got {type(paths).__name__}")
    paths = [str(p) for p in paths]
    sensor_mm = _pair("sensor_mm", sensor_mm)
    for name, v in (("size_px", size_px), ("principal_point_px", principal_point_px)):
        if isinstance(v, (str, bytes)) or not hasattr(v, "__len__") or len(v) != 2:
            raise InputError(f"{name} is a pair of numbers, got {v!r}")
    if not paths:
        raise InputError("give one or more flat-field frames")
    w, h = size_px
    for p in paths:  # every header before the first frame is decoded
        fw, fh = image_size(p)
        check_pixels(p, fw, fh, max_pixels)
        if (fw, fh) != (w, h):
            raise InputError(f"{p}: {fw}x{fh} px, but the chart images are {w}x{h}: give flat fields of the same "
                             "camera mode")
    pitch = (sensor_mm[0] / w, sensor_mm[1] / h)
    r_max = max(np.hypot((x - principal_point_px[0]) * pitch[0], (y - principal_point_px[1]) * pitch[1])
                for x in (0, w - 1) for y in (0, h - 1))
    edges = np.linspace(0.0, r_max * (1 + 1e-9), rings + 1)
    counts, per, sq = None, [], None
    for p in paths:
        c, sums, sums2 = _ring_sums(read_gray(p, max_pixels=max_pixels), edges, pitch, principal_point_px, rings)
        counts = c
        per.append(sums / np.maximum(c, 1))
        sq = sums2 if sq is None else sq
    if (counts == 0).any():
        raise InputError("the frame is too small for the rings of the flat-field measurement")
    per = np.array(per)
    if not (per[:, 0] > 0).all():
        raise InputError(f"{paths[0]}: the flat field's centre is black: not a flat-field frame")
    rel = per / per[:, :1]
    if len(paths) > 1:
        std = rel.std(axis=0, ddof=1) / math.sqrt(len(paths))
    else:
        spread = np.sqrt(np.maximum(sq / counts - per[0] ** 2, 0.0)) / per[0, 0]
        std = spread / np.sqrt(counts)
    mid = 0.5 * (edges[:-1] + edges[1:])
    mid[0] = 0.0
    return MeasuredIllumination(paths, mid, rel.mean(axis=0), std)


def _ring_sums(img, edges, pitch, pp, rings, band: int = 256):
    """(pixel count, sum, sum of squares) per ring of ``img``, a band of rows at a time (memory of one band)."""
    h, w = img.shape
    counts, sums, sums2 = np.zeros(rings), np.zeros(rings), np.zeros(rings)
    dx2 = ((np.arange(w) - pp[0]) * pitch[0]) ** 2
    for y0 in range(0, h, band):
        rows = np.arange(y0, min(h, y0 + band))
        r = np.sqrt(dx2[None, :] + (((rows - pp[1]) * pitch[1]) ** 2)[:, None])
        ring = (np.digitize(r, edges) - 1).ravel()
        v = img[y0:y0 + len(rows)].astype(np.float64).ravel()
        counts += np.bincount(ring, minlength=rings)[:rings]
        sums += np.bincount(ring, v, minlength=rings)[:rings]
        sums2 += np.bincount(ring, v * v, minlength=rings)[:rings]
    return counts, sums, sums2
