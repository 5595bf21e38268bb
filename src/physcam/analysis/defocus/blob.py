"""Measuring a bright blob in an image: centroid, second-moment size, rim and polygon corners.

Used to compare pictures made by different renderers of the same point light (physcam's own
bokeh, a Cycles render through physcam's OSL camera). Images are 2-D arrays, row 0 at the bottom.
A uniform disk of diameter c has E[r^2] = c^2 / 8 about its centre, so the second moment gives an
"equivalent diameter" sqrt(8 E[r^2]); moments of a convolution add, so a source's own image of
diameter e is removed as sqrt(8 E[r^2] - e^2).
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import InputError

__all__ = ["blob_moments", "equivalent_diameter", "rim_profile", "polygon_corners"]


def _image(img) -> np.ndarray:
    a = np.asarray(img, dtype=float)
    if a.ndim != 2 or min(a.shape) < 3 or not np.isfinite(a).all():
        raise InputError("a blob image must be a finite 2-D array of at least 3 x 3 pixels")
    if not a.sum() > 0:
        raise InputError("the image holds no light to measure")
    return a


def blob_moments(img, pixel: float = 1.0):
    """(cx, cy, E[r^2]) about the image centre, in units of ``pixel`` (the pixel pitch)."""
    a = _image(img)
    h, w = a.shape
    ys, xs = np.indices(a.shape)
    X, Y = (xs + 0.5 - w / 2) * pixel, (ys + 0.5 - h / 2) * pixel
    tot = a.sum()
    cx, cy = (a * X).sum() / tot, (a * Y).sum() / tot
    return float(cx), float(cy), float((a * ((X - cx) ** 2 + (Y - cy) ** 2)).sum() / tot)


def equivalent_diameter(img, pixel: float = 1.0, source_diameter: float = 0.0) -> float:
    """Diameter of the uniform disk with the blob's second moment, the source's own image removed."""
    m2 = blob_moments(img, pixel)[2]
    return float(math.sqrt(max(8.0 * m2 - source_diameter**2, 0.0)))


def rim_profile(img, n_angles: int = 360):
    """(angles, radii in pixels): where the 3 x 3 box-smoothed image last exceeds half its central
    plateau along each ray from the centroid (bilinear sampling)."""
    a = _image(img)
    h, w = a.shape
    p = np.pad(a, 1)
    sm = sum(p[1 + i:1 + i + h, 1 + j:1 + j + w] for i in (-1, 0, 1) for j in (-1, 0, 1)) / 9.0
    ys, xs = np.indices(a.shape)
    tot = a.sum()
    cx, cy = (a * xs).sum() / tot, (a * ys).sum() / tot
    r_eq = math.sqrt(2.0 * (a * ((xs - cx) ** 2 + (ys - cy) ** 2)).sum() / tot)
    plateau = sm[(xs - cx) ** 2 + (ys - cy) ** 2 < (0.5 * r_eq) ** 2].mean()
    rs = np.arange(0.0, 1.6 * r_eq, 0.05)
    th = np.arange(n_angles) * 2 * math.pi / n_angles
    X = cx + np.cos(th)[:, None] * rs[None, :]
    Y = cy + np.sin(th)[:, None] * rs[None, :]
    x0 = np.clip(np.floor(X).astype(int), 0, w - 2)
    y0 = np.clip(np.floor(Y).astype(int), 0, h - 2)
    fx, fy = X - x0, Y - y0
    v = (sm[y0, x0] * (1 - fx) * (1 - fy) + sm[y0, x0 + 1] * fx * (1 - fy) + sm[y0 + 1, x0] * (1 - fx) * fy
         + sm[y0 + 1, x0 + 1] * fx * fy)
    above = v > 0.5 * plateau
    last = above.shape[1] - 1 - np.argmax(above[:, ::-1], axis=1)
    return th, rs[last]


#: Share of the rim's range (largest radius less smallest) a corner stands out by, from the lower of
#: the troughs either side (a smaller bump is noise: polygon_corners)
CORNER_PROMINENCE = 0.1


def polygon_corners(img) -> tuple[int, int, float]:
    """(corners counted, dominant harmonic, angle of one corner in degrees modulo 360/harmonic) of a
    blob's rim: the rim profile low-passed to 12 harmonics, its local maxima counted that stand out by
    :data:`CORNER_PROMINENCE` of the profile's range from the higher trough either side (topographic
    prominence on the circle). A 512-sample Cycles render's rim wanders by about 0.05 px, which on a
    hexagon's flat side (2.5 px from corner to flat) made a seventh maximum 0.04 px high."""
    th, r = rim_profile(img)
    F = np.fft.rfft(r)
    F[13:] = 0.0
    smooth = np.fft.irfft(F, r.size)
    k = int(np.argmax(np.abs(F[1:13]))) + 1
    phase = -np.angle(F[k]) / k
    return _prominent_peaks(smooth, CORNER_PROMINENCE * float(smooth.max() - smooth.min())), k, \
        float(math.degrees(phase) % (360.0 / k))


def _prominent_peaks(v, least: float) -> int:
    """How many local maxima of the circular sequence ``v`` rise at least ``least`` above the higher
    of the troughs between them and their higher neighbours: of its alternating maxima and minima, the
    adjacent pair that differs least is dropped while it differs by less."""
    peaks = (v > np.roll(v, 1)) & (v >= np.roll(v, -1))
    troughs = (v < np.roll(v, 1)) & (v <= np.roll(v, -1))
    ext = [(float(v[i]), bool(peaks[i])) for i in np.flatnonzero(peaks | troughs).tolist()]
    while len(ext) > 2:
        gaps = [abs(ext[i][0] - ext[(i + 1) % len(ext)][0]) for i in range(len(ext))]
        i = int(np.argmin(gaps))
        if gaps[i] >= least:
            break
        # dropping an adjacent maximum and minimum leaves the others alternating
        ext = [e for m, e in enumerate(ext) if m not in (i, (i + 1) % len(ext))]
    return sum(1 for _, is_peak in ext if is_peak)
