"""How two consumers read an OpenTrackIO ``lens.distortion`` entry, written from their public
documentation, not from physcam (issue 31):

* camdkit's note "Conversion of OpenCV to OpenTrackIO (OpenLensIO) lens calibration parameters"
  (SMPTE ris-osvp-metadata-camdkit, corrected 2025-09-02): l1 = k1/F^2, l2 = k4/F^2, l3 = k2/F^4,
  l4 = k5/F^4, l5 = k3/F^6, l6 = k6/F^6 (OpenCV's rational model);
* Unreal's Live Link OpenTrackIO receiver: K1 = l1 F^2, K2 = l3 F^4, K3 = l5 F^6 into its
  OpenCV-style spherical model; fewer than six radial terms read as none.

Both return OpenCV's k1..k6 (normalised coordinates); :func:`opencv_rational` is OpenCV's documented
distortion of normalised points with them.
"""

from __future__ import annotations

import numpy as np


def opencv_rational(xy, k, p1=0.0, p2=0.0):
    """OpenCV's distortion of normalised points (its documented rational model)."""
    x, y = xy[:, 0], xy[:, 1]
    r2 = x * x + y * y
    rad = (1 + k[0] * r2 + k[1] * r2**2 + k[2] * r2**3) / (1 + k[3] * r2 + k[4] * r2**2 + k[5] * r2**3)
    return np.c_[x * rad + 2 * p1 * x * y + p2 * (r2 + 2 * x * x), y * rad + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y]


def camdkit_reader(dist, f):
    """OpenCV k1..k6 from an OpenTrackIO radial list as camdkit's conversion note numbers it."""
    l_ = list(dist["radial"]) + [0.0] * (6 - len(dist["radial"]))
    return [l_[0] * f**2, l_[2] * f**4, l_[4] * f**6, l_[1] * f**2, l_[3] * f**4, l_[5] * f**6]


def unreal_reader(dist, f):
    """Unreal's spherical K1-K3 (no denominator) from an OpenTrackIO radial list: none below six terms."""
    l_ = dist["radial"]
    if len(l_) < 6:
        return [0.0] * 6
    return [l_[0] * f**2, l_[2] * f**4, l_[4] * f**6, 0.0, 0.0, 0.0]


READERS = {"camdkit": camdkit_reader, "unreal": unreal_reader}
