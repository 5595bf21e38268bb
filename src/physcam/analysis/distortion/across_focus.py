"""Distortion across focus: the breathing of distortion, as a table for a lens report (docs/distortion.md).

For each focus mark (mm from the film plane; infinity allowed) the real chief rays are traced over
the frame (:func:`physcam.analysis.distortion.stmap.distortion_field`, no maps) and measured against the
best-match pinhole *at that focus*; the row gives that pinhole's focal length, the largest
distortion in pixels, the corner distortion in percent, 100 (r_real - r_ideal) / r_ideal of the
frame's corner, and the fitted Brown-Conrady D-U and 3DE4 coefficients with their residuals.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from ...figures import PALETTE, styled
from ...lens.prescription import Prescription, takes_prescription

__all__ = ["DistortionAcrossFocus", "distortion_across_focus", "MAX_FOCUS_ROWS"]

MAX_FOCUS_ROWS = 64


@dataclass
class DistortionAcrossFocus:
    lens_name: str
    sensor_mm: tuple[float, float]
    size_px: tuple[int, int]
    rows: list[dict]
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"lens": self.lens_name, "sensor_mm": list(self.sensor_mm), "size_px": list(self.size_px),
                "focus_reference": "mm from the film plane; null = infinity",
                "corner_distortion_definition": "100 (r_real - r_ideal) / r_ideal at the frame corner; negative = barrel",
                "rows": [dict(r) for r in self.rows], "notes": list(self.notes)}

    @styled
    def plot(self, path=None, *, force: bool = False, units: str = "m"):
        """Corner distortion and pinhole focal length against focus, a tick at each mark in ``units``
        (m, or ft for feet and inches); PNG/SVG if ``path``, else the Figure."""
        from .._plot import distance_ticks, figure, save, unit_words

        fig, ax = figure(5.6, 3.6)
        finite = [r for r in self.rows if r["focus_from_film_mm"] is not None]
        ax.set_xscale("log")
        x = distance_ticks(ax, [r["focus_from_film_mm"] for r in finite], units)
        ax.plot(x, [r["corner_distortion_pct"] for r in finite], "o-", label="corner distortion (%)")
        inf = [r for r in self.rows if r["focus_from_film_mm"] is None]
        if inf:
            ax.axhline(inf[0]["corner_distortion_pct"], ls=":", color="0.4", label="at infinity")
        ax.tick_params(axis="x", labelsize=7)
        ax.set_xlabel(f"focus from the film plane ({unit_words(units)})")
        ax.set_ylabel("corner distortion (%)")
        ax2 = ax.twinx()
        ax2.plot(x, [r["pinhole_focal_length_mm"] for r in finite], "s--", color=PALETTE[1], ms=3)
        ax2.set_ylabel("pinhole focal length (mm)", color=PALETTE[1])
        ax.legend(fontsize=7, loc="center right")
        ax.set_title(f"{self.lens_name}: distortion across focus on {self.sensor_mm[0]:g} x {self.sensor_mm[1]:g} mm",
                     fontsize=8)
        return save(fig, path, force)


@takes_prescription
def distortion_across_focus(lens: Prescription, focus_mm, *, sensor_width_mm: float, sensor_height_mm: float,
                            width_px: int, height_px: int, wavelength_nm: float | None = None,
                            method: str = "auto") -> DistortionAcrossFocus:
    """One row per focus mark in ``focus_mm`` (module notes)."""
    from ...optics.state import camera_state
    from .models import fit_brown_conrady, fit_tde4_radial, samples_from_field
    from .stmap import distortion_field

    marks = list(np.atleast_1d(np.asarray(focus_mm, dtype=float)))
    if not 1 <= len(marks) <= MAX_FOCUS_ROWS:
        raise InputError(f"give 1 to {MAX_FOCUS_ROWS} focus distances, got {len(marks)}")
    rows = []
    for s in marks:
        camera = camera_state(lens, focus_mm=s, sensor_mm=(sensor_width_mm, sensor_height_mm))
        res = distortion_field(camera, width_px=width_px, height_px=height_px, wavelength_nm=wavelength_nm,
                               method=method, maps=False)
        smp = samples_from_field(res)
        r_real = np.hypot(*smp.distorted_mm.T)
        k = int(np.argmax(r_real))  # a frame corner
        r_ideal = float(np.hypot(*smp.undistorted_mm[k]))
        brown = fit_brown_conrady(smp, "D-U", max_residual_px=math.inf)
        tde4 = fit_tde4_radial(smp, max_residual_px=math.inf)
        rows.append({
            "focus_from_film_mm": None if math.isinf(res.focus_from_film_mm) else res.focus_from_film_mm,
            "pinhole_focal_length_mm": res.pinhole_focal_length_mm[1],
            "pinhole_focal_length_x_mm": res.pinhole_focal_length_mm[0],
            "max_distortion_px": res.max_distortion_px,
            "corner_distortion_pct": 100.0 * (float(r_real[k]) - r_ideal) / r_ideal,
            "brown_du": {n: brown.coefficients[n] for n in ("k1", "k2", "k3", "p1", "p2")}
            | {"rms_px": brown.rms_residual_px, "max_px": brown.max_residual_px},
            "tde4": {"Distortion - Degree 2": tde4.coefficients["Distortion - Degree 2"],
                     "Quartic Distortion - Degree 4": tde4.coefficients["Quartic Distortion - Degree 4"],
                     "rms_px": tde4.rms_residual_px, "max_px": tde4.max_residual_px},
        })
    return DistortionAcrossFocus(lens.name, (float(sensor_width_mm), float(sensor_height_mm)),
                                 (int(width_px), int(height_px)), rows,
                                 ["each row against the best-match pinhole at that focus (its paraxial focal length)"])
