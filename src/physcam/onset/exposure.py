"""Exposure on set, in stops: shutter angle and frame rate, ND, exposure index and T-stop.

The film (or sensor) receives, per frame, an exposure proportional to t / T^2 (t the exposure time,
T the T-stop: the f-number corrected for the lens's transmission), and the picture's brightness to
that exposure times the exposure index EI (ISO 12232's rating of the camera's gain) and the
neutral-density filter's transmission 10^-D (D its optical density). One stop is a factor of 2:

* exposure time t = (shutter angle / 360) / frame rate (a rotary shutter open for that fraction of
  the frame: 180 deg at 24 fps is 1/48 s);
* stops = log2(t2 / t1) + log2(EI2 / EI1) - 2 log2(T2 / T1) - (D2 - D1) / 0.3, an ND's stops its
  density over 0.3 as the makers label them (ND 0.3 = 1 stop, 0.9 = 3 stops; its true factor
  10^-0.3 = 0.501 is 0.997 stop, see :func:`nd_transmission`).

Sources: ISO 12232:2019 (exposure index); the makers' shutter tables (RED's KOMODO guide: 180 deg at
23.98 fps is 1/47.95 s); Tiffen's ND labelling (0.3 per stop).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..errors import InputError, require_positive, require_type
from ..optics.thinlens import require_f_number

__all__ = ["ExposureSetting", "exposure_time_s", "shutter_angle_for", "stops_between_settings", "compensate",
           "nd_transmission", "ND_STOP_DENSITY"]

#: Optical density per stop as ND filters are labelled (0.3, 0.6, 0.9 ...: 1, 2, 3 stops).
ND_STOP_DENSITY = 0.3


def exposure_time_s(shutter_angle_deg: float, fps: float) -> float:
    """t = (angle / 360) / fps, seconds."""
    a = require_positive("shutter angle", shutter_angle_deg, unit="degrees")
    if a > 360.0:
        raise InputError(f"a shutter angle is at most 360 degrees (open all the frame), got {a:g}")
    return (a / 360.0) / require_positive("frame rate", fps, unit="fps")


def shutter_angle_for(exposure_time: float, fps: float) -> float:
    """The shutter angle (degrees) that exposes ``exposure_time`` seconds per frame at ``fps``."""
    a = 360.0 * require_positive("exposure time", exposure_time, unit="s") * require_positive("frame rate", fps,
                                                                                                  unit="fps")
    if a > 360.0 + 1e-9:
        raise InputError(f"{exposure_time:g} s per frame at {fps:g} fps needs a {a:.1f} degree shutter: more than the "
                         "whole frame (360)")
    return a


def nd_transmission(density: float) -> float:
    """The fraction of light an ND of optical ``density`` passes, 10^-D."""
    if not math.isfinite(density) or density < 0:
        raise InputError(f"an ND's optical density is 0 or more (0.3 per stop), got {density!r}")
    return 10.0 ** -density


@dataclass(frozen=True)
class ExposureSetting:
    """One camera setting: frame rate, shutter angle (degrees), T-stop, exposure index and ND density."""

    fps: float = 24.0
    shutter_deg: float = 180.0
    tstop: float = 2.8
    ei: float = 800.0
    nd: float = 0.0

    def __post_init__(self):
        exposure_time_s(self.shutter_deg, self.fps)
        require_f_number("T-stop", self.tstop)
        require_positive("exposure index", self.ei, unit="")
        nd_transmission(self.nd)

    @property
    def exposure_time_s(self) -> float:
        return exposure_time_s(self.shutter_deg, self.fps)

    def to_dict(self) -> dict:
        return {"fps": self.fps, "shutter_deg": self.shutter_deg, "tstop": self.tstop, "ei": self.ei, "nd": self.nd,
                "exposure_time_s": self.exposure_time_s}


def stops_between_settings(a: ExposureSetting, b: ExposureSetting) -> dict:
    """How much brighter (+) or darker (-) setting ``b`` makes the picture than ``a``, in stops, and the
    part each control plays (shutter and frame rate, EI, T-stop, ND)."""
    for name, v in (("a", a), ("b", b)):
        require_type(name, v, ExposureSetting, "physcam.onset.exposure.ExposureSetting(fps=24, shutter_deg=180, ...)")
    parts = {"time": math.log2(b.exposure_time_s / a.exposure_time_s), "ei": math.log2(b.ei / a.ei),
             "tstop": 0.0 - 2.0 * math.log2(b.tstop / a.tstop), "nd": (a.nd - b.nd) / ND_STOP_DENSITY}
    return {"stops": sum(parts.values()), "parts": parts}


def compensate(a: ExposureSetting, b: ExposureSetting, control: str = "tstop") -> ExposureSetting:
    """``b`` with ``control`` ("tstop", "nd", "ei" or "shutter") changed so that it exposes as ``a`` does."""
    delta = stops_between_settings(a, b)["stops"]
    if not isinstance(control, str):
        raise InputError(f"compensate with tstop, nd, ei or shutter, not {control!r}")
    if control == "tstop":
        return replace(b, tstop=b.tstop * 2.0 ** (delta / 2.0))
    if control == "nd":
        nd = b.nd + delta * ND_STOP_DENSITY
        if nd < -1e-12:
            raise InputError(f"the new setting is {-delta:.2f} stops darker: no ND can give light back; open the "
                             "T-stop or raise the EI")
        return replace(b, nd=max(nd, 0.0))
    if control == "ei":
        return replace(b, ei=b.ei * 2.0 ** -delta)
    if control == "shutter":
        return replace(b, shutter_deg=shutter_angle_for(b.exposure_time_s * 2.0 ** -delta, b.fps))
    raise InputError(f"compensate with tstop, nd, ei or shutter, not {control!r}")
