"""The one-page calibration sheet of a chart calibration (docs/calibrate.md): the measured distortion
over the frame with every corner found, the residual of each view, the figures and their
uncertainty, breathing, relative illumination and the verdict against the prescription."""

from __future__ import annotations

import math

import numpy as np

from ...figures import new_figure, save_figure, styled

__all__ = ["calibration_sheet"]


def _field_panel(ax, m) -> None:
    from .calibrate import _grid, displacement_px

    w, h = m.size_px
    g = _grid(m.size_px)
    d = displacement_px(m.camera_matrix, m.distortion, m.size_px)
    mag = np.hypot(*d.T)
    sc = ax.scatter(g[:, 0], g[:, 1], c=mag, s=10, cmap="viridis")
    ax.quiver(g[:, 0], g[:, 1], d[:, 0], -d[:, 1], angles="xy", scale_units="xy", scale=0.1, width=0.002)
    for v in m.views:
        ax.plot(v.image_points[:, 0], v.image_points[:, 1], ",", color="tab:red", alpha=0.5)
    ax.figure.colorbar(sc, ax=ax, label="distortion (px)", shrink=0.8)
    ax.set_xlim(0, w)
    ax.set_ylim(h, 0)
    ax.set_aspect("equal")
    where = "infinity" if m.mark_mm is None or math.isinf(m.mark_mm) else f"{m.mark_mm:g} mm"
    ax.set_title(f"measured distortion at {where} (arrows x10), corners found (red)", fontsize=8)


def _text(m, cal) -> str:
    good, why = m.verdict
    u = m.uncertainty or {}
    fs = (u.get("focal_length_mm") or {}).get("y", math.nan)
    pp = u.get("principal_point_px", [math.nan, math.nan])
    k1, k2, p1, p2, k3 = m.distortion
    lines = [(f"{cal.lens_name}: {len(m.views)} views, {m.size_px[0]}x{m.size_px[1]} px, "
              f"sensor {m.sensor_mm[0]:g} x {m.sensor_mm[1]:g} mm"),
             f"pinhole focal length {m.focal_length_mm[1]:.4f} mm +- {fs:.4f} (1 sigma)",
             (f"principal point ({m.principal_point_px[0]:.2f}, {m.principal_point_px[1]:.2f}) px +- "
              f"({pp[0]:.2f}, {pp[1]:.2f})"),
             f"OpenCV k1 {k1:.5f} k2 {k2:.5f} k3 {k3:.5f} p1 {p1:.6f} p2 {p2:.6f}",
             (f"residual {m.rms_px:.3f} px RMS; field uncertainty "
              f"{'not estimated' if 'field_rms_px' not in u else format(u['field_rms_px'], '.3f') + ' px RMS'}; "
              f"coverage {100 * m.coverage:.0f} %")]
    lines += [f"{f.model}: max {f.max_residual_px:.3f} px {'good' if f.acceptable else 'NOT good'}" for f in m.fits]
    lines.append("verdict: " + ("good" if good else "NOT good: " + "; ".join(why)))
    if cal.comparison is not None:
        c = cal.comparison
        lines.append(f"against {c.lens_name}: " + ("agrees" if c.agrees else "does NOT agree")
                     + f" (k = {c.k:g})")
        lines += [f"  {r['figure']}: {r['measured']:.4g} vs {r['predicted']:.4g} {r['unit']} "
                  f"(+- {r['std']:.2g}) {'ok' if r['agrees'] else 'DIFFERS'}" for r in c.rows[:8]]
    return "\n".join(lines)


#: Characters of the sheet's text a line holds: its panel (two thirds of an A4 page's width, 7.8 in) in 7 pt
#: monospace (0.6 em a character, 4.2 pt), with room to spare. A longer line (a verdict with its reasons) ran off
#: the page, and tight_layout, unable to make room for it, left the sheet unlaid with a warning (round 22).
TEXT_CHARS = 120


def _wrapped(text: str) -> str:
    """``text``'s lines cut at words to :data:`TEXT_CHARS`, a cut line's rest indented."""
    import textwrap

    return "\n".join("\n".join(textwrap.wrap(line, TEXT_CHARS, subsequent_indent="    ")) or line
                     for line in text.split("\n"))


@styled
def calibration_sheet(calibration, path=None, *, force: bool = False):
    """The sheet of ``calibration`` (a :class:`~physcam.analysis.calibration.calibrate.Calibration`); written to
    ``path`` (.png, .svg, .pdf) through :func:`physcam.figures.save_figure`, else returned."""
    from ...errors import InputError
    from .calibrate import Calibration

    if not isinstance(calibration, Calibration):
        raise InputError(f"give a Calibration (calibrate_views), got {type(calibration).__name__}")
    m = calibration.marks[0]
    fig = new_figure(figsize=(11.69, 8.27))
    gs = fig.add_gridspec(2, 3)
    _field_panel(fig.add_subplot(gs[0, :2]), m)
    ax = fig.add_subplot(gs[0, 2])
    ax.bar(range(len(m.views)), m.view_rms_px, color="tab:blue")
    ax.axhline(m.max_residual_px, color="tab:red", lw=0.8)
    ax.set_xlabel("view")
    ax.set_ylabel("residual RMS (px)")
    ax.set_title("residual of each view", fontsize=8)
    ax = fig.add_subplot(gs[1, 2])
    if calibration.breathing:
        rows = calibration.breathing
        ax.errorbar([r.mark_mm / 1000.0 for r in rows], [r.change_pct for r in rows],
                    yerr=[r.change_std_pct for r in rows], fmt="o-")
        ax.set_xlabel("focus mark (m from the film)")
        ax.set_ylabel("focal length change (%)")
        ax.set_title("breathing against the farthest mark", fontsize=8)
    elif calibration.illumination is not None:
        ill = calibration.illumination
        ax.errorbar(ill.height_mm, ill.relative, yerr=ill.std, fmt="o-")
        ax.set_xlabel("image height (mm)")
        ax.set_ylabel("relative illumination")
    else:
        ax.axis("off")
    ax = fig.add_subplot(gs[1, :2])
    ax.axis("off")
    ax.text(0.0, 1.0, _wrapped(_text(m, calibration)), va="top", family="monospace", fontsize=7)
    fig.suptitle(f"physcam calibration sheet: {calibration.lens_name}", fontsize=11)
    fig.tight_layout()
    return fig if path is None else save_figure(fig, path, force=force)
