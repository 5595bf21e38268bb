"""The lens card's zoom page: how a zoom lens changes across its range (issue 45; docs/lens-card.md).

A second page of the card of a zoom lens (a prescription with a zoom table, docs/zoom.md), the same
paper size: the lens section at the first and last tabulated positions; a table of the tabulated
positions and the midpoints between them (where interpolated cams stray most); and, against the
normalised zoom encoder along the interpolated cams (:func:`physcam.optics.zoom.zoom_table`, at
infinity focus with the stop full open): the focal length (with the source's stated labels), the
f-number ramp with the entrance-pupil diameter, where the entrance pupil lies in front of the film,
the image-plane shift (parfocality: the paraxial image of infinity minus the film plane, + behind the
film); focus breathing at each tabulated position (the horizontal field's change from infinity focus,
:func:`physcam.optics.zoom.zoom_breathing`); and real distortion against image height at each
tabulated position, focused at infinity (:func:`physcam.analysis.distortion.field.real_distortion`).
The position the card's first page shows is marked on every curve. Lengths in mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ...errors import InputError, OpticsError
from ...figures import PALETTE
from ...lens.prescription import Prescription, takes_prescription
from ._page import checked_drawing, draw_distortion_curves, sensor_size

__all__ = ["ZOOM_PANELS", "ZoomPage", "zoom_page", "draw_zoom_page"]

#: The zoom page's panels, by the label their axes carry.
ZOOM_PANELS = ("zoom wide section", "zoom tele section", "zoom table", "zoom focal length", "zoom f-number",
               "zoom entrance pupil", "zoom parfocality", "zoom breathing", "zoom distortion")

#: Encoder samples of the curves along the cams.
CURVE_SAMPLES = 41


@dataclass
class ZoomPage:
    """What the zoom page shows (module notes); ``encoder``: the position of the card's first page."""

    lens_name: str
    encoder: float
    sensor_width_mm: float
    positions: list  # ZoomRow: tabulated positions and the midpoints between them
    curve: list  # ZoomRow along the cams, CURVE_SAMPLES encoder values 0..1
    breathing: list  # (encoder, [BreathingRow]) at each tabulated position
    distortion: list  # (encoder, DistortionResult or None) at each tabulated position, infinity focus
    sections: list  # (encoder, LensDiagram) at the first and last tabulated positions
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"lens": self.lens_name, "panels": list(ZOOM_PANELS), "card_encoder": self.encoder,
                "sensor_width_mm": self.sensor_width_mm,
                "conditions": "infinity focus, stop full open (its tabulated size where the source gives one); "
                              "image shift = paraxial image of infinity minus the film plane, + behind the film",
                "positions": [r.to_dict() for r in self.positions],
                "curve": [r.to_dict() for r in self.curve],
                "breathing": [{"encoder": u, "efl_mm": rows[0].efl_mm if rows else None,
                               "rows": [r.to_dict() for r in rows]} for u, rows in self.breathing],
                "distortion": [{"encoder": u, "field": None if d is None else d.to_dict()} for u, d in self.distortion],
                "sections": [{"encoder": u, "diagram": d.to_dict()} for u, d in self.sections],
                "notes": list(self.notes)}


@takes_prescription
def zoom_page(lens: Prescription, encoder: float, sensor_mm: tuple[float, float], *, curve_fields: int = 6,
              backend: str = "auto") -> ZoomPage:
    """The zoom page of zoom lens ``lens`` whose first page shows zoom ``encoder`` (0..1 or a focal length
    such as "135mm") on a ``sensor_mm`` (width, height) sensor (module notes)."""
    from ...lens.zoom import prescription_at
    from ...optics.state import camera_state
    from ...optics.zoom import default_encoders, zoom_breathing, zoom_encoder, zoom_table
    from ..distortion.field import real_distortion
    from .diagram import lens_diagram

    if lens.zoom is None:
        raise InputError(f"lens {lens.name!r} is not a zoom lens (its file has no zoom table): it has no zoom page")
    encoder = zoom_encoder(lens, encoder)
    w, h = sensor_size(sensor_mm)
    notes: list[str] = []
    enc = list(lens.zoom.encoder)
    positions = zoom_table(lens, default_encoders(lens), sensor_width_mm=w)
    curve = zoom_table(lens, [k / (CURVE_SAMPLES - 1) for k in range(CURVE_SAMPLES)], sensor_width_mm=w)
    try:
        breathing = zoom_breathing(lens, sensor_width_mm=w)
    except OpticsError as exc:
        breathing = []
        notes.append(f"breathing: {exc}")
    distortion = []
    for u in enc:
        try:
            d = real_distortion(prescription_at(lens, u), n_fields=curve_fields, sensor_width_mm=w,
                                sensor_height_mm=h, focus_mm=math.inf, backend=backend)
        except OpticsError as exc:
            d = None
            notes.append(f"distortion at zoom {u:g}: {exc}")
        distortion.append((u, d))
    sections = [(u, lens_diagram(camera_state(prescription_at(lens, u), sensor_mm=(w, h)), rays=3))
                for u in (enc[0], enc[-1])]
    return ZoomPage(lens.name, float(encoder), float(w), positions, curve, breathing, distortion, sections, notes)


# ---- drawing --------------------------------------------------------------------------------------
def _wrap(text: str, n: int) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, n)) or text


def draw_zoom_page(fig, page: ZoomPage, units: str) -> None:
    """Draw ``page`` on ``fig`` (a card-sized Figure) below its title, one axes per :data:`ZOOM_PANELS`."""
    checked_drawing(fig, page, ZoomPage, units)
    gs = fig.add_gridspec(5, 2, left=0.09, right=0.9, top=0.925, bottom=0.06, hspace=0.62, wspace=0.42,
                          height_ratios=(0.85, 0.7, 1.0, 1.0, 1.0))
    for k, (u, d) in enumerate(page.sections):
        ax = fig.add_subplot(gs[0, k], label=ZOOM_PANELS[k])
        d.draw(ax, units=units, width_in=3.0, title=False)
        for t in ax.texts:  # the diagram's "outside the view: ..." note, wrapped to the half-page axes
            if t.get_text().startswith("outside the view"):
                t.set_text(_wrap(t.get_text(), 70))
                t.set_fontsize(5.5)
        ax.set_xlabel("z from the first vertex (mm)", fontsize=7)
        ax.set_title(f"{('wide', 'tele')[k]} end: EFL {d.gaussian.efl:.1f} mm (zoom {u:g}), infinity", loc="left",
                     fontsize=7.5)
    _draw_table(fig.add_subplot(gs[1, :], label="zoom table"), page)
    _draw_focal_length(fig.add_subplot(gs[2, 0], label="zoom focal length"), page)
    _draw_fnumber(fig.add_subplot(gs[2, 1], label="zoom f-number"), page)
    _draw_pupil(fig.add_subplot(gs[3, 0], label="zoom entrance pupil"), page)
    _draw_parfocality(fig.add_subplot(gs[3, 1], label="zoom parfocality"), page)
    _draw_breathing(fig.add_subplot(gs[4, 0], label="zoom breathing"), page, units)
    _draw_distortion(fig.add_subplot(gs[4, 1], label="zoom distortion"), page)


def _draw_table(ax, page):
    ax.set_axis_off()
    ax.set_title("across the zoom: infinity focus, stop full open (~: between tabulated positions, on the "
                 "interpolated cams)", loc="left", fontsize=8)
    head = ("zoom", "stated", "EFL", "f-number", "pupil Ø", "pupil from film", "image shift", "HFOV")
    units = ("encoder", "mm", "mm", "", "mm", "mm", "mm", "deg")
    xs = (0.07, 0.19, 0.31, 0.43, 0.55, 0.69, 0.83, 0.96)
    for x, a, b in zip(xs, head, units):
        ax.text(x, 1.0, a, transform=ax.transAxes, ha="right", va="top", fontsize=7, fontweight="bold")
        ax.text(x, 0.88, b, transform=ax.transAxes, ha="right", va="top", fontsize=6, color="0.35")
    step = min(0.15, 0.8 / max(1, len(page.positions)))
    for i, r in enumerate(page.positions):
        vals = (f"{r.encoder:.3f}{'' if r.tabulated else ' ~'}",
                "" if r.stated_focal_length_mm is None else f"{r.stated_focal_length_mm:g}", f"{r.efl_mm:.2f}",
                f"{r.f_number:.2f}", f"{r.entrance_pupil_diameter_mm:.1f}", f"{r.entrance_pupil_from_film_mm:.1f}",
                f"{r.image_shift_mm:+.3f}", f"{r.hfov_deg:.2f}")
        y = 0.74 - i * step
        for x, v in zip(xs, vals):
            ax.text(x, y, v, transform=ax.transAxes, ha="right", va="top", fontsize=6.5,
                    color="black" if r.tabulated else "0.35")


def _mark_card(ax, page):
    ax.axvline(page.encoder, color="0.55", lw=0.8, ls=":", label="this card's page 1")


def _curve(ax, page, attr, **kw):
    ax.plot([r.encoder for r in page.curve], [getattr(r, attr) for r in page.curve], **kw)
    tab = [r for r in page.positions if r.tabulated]
    ax.plot([r.encoder for r in tab], [getattr(r, attr) for r in tab], "o", ms=3.5, color=kw.get("color"))


def _zoom_axis(ax):
    ax.set_xlim(-0.02, 1.02)
    ax.set_xlabel("zoom encoder (0 = first tabulated position)", fontsize=7)
    ax.grid(True)


def _draw_focal_length(ax, page):
    ax.set_title("focal length (paraxial EFL) across the zoom", loc="left", fontsize=8)
    _curve(ax, page, "efl_mm", color=PALETTE[0], label="EFL (dots: tabulated)")
    stated = [r for r in page.positions if r.stated_focal_length_mm is not None]
    if stated:
        ax.plot([r.encoder for r in stated], [r.stated_focal_length_mm for r in stated], "x", color=PALETTE[1],
                ms=6, label="the source's stated focal length")
    _mark_card(ax, page)
    _zoom_axis(ax)
    ax.set_ylabel("focal length (mm)")
    ax.legend(loc="upper left", fontsize=6)


def _draw_fnumber(ax, page):
    ax.set_title("f-number ramp and entrance-pupil diameter", loc="left", fontsize=8)
    _curve(ax, page, "f_number", color=PALETTE[0], label="f-number (EFL / pupil Ø)")
    _mark_card(ax, page)
    _zoom_axis(ax)
    ax.set_ylabel("f-number (ratio)")
    lo, hi = ax.get_ylim()
    if hi - lo < 0.2:  # a constant-aperture zoom: keep the axis from magnifying rounding
        mid = 0.5 * (lo + hi)
        ax.set_ylim(mid - 0.3, mid + 0.3)
    b = ax.twinx()
    b.spines["right"].set_visible(True)
    _curve(b, page, "entrance_pupil_diameter_mm", color=PALETTE[1], ls="--", label="entrance pupil Ø")
    b.set_ylabel("entrance pupil Ø (mm)", fontsize=7)
    lines = [ax.get_lines()[0], b.get_lines()[0]]
    ax.legend(lines, [ln.get_label() for ln in lines], loc="upper left", fontsize=6)


def _draw_pupil(ax, page):
    """The entrance pupil and front vertex in front of the film across the zoom: lengths inside the camera, in
    millimetres in every unit system (docs/cli.md), as the page's other lengths."""
    ax.set_title("entrance pupil (the nodal pivot) in front of the film", loc="left", fontsize=8)
    xs = [r.encoder for r in page.curve]
    ax.plot(xs, [r.entrance_pupil_from_film_mm for r in page.curve], color=PALETTE[2],
            label="entrance pupil")
    ax.plot(xs, [r.front_vertex_to_film_mm for r in page.curve], color="0.45", ls="--",
            label="front vertex")
    tab = [r for r in page.positions if r.tabulated]
    ax.plot([r.encoder for r in tab], [r.entrance_pupil_from_film_mm for r in tab], "o", ms=3.5,
            color=PALETTE[2])
    _mark_card(ax, page)
    _zoom_axis(ax)
    ax.set_ylabel("in front of the film (mm)")
    ax.legend(loc="best", fontsize=6)


def _draw_parfocality(ax, page):
    ax.set_title("parfocality: image-plane shift from the film", loc="left", fontsize=8)
    _curve(ax, page, "image_shift_mm", color=PALETTE[4], label="image shift (+ behind the film)")
    ax.axhline(0.0, color="0.6", lw=0.6)
    _mark_card(ax, page)
    _zoom_axis(ax)
    ax.set_ylabel("image shift (mm)")
    ax.legend(loc="best", fontsize=6)


def _draw_breathing(ax, page, units):
    from ._focus_axis import focus_axis, focus_x

    ax.set_title("focus breathing at each tabulated position", loc="left", fontsize=8)
    if not page.breathing:
        ax.set_axis_off()
        ax.text(0.5, 0.5, "no breathing table: see the notes", transform=ax.transAxes, ha="center", fontsize=7)
        return
    marks = []
    for k, (u, rows) in enumerate(page.breathing):
        ax.plot([focus_x(r.focus_from_film_mm, units) for r in rows], [r.fov_change_pct for r in rows], marker="o",
                ms=2.5, color=PALETTE[k % len(PALETTE)], label=f"EFL {rows[0].efl_mm:.1f} mm")
        marks += [r.focus_from_film_mm for r in rows]
    focus_axis(ax, [m for m in marks if math.isfinite(m)] + [math.inf], units)
    ax.xaxis.label.set_fontsize(7)
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.grid(True)
    ax.set_ylabel("horizontal FOV change (%)")
    ax.legend(loc="best", fontsize=6)


def _draw_distortion(ax, page):
    ax.set_title("distortion at each tabulated position, infinity", loc="left", fontsize=8)
    efl = {r.encoder: r.efl_mm for r in page.positions}
    curves = [(f"EFL {efl[u]:.1f} mm", [] if d is None else d.meridian("y"), "-", PALETTE[k % len(PALETTE)])
              for k, (u, d) in enumerate(page.distortion)]
    draw_distortion_curves(ax, curves, "image height (mm)")
