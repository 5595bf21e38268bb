"""The lens card's anamorphic page: the lens in its two meridians (issue 49; docs/lens-card.md,
docs/anamorphic.md).

A second page of the card of an anamorphic lens (squeeze other than 1), the same paper size. X is the
picture's horizontal (the squeezed meridian), Y its vertical. Shown, from infinity to the close focus:

* the **framing focal length** of each meridian (the pinhole at that meridian's entrance pupil that frames
  like the lens: sensor half-width over the tangent of the paraxial half-field,
  :func:`physcam.optics.focusing.breathing_table`) and their ratio, the **squeeze the framing shows**
  at each mark beside the squeeze the file states: squeeze breathing;
* both **entrance pupils** in front of the film (the pan pivot, X, and the tilt pivot, Y; they differ for
  a front anamorphic: "anamorphic mumps") and their diameters
  (:func:`physcam.optics.focusing.entrance_pupils`);
* real **distortion** of each meridian against image height at infinity and at the close focus
  (:func:`physcam.analysis.distortion.field.real_distortion`);
* **bokeh across the frame**: point lights imaged at the centre, the frame's horizontal and vertical edge
  and its corner (90 % of the half-width and half-height, within the image circle), wide open, at the
  card's focus and light distance (:func:`physcam.analysis.defocus.bokeh.bokeh_image`), drawn in the
  desqueezed picture (film x times the stated squeeze). Each blur's **aspect** is the ratio of its RMS
  widths, sqrt(var x / var y) of the irradiance on the film (the axis ratio of a uniform ellipse), and
  that times the squeeze in the desqueezed picture: below 1 the oval stands upright.

The key numbers per meridian are paraxial at infinity: EFL, entrance-pupil diameter and f-number
(EFL over that diameter, ISO 517). Distances from the film plane, lengths in mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, OpticsError, require_type
from ...figures import PALETTE
from ...lens.prescription import Prescription, takes_prescription
from ._page import checked_drawing, draw_distortion_curves, sensor_size

__all__ = ["ANAMORPHIC_PANELS", "AnamorphicPage", "anamorphic_page", "draw_anamorphic_page", "blur_aspect"]

#: The anamorphic page's panels, by the label their axes carry.
ANAMORPHIC_PANELS = ("anamorphic numbers", "squeeze breathing", "framing focal lengths", "entrance pupils",
                     "distortion per meridian", "pupil diameters", "bokeh across the frame")

#: Where the bokeh lights land, as fractions of the sensor's half-width and half-height.
BOKEH_PLACES = (("centre", 0.0, 0.0), ("horizontal edge", 0.9, 0.0), ("vertical edge", 0.0, 0.9),
                ("corner", 0.9, 0.9))


#: Fewest rays through the lens for a blur's aspect to be given (a lens whose front element is much wider than
#: its entrance pupil passes few of the rays a bokeh image aims at the front element).
MIN_RAYS_FOR_ASPECT = 500

#: The bokeh images aim their rays at the front element's disk; where a quarter of them or fewer pass the lens,
#: they are traced again with as many more as would pass a quarter, at most this many times the first count.
RAYS_CAP = 40


def blur_aspect(img) -> float | None:
    """Width over height of a blur on the film: sqrt(var x / var y) of its irradiance (None: no light)."""
    from ..defocus.bokeh import BokehImage

    require_type("img", img, BokehImage, "physcam.analysis.defocus.bokeh.bokeh_image(camera, ...)")
    e = img.image.sum(axis=2)
    tot = float(e.sum())
    if tot <= 0.0:
        return None
    x0, x1, y0, y1 = img.extent_mm
    ny, nx = e.shape
    xs = x0 + (np.arange(nx) + 0.5) * (x1 - x0) / nx
    ys = y0 + (np.arange(ny) + 0.5) * (y1 - y0) / ny
    px, py = e.sum(axis=0) / tot, e.sum(axis=1) / tot
    vx = float((px * (xs - (px * xs).sum()) ** 2).sum())
    vy = float((py * (ys - (py * ys).sum()) ** 2).sum())
    return math.sqrt(vx / vy) if vy > 0.0 else None


@dataclass
class AnamorphicPage:
    """What the anamorphic page shows (module notes)."""

    lens_name: str
    stated_squeeze: float
    meridians: dict  # key numbers per meridian at infinity: {"x": {...}, "y": {...}}
    breathing: list  # BreathingRow from infinity to the close focus (both meridians)
    pupils: list  # EntrancePupils at the same marks
    distortion: list  # (mark mm, DistortionResult or None): infinity and the close focus
    bokeh: list  # (label, (x mm, y mm) on the film aimed at, BokehImage or None)
    light_from_film_mm: float  # where the bokeh lights stand, in front of the film
    notes: list[str] = field(default_factory=list)

    def bokeh_rows(self) -> list[dict]:
        out = []
        for lab, (hx, hy), img in self.bokeh:
            a = None if img is None or img.rays_passed < MIN_RAYS_FOR_ASPECT else blur_aspect(img)
            out.append({"label": lab, "aimed_at_film_mm": [hx, hy], "light_from_film_mm": self.light_from_film_mm,
                        "aspect_on_film": a,
                        "aspect_desqueezed": None if a is None else a * self.stated_squeeze,
                        **({} if img is None else img.to_dict())})
        return out

    def to_dict(self) -> dict:
        return {"lens": self.lens_name, "panels": list(ANAMORPHIC_PANELS), "stated_squeeze": self.stated_squeeze,
                "reference": "X = the picture's horizontal (squeezed) meridian, Y its vertical; distances in mm "
                             "in front of the film plane",
                "meridians": self.meridians, "breathing": [r.to_dict() for r in self.breathing],
                "entrance_pupils": [p.to_dict() for p in self.pupils],
                "distortion": [{"focus_from_film_mm": None if math.isinf(m) else m,
                                "field": None if d is None else d.to_dict()} for m, d in self.distortion],
                "bokeh_aspect_definition": "sqrt(var x / var y) of the blur's irradiance on the film; desqueezed: "
                                           "times the stated squeeze",
                "bokeh": self.bokeh_rows(), "notes": list(self.notes)}


def _meridians(lens) -> dict:
    """Each meridian's key numbers at infinity; the pupils from the one film plane, where the lens focuses Y
    (:func:`physcam.optics.focusing.entrance_pupils`, as the report and the page's pupil panel give them: each
    meridian's own paraxial focus put the X pupil 0.1 mm farther on Neil's front 2x, 170.7 against 170.6 mm)."""
    from ...optics.focusing import entrance_pupils
    from ...optics.paraxial import gaussian_xy

    out, ep = {}, entrance_pupils(lens, math.inf)
    pupil = {"x": ep.horizontal_from_film_mm, "y": ep.vertical_from_film_mm}
    for a, g in gaussian_xy(lens).items():
        out[a] = {"efl_mm": g.efl, "entrance_pupil_diameter_mm": g.entrance_pupil_diameter,
                  "f_number": g.efl / g.entrance_pupil_diameter, "entrance_pupil_from_film_mm": pupil[a]}
    out["efl_ratio_y_over_x"] = out["y"]["efl_mm"] / out["x"]["efl_mm"]
    return out


@takes_prescription
def anamorphic_page(lens: Prescription, camera, breathing: list, sensor_mm: tuple[float, float], image_circle_mm: float, *,
                    curve_fields: int = 6, rays: int = 20_000, pixels: int = 48, backend: str = "auto") -> AnamorphicPage:
    """The anamorphic page of ``lens`` (module notes): ``camera`` its state at the card's focus,
    ``breathing`` the card's breathing rows (infinity to the close focus)."""
    from ...optics.focusing import BreathingRow, entrance_pupils
    from ...optics.state import CameraState
    from ..distortion.field import real_distortion

    require_type("camera", camera, CameraState, "physcam.optics.state.camera_state(lens, focus_mm=...)")
    if not (isinstance(breathing, list) and all(isinstance(r, BreathingRow) for r in breathing)):
        raise InputError("breathing must be a list of BreathingRow (physcam.optics.focusing.breathing_table)")
    w, h = sensor_size(sensor_mm)
    notes: list[str] = []
    pupils = [entrance_pupils(lens, r.focus_from_film_mm) for r in breathing]
    marks = [math.inf] + ([breathing[-1].focus_from_film_mm] if breathing else [])
    distortion = []
    for m in marks:
        try:
            d = real_distortion(lens, n_fields=curve_fields, sensor_width_mm=w, sensor_height_mm=h, focus_mm=m,
                                backend=backend)
        except OpticsError as exc:
            d = None
            notes.append(f"distortion per meridian at {m:g} mm: {exc}")
        distortion.append((m, d))
    depth, bokeh = _bokeh(lens, camera, (w, h), image_circle_mm, rays, pixels, backend, notes)
    return AnamorphicPage(lens.name, float(lens.squeeze), _meridians(lens), list(breathing), pupils, distortion,
                          bokeh, depth, notes)


def _bokeh(lens, camera, sensor_mm, circle_mm, rays, pixels, backend, notes):
    """Lights aimed (paraxially, per meridian) at :data:`BOKEH_PLACES` on the film, at the card's light distance
    (:func:`physcam.analysis.lens_cards._lights.light_distance_mm`, with the Y focal length)."""
    from ...optics.focusing import entrance_pupils
    from ...optics.paraxial import gaussian_xy
    from ..defocus.bokeh import bokeh_image
    from ._lights import light_distance_mm

    g = gaussian_xy(lens)
    focus = camera.focus_from_film_mm
    depth = light_distance_mm(camera, g["y"].efl)
    ep = entrance_pupils(lens, focus)
    w, h = sensor_mm
    shrink = min(1.0, 0.9 * 0.5 * circle_mm / max(1e-9, 0.9 * 0.5 * math.hypot(w, h)))  # inside the image circle
    out = []
    for lab, fx, fy in BOKEH_PLACES:
        hx, hy = shrink * fx * 0.5 * w, shrink * fy * 0.5 * h
        x = -hx / g["x"].efl * max(depth - ep.horizontal_from_film_mm, g["x"].efl)
        y = -hy / g["y"].efl * max(depth - ep.vertical_from_film_mm, g["y"].efl)
        try:
            img = bokeh_image(camera, depth, x, y, rays=rays, pixels=pixels, backend=backend)
            if img.rays_passed < rays // 4:  # few rays get through: trace more, up to RAYS_CAP times as many
                more = min(RAYS_CAP * rays, round(rays * (rays // 4) / max(img.rays_passed, 1)))
                img = bokeh_image(camera, depth, x, y, rays=more, pixels=pixels, extent_mm=img.extent_mm,
                                  backend=backend)
        except (OpticsError, InputError) as exc:
            notes.append(f"bokeh {lab}: {exc}")
            img = None
        out.append((lab, (hx, hy), img))
    return depth, out


# ---- drawing --------------------------------------------------------------------------------------
def draw_anamorphic_page(fig, page: AnamorphicPage, units: str) -> None:
    """Draw ``page`` on ``fig`` (a card-sized Figure) below its title, one axes per :data:`ANAMORPHIC_PANELS`."""
    checked_drawing(fig, page, AnamorphicPage, units)
    gs = fig.add_gridspec(3, 2, left=0.09, right=0.9, top=0.925, bottom=0.32, hspace=0.5, wspace=0.42)
    _draw_numbers(fig.add_subplot(gs[0, 0], label="anamorphic numbers"), page, units)
    _draw_squeeze(fig.add_subplot(gs[0, 1], label="squeeze breathing"), page, units)
    _draw_pair(fig.add_subplot(gs[1, 0], label="framing focal lengths"), page, units,
               "framing focal length per meridian", "framing focal length (mm)",
               [r.breathing_focal_length_mm for r in page.breathing],
               [r.vertical_breathing_focal_length_mm for r in page.breathing])
    _draw_pair(fig.add_subplot(gs[1, 1], label="entrance pupils"), page, units,
               "entrance pupils: X the pan pivot, Y the tilt pivot", "in front of the film (mm)",
               [p.horizontal_from_film_mm for p in page.pupils], [p.vertical_from_film_mm for p in page.pupils])
    _draw_distortion(fig.add_subplot(gs[2, 0], label="distortion per meridian"), page, units)
    _draw_pair(fig.add_subplot(gs[2, 1], label="pupil diameters"), page, units,
               "entrance-pupil diameter per meridian", "entrance pupil Ø (mm)",
               [p.horizontal_diameter_mm for p in page.pupils], [p.vertical_diameter_mm for p in page.pupils])
    _draw_bokeh(fig, fig.add_gridspec(1, len(page.bokeh), left=0.09, right=0.9, top=0.215, bottom=0.06, wspace=0.4),
                page)


def _draw_numbers(ax, page, units):
    from ...units import format_distance
    from ._page import millimetres

    ax.set_axis_off()
    ax.set_title("per meridian (paraxial, infinity)", loc="left", fontsize=8)
    mx, my = page.meridians["x"], page.meridians["y"]
    near = page.breathing[-1] if page.breathing else None
    rows = [("", "X (horizontal)", "Y (vertical)"),
            ("EFL", f"{mx['efl_mm']:.2f} mm", f"{my['efl_mm']:.2f} mm"),
            ("entrance pupil Ø", f"{mx['entrance_pupil_diameter_mm']:.2f} mm", f"{my['entrance_pupil_diameter_mm']:.2f} mm"),
            ("f-number", f"f/{mx['f_number']:.2f}", f"f/{my['f_number']:.2f}"),
            ("pupil in front of film", millimetres(mx["entrance_pupil_from_film_mm"]),
             millimetres(my["entrance_pupil_from_film_mm"])),  # inside the camera: mm in every unit system
            ("squeeze: stated", f"{page.stated_squeeze:g}x", ""),
            ("  EFL Y / X", f"{page.meridians['efl_ratio_y_over_x']:.3f}x", "")]
    if page.breathing:
        rows.append(("  framing, infinity", f"{page.breathing[0].breathing_squeeze:.3f}x", ""))
        rows.append((f"  framing, {format_distance(near.focus_from_film_mm, units)}", f"{near.breathing_squeeze:.3f}x",
                     ""))
    centre = next((b for b in page.bokeh_rows() if b["label"] == "centre"), None)
    if centre and centre["aspect_desqueezed"] is not None:
        rows.append(("bokeh aspect, centre", f"{centre['aspect_on_film']:.2f} film",
                     f"{centre['aspect_desqueezed']:.2f} desq."))
    for i, (k, a, b) in enumerate(rows):
        y = 1.0 - i * 0.1
        bold = "bold" if i else "normal"
        ax.text(0.0, y, k, transform=ax.transAxes, fontsize=7, va="top")
        ax.text(0.72, y, a, transform=ax.transAxes, fontsize=7, va="top", ha="right", fontweight=bold)
        ax.text(1.02, y, b, transform=ax.transAxes, fontsize=7, va="top", ha="right", fontweight=bold)


def _marks(page):
    return [r.focus_from_film_mm for r in page.breathing]


def _draw_squeeze(ax, page, units):
    from ._focus_axis import focus_axis, focus_x

    ax.set_title("squeeze breathing: the framing's squeeze", loc="left", fontsize=8)
    xs = [focus_x(m, units) for m in _marks(page)]
    ax.plot(xs, [r.breathing_squeeze for r in page.breathing], "o-", ms=3, color=PALETTE[0],
            label="framing focal length Y / X")
    ax.axhline(page.stated_squeeze, color=PALETTE[1], ls="--", lw=1.0, label=f"stated {page.stated_squeeze:g}x")
    focus_axis(ax, _marks(page), units)
    ax.xaxis.label.set_fontsize(7)
    ax.grid(True)
    ax.set_ylabel("squeeze (ratio)")
    ax.legend(loc="best", fontsize=6)


def _draw_pair(ax, page, units, title, ylabel, xvals, yvals):
    from ._focus_axis import focus_axis, focus_x

    ax.set_title(title, loc="left", fontsize=8)
    xs = [focus_x(m, units) for m in _marks(page)]
    ax.plot(xs, xvals, "o-", ms=3, color=PALETTE[0], label="X (horizontal)")
    ax.plot(xs, yvals, "s--", ms=3, color=PALETTE[1], label="Y (vertical)")
    focus_axis(ax, _marks(page), units)
    ax.xaxis.label.set_fontsize(7)
    ax.grid(True)
    ax.set_ylabel(ylabel, fontsize=7)
    ax.legend(loc="best", fontsize=6)


def _draw_distortion(ax, page, units):
    from ...units import format_distance

    ax.set_title("distortion per meridian (− barrel)", loc="left", fontsize=8)
    curves = []
    for k, (m, d) in enumerate(page.distortion):
        at = "∞" if math.isinf(m) else format_distance(m, units)
        for axis, style in (("x", "-"), ("y", "--")):
            curves.append((f"{axis.upper()}, {at}", [] if d is None else d.meridian(axis), style, PALETTE[k]))
    draw_distortion_curves(ax, curves, "image height on the film (mm)", ncol=2)


def _draw_bokeh(fig, sub, page):
    """The blurs side by side in the desqueezed picture, each centred on its light, all at one scale."""
    from matplotlib.ticker import MaxNLocator

    fig.text(0.09, 0.255, "bokeh across the frame, wide open, in the desqueezed picture (film x times the stated "
             "squeeze), one scale", fontsize=8, ha="left", va="bottom")
    sq, rows = page.stated_squeeze, page.bokeh_rows()
    windows = [_window(img, sq) for _, _, img in page.bokeh]
    half = 1.15 * max([max(wx, wy) for _, _, wx, wy in filter(None, windows)] or [1.0])
    for k, ((lab, (hx, hy), img), row, win) in enumerate(zip(page.bokeh, rows, windows)):
        ax = fig.add_subplot(sub[0, k], label="bokeh across the frame" if k == 0 else f"bokeh across the frame {k}")
        ax.set_title(f"{lab}\n({hx:.1f}, {hy:.1f}) mm on film", loc="left", fontsize=6.5)
        if win is None:
            ax.set_xticks([])
            ax.set_yticks([])
            ax.text(0.5, 0.5, "no light\nreaches the film", transform=ax.transAxes, ha="center", fontsize=6)
            continue
        x0, x1, y0, y1 = img.extent_mm
        a = img.image.sum(axis=2)
        a = a / max(float(a.max()), 1e-300)
        ax.imshow(np.sqrt(a), origin="lower", extent=(x0 * sq, x1 * sq, y0, y1), cmap="gray", interpolation="bilinear")
        cx, cy = win[0], win[1]
        ax.set_xlim(cx - half, cx + half)
        ax.set_ylim(cy - half, cy + half)
        ax.set_facecolor("black")
        ax.xaxis.set_major_locator(MaxNLocator(3))
        ax.yaxis.set_major_locator(MaxNLocator(3))
        ax.tick_params(labelsize=5.5)
        asp = row["aspect_desqueezed"]
        ax.set_xlabel("x desqueezed (mm)\n" + (f"aspect {asp:.2f} (w / h)" if asp is not None else
                                                f"{img.rays_passed} rays: too few for an aspect"), fontsize=6)
        ax.set_ylabel("y (mm)", fontsize=6, labelpad=1)


def _window(img, squeeze):
    """(centre x desqueezed, centre y, half-width desqueezed, half-height) of the lit pixels (mm), or None."""
    if img is None:
        return None
    a = img.image.sum(axis=2)
    lit = a > 0.02 * float(a.max()) if a.max() > 0 else None
    if lit is None or not lit.any():
        return None
    x0, x1, y0, y1 = img.extent_mm
    ny, nx = a.shape
    cols, rows = np.flatnonzero(lit.any(axis=0)), np.flatnonzero(lit.any(axis=1))
    px, py = (x1 - x0) / nx, (y1 - y0) / ny
    xa, xb = x0 + cols[0] * px, x0 + (cols[-1] + 1) * px
    ya, yb = y0 + rows[0] * py, y0 + (rows[-1] + 1) * py
    return 0.5 * (xa + xb) * squeeze, 0.5 * (ya + yb), 0.5 * (xb - xa) * squeeze, 0.5 * (yb - ya)
