"""A zoom lens's figure: breathing over zoom x focus and parfocality over the zoom (docs/zoom.md).

Left: the horizontal field of view against the focus mark (on a 1/distance axis, infinity at 0) at
each tabulated zoom position, one line per position
(:func:`physcam.optics.zoom.zoom_breathing`). Right: the image-plane shift (paraxial image of
infinity minus the film plane; + behind the film) and the EFL against the zoom encoder, along the
interpolated cams, the tabulated positions marked (:func:`physcam.optics.zoom.zoom_table`).
"""

from __future__ import annotations

import math
from pathlib import Path

from ...data.default_sensor import DEFAULT_SENSOR_WIDTH_MM
from ...figures import styled
from ...lens.prescription import Prescription, takes_prescription

__all__ = ["zoom_figure", "save_zoom_figure"]

#: Encoder samples of the parfocality curve.
CURVE_SAMPLES = 41


@styled
@takes_prescription
def zoom_figure(lens: Prescription, *, sensor_width_mm: float = DEFAULT_SENSOR_WIDTH_MM):
    """A matplotlib Figure (Agg canvas) of breathing and parfocality (module notes)."""
    from ...figures import PALETTE, fit_title, new_figure
    from ...optics.zoom import zoom_breathing, zoom_table

    fig = new_figure(figsize=(10.0, 4.2))
    ax, bx = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    for k, (u, rows) in enumerate(zoom_breathing(lens, sensor_width_mm=sensor_width_mm)):
        x = [0.0 if math.isinf(r.focus_from_film_mm) else 1000.0 / r.focus_from_film_mm for r in rows]
        ax.plot(x, [r.hfov_deg for r in rows], marker="o", ms=3, color=PALETTE[k % len(PALETTE)],
                label=f"EFL {rows[0].efl_mm:.1f} mm (encoder {u:.2f})")
    ax.set_xlabel("1 / focus mark from the film (1/m; 0 = infinity)")
    ax.set_ylabel(f"horizontal field of view (deg), {sensor_width_mm:g} mm sensor")
    ax.set_title("breathing at each tabulated zoom position")
    ax.grid(True)
    ax.legend(loc="best", fontsize=7)
    curve = zoom_table(lens, [k / (CURVE_SAMPLES - 1) for k in range(CURVE_SAMPLES)], sensor_width_mm=sensor_width_mm)
    marks = zoom_table(lens, list(lens.zoom.encoder), sensor_width_mm=sensor_width_mm)
    bx.plot([r.encoder for r in curve], [r.image_shift_mm for r in curve], color=PALETTE[0],
            label="image-plane shift (interpolated cams)")
    bx.plot([r.encoder for r in marks], [r.image_shift_mm for r in marks], "o", color=PALETTE[0],
            label="tabulated positions")
    bx.axhline(0.0, color=PALETTE[7], linewidth=0.6)
    bx.set_xlabel("zoom encoder (0 = first tabulated position, 1 = last)")
    bx.set_ylabel("image-plane shift from the film (mm; + behind)")
    bx.grid(True)
    b2 = bx.twinx()
    b2.spines["right"].set_visible(True)
    b2.plot([r.encoder for r in curve], [r.efl_mm for r in curve], linestyle="--", color=PALETTE[1], label="EFL")
    b2.set_ylabel("effective focal length (mm)")
    lines = bx.get_lines()[:2] + b2.get_lines()
    bx.legend(lines, [ln.get_label() for ln in lines], loc="best", fontsize=7)
    bx.set_title("parfocality and focal length over the zoom")
    fig.suptitle(fit_title(f"{lens.name}: breathing and parfocality", 9.5))
    fig.tight_layout()
    return fig


@styled
@takes_prescription
def save_zoom_figure(lens: Prescription, path, *, force: bool = False,
                     sensor_width_mm: float = DEFAULT_SENSOR_WIDTH_MM) -> Path:
    """Write :func:`zoom_figure` to ``path`` (.png, .svg, .pdf) through atomic_write."""
    from ...figures import save_figure

    return save_figure(zoom_figure(lens, sensor_width_mm=sensor_width_mm), path, force=force, dpi=150)
