"""The lens card: one printed page per lens, like a lens maker's data sheet.

One A4 or US Letter page (portrait) with the lens section and its rays
(:mod:`physcam.analysis.lens_cards.diagram`), the vendor MTF chart at 10, 20 and 40 lp/mm, sagittal and
tangential, at full aperture and stopped down (:func:`physcam.analysis.image_quality.mtf.mtf_chart`), real
distortion and relative illumination against image height (:mod:`~physcam.analysis.distortion.field`,
:mod:`~physcam.analysis.image_quality.illumination`), focus breathing against the focus mark
(:func:`physcam.optics.focusing.breathing_table`), bokeh of point lights at the centre, middle and
corner of the sensor at full aperture (:func:`physcam.analysis.defocus.bokeh.bokeh_image`: the corner's
cat's eye is the mechanical vignetting), and the key numbers (EFL, f-number, entrance pupil, close
focus, image circle). Every number is computed by those functions as they are; this module only
chooses their inputs and draws. Image heights and film sizes in mm; scene distances from the film
plane (docs/conventions.md).

A zoom lens's card has a second page, across its zoom range (:mod:`.zoom_page`), and its first page
shows one zoom position; an anamorphic lens's card has a page of its two meridians
(:mod:`.anamorphic_page`). A PDF holds every page; a PNG or SVG holds one, so the further pages go to
files beside it named ``<name>-zoom`` and ``<name>-anamorphic`` (:func:`card_files`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ...errors import InputError, OpticsError
from ...lens.prescription import Prescription, takes_prescription
from ...figures import PALETTE, TITLE_Y, styled

__all__ = ["PAGES", "PANELS", "LensCard", "lens_card", "save_lens_card", "card_pages", "card_files"]

#: Page sizes (width, height) in inches, portrait: ISO A4 (210 x 297 mm) and US Letter (8.5 x 11 in).
PAGES = {"a4": (210.0 / 25.4, 297.0 / 25.4), "letter": (8.5, 11.0)}

#: The panels of a card, by the label their axes carry (``Axes.get_label()``).
PANELS = ("diagram", "key numbers", "mtf open", "mtf stopped", "distortion", "illumination", "breathing",
          "bokeh centre", "bokeh mid", "bokeh corner")

#: Work per card: fields of the MTF chart and of distortion / illumination, the MTF pupil-grid cap,
#: rays and pixels of each bokeh image, and the illumination grid.
_QUALITY = {"full": dict(mtf_fields=8, curve_fields=12, pupil_cap=256, rays=120_000, pixels=112, grid=96),
            "draft": dict(mtf_fields=4, curve_fields=6, pupil_cap=96, rays=20_000, pixels=48, grid=32)}


def _title_that_fits(text: str, width_in: float) -> tuple[str, float]:
    """The page title and its size: the largest of 11, 10, 9 and 8 pt at which ``text``, bold, fits on one line
    ``width_in`` inches wide (a long lens name, such as a zoom's with its source), else wrapped at 8 pt."""
    from ...figures import fit_title

    for size in (11.0, 10.0, 9.0, 8.0):
        lines = fit_title(text, width_in, fontsize=size, weight="bold")
        if "\n" not in lines:
            return lines, size
    return lines, 8.0


@dataclass
class LensCard:
    """What a lens card shows, computed once; :meth:`figure` draws the page."""

    lens_name: str
    focus_from_film_mm: float
    sensor_name: str
    sensor_mm: tuple[float, float]
    key: dict
    diagram: object
    mtf: list  # (label, MTFChart or None, note)
    distortion: object
    illumination: object
    breathing: list
    bokeh: list  # (label, image height mm, BokehImage)
    page: str = "a4"
    notes: list[str] = field(default_factory=list)
    zoom_page: object = None  # ZoomPage of a zoom lens (.zoom_page), else None
    anamorphic_page: object = None  # AnamorphicPage of an anamorphic lens (.anamorphic_page), else None

    @property
    def pages(self) -> list[str]:
        """The card's pages in order: "main", then "zoom" and "anamorphic" where the lens has them."""
        return ["main"] + [n for n, pg in (("zoom", self.zoom_page), ("anamorphic", self.anamorphic_page))
                           if pg is not None]

    def to_dict(self) -> dict:
        """The card's numbers (what ``physcam lens card --json`` prints besides the file)."""
        return {"lens": self.lens_name, "page": self.page, "page_inches": list(PAGES[self.page]),
                "focus_from_film_mm": None if math.isinf(self.focus_from_film_mm) else self.focus_from_film_mm,
                "sensor": {"name": self.sensor_name, "width_mm": self.sensor_mm[0], "height_mm": self.sensor_mm[1]},
                "key": self.key, "panels": list(PANELS),
                "mtf": [{"label": lab, "fstop": None if c is None else c.fstop, "note": note,
                         "chart": None if c is None else c.to_dict()} for lab, c, note in self.mtf],
                "diagram": self.diagram.to_dict(),
                "distortion": None if self.distortion is None else self.distortion.to_dict(),
                "illumination": None if self.illumination is None else self.illumination.to_dict(),
                "breathing": [r.to_dict() for r in self.breathing],
                "bokeh": [{"label": lab, "image_height_mm": h, **({} if b is None else b.to_dict())}
                          for lab, h, b in self.bokeh],
                "notes": list(self.notes), "pages": self.pages,
                "zoom_page": None if self.zoom_page is None else self.zoom_page.to_dict(),
                "anamorphic_page": None if self.anamorphic_page is None else self.anamorphic_page.to_dict()}

    @styled
    def figures(self, *, units: str = "m", dpi: int | None = None) -> list:
        """Every page as a matplotlib Figure, in the order of :attr:`pages`."""
        return [self.figure(units=units, dpi=dpi) if name == "main" else self.extra_page(name, units=units, dpi=dpi)
                for name in self.pages]

    @styled
    def extra_page(self, name: str, *, units: str = "m", dpi: int | None = None):
        """The "zoom" or "anamorphic" page as a Figure the size of the card's first page."""
        from ...figures import new_figure
        from .anamorphic_page import draw_anamorphic_page
        from .zoom_page import draw_zoom_page

        if name not in self.pages[1:]:
            raise InputError(f"the card of {self.lens_name!r} has no {name!r} page; its pages: {', '.join(self.pages)}")
        w, h = PAGES[self.page]
        fig = new_figure(figsize=(w, h), dpi=dpi)
        pg = self.zoom_page if name == "zoom" else self.anamorphic_page
        what = "across the zoom" if name == "zoom" else "anamorphic, in its two meridians"
        title, size = _title_that_fits(f"{pg.lens_name}: {what}", 0.94 * w)
        fig.suptitle(title, fontsize=size, fontweight="bold", y=0.985)
        fig.text(0.5, 0.955, self._page_subtitle(name, units), ha="center", va="center", fontsize=7.5, color="0.25")
        (draw_zoom_page if name == "zoom" else draw_anamorphic_page)(fig, pg, units)
        if pg.notes:
            fig.text(0.5, 0.012, _wrap("; ".join(pg.notes), 150), ha="center", va="bottom", fontsize=6, color="0.35")
        return fig

    @styled
    def figure(self, *, units: str = "m", dpi: int | None = None):
        """The page as a matplotlib Figure (Agg canvas), one axes per :data:`PANELS` entry."""
        from ...figures import new_figure

        w, h = PAGES[self.page]
        fig = new_figure(figsize=(w, h), dpi=dpi)
        gs = fig.add_gridspec(5, 6, left=0.08, right=0.9, top=0.93, bottom=0.075, hspace=0.75, wspace=1.6,
                              height_ratios=(1.25, 1.0, 1.0, 1.0, 0.8))
        title, size = _title_that_fits(self._title(), 0.94 * w)
        fig.suptitle(title, fontsize=size, fontweight="bold", y=0.985)
        fig.text(0.5, 0.955, self._subtitle(units), ha="center", va="center", fontsize=7.5, color="0.25")
        _draw_diagram(fig.add_subplot(gs[0, :4], label="diagram"), self, units)
        _draw_key(fig.add_subplot(gs[0, 4:], label="key numbers"), self.key, units)
        for k, (lab, chart, note) in enumerate(self.mtf):
            _draw_mtf(fig.add_subplot(gs[1, 3 * k:3 * k + 3], label=("mtf open", "mtf stopped")[k]), chart, lab, note)
        _draw_distortion(fig.add_subplot(gs[2, :3], label="distortion"), self.distortion)
        _draw_illumination(fig.add_subplot(gs[2, 3:], label="illumination"), self.illumination)
        _draw_breathing(fig.add_subplot(gs[3, :], label="breathing"), self, units)
        for k, (lab, hgt, img) in enumerate(self.bokeh):
            _draw_bokeh(fig.add_subplot(gs[4, 2 * k:2 * k + 2], label=f"bokeh {lab}"), img, lab, hgt)
        src = self.key.get("source") or "not stated"
        lic = self.key.get("licence") or "not stated"
        foot = (f"physcam lens card · prescription: {src} (licence: {lic}) · "
                + ("; ".join(self.notes) if self.notes else "all numbers from the prescription"))
        fig.text(0.5, 0.012, _wrap(foot, 150), ha="center", va="bottom", fontsize=6, color="0.35")
        return fig

    def _page_subtitle(self, name: str, units: str) -> str:
        from ...units import format_distance

        w, h = self.sensor_mm
        sensor = f"sensor {self.sensor_name} ({w:.2f} x {h:.2f} mm)"
        if name == "zoom":
            return _wrap(f"infinity focus and the stop full open unless stated · {sensor} · dotted line: the zoom "
                         f"position of page 1 (EFL {self.key['efl_mm']:.1f} mm, zoom {self.zoom_page.encoder:.4g})", 140)
        foc = "infinity" if math.isinf(self.focus_from_film_mm) else format_distance(self.focus_from_film_mm, units)
        return _wrap(f"X = the picture's horizontal (squeezed) meridian, Y its vertical · {sensor} · bokeh focused "
                     f"at {foc} from the film plane", 140)

    def _title(self) -> str:
        return f"{self.lens_name}"

    def _subtitle(self, units: str) -> str:
        from ...units import format_distance

        foc = "infinity" if math.isinf(self.focus_from_film_mm) else format_distance(self.focus_from_film_mm, units)
        w, h = self.sensor_mm
        page = "A4" if self.page == "a4" else "US Letter"
        return _wrap(f"focused at {foc} from the film plane · sensor {self.sensor_name} ({w:.2f} x {h:.2f} mm) · "
                     f"{page} page", 140)


def _wrap(text: str, n: int) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, n)) or text


# ---- computing ------------------------------------------------------------------------------------
@takes_prescription
def lens_card(lens: Prescription, *, focus_mm: float = math.inf, sensor_width_mm: float | None = None,
              sensor_height_mm: float | None = None, sensor_name: str | None = None, stopped_fstop: float = 8.0,
              page: str = "a4", quality: str = "full", backend: str = "auto", sensor=None, zoom=None) -> LensCard:
    """Compute the card of ``lens`` focused ``focus_mm`` from the film plane (default infinity; a string with
    units such as "2m" or "10ft" too) on a ``sensor_width_mm`` x ``sensor_height_mm`` sensor, or ``sensor``
    (a name such as "ALEXA 35", or a :class:`~physcam.optics.sensors.Sensor`; default Super 35). The MTF chart
    is drawn wide open and at ``stopped_fstop`` (default f/8; skipped when not slower than wide open).
    ``page``: "a4" or "letter"; ``quality``: "full" or "draft" (fewer fields and rays: tests).
    A zoom lens's first page shows it at ``zoom`` (an encoder value 0..1 or a focal length such as "135mm";
    default its first tabulated position), named with that position, and its zoom page the whole range;
    a prime given ``zoom`` is refused."""
    from ...data.default_sensor import DEFAULT_SENSOR, DEFAULT_SENSOR_HEIGHT_MM, DEFAULT_SENSOR_WIDTH_MM
    from ...errors import require_positive
    from ...units import parse_distance

    if sensor is not None:
        from ...optics.sensors import Sensor, find_sensor

        if sensor_width_mm is not None or sensor_height_mm is not None:
            raise InputError("give the sensor either by name (sensor=) or by size (sensor_width_mm=, "
                             "sensor_height_mm=), not both")
        s = sensor if isinstance(sensor, Sensor) else find_sensor(sensor)
        sensor_width_mm, sensor_height_mm, sensor_name = s.width_mm, s.height_mm, sensor_name or s.name

    if page not in PAGES:
        raise InputError(f"page must be one of {', '.join(PAGES)}, got {page!r}")
    if quality not in _QUALITY:
        raise InputError(f"quality must be one of {', '.join(_QUALITY)}, got {quality!r}")
    q = _QUALITY[quality]
    w = require_positive("sensor width", DEFAULT_SENSOR_WIDTH_MM if sensor_width_mm is None else sensor_width_mm)
    h = require_positive("sensor height", DEFAULT_SENSOR_HEIGHT_MM if sensor_height_mm is None else sensor_height_mm)
    name = sensor_name or (DEFAULT_SENSOR if sensor_width_mm is None else f"{w:g} x {h:g} mm")
    focus_mm = parse_distance(focus_mm, name="focus distance", allow_inf=True)
    notes: list[str] = []
    zoom_lens, encoder = _zoom_position(lens, zoom)
    if zoom_lens is not None:
        lens = _named_at(zoom_lens, encoder)
    from ...optics.state import camera_state

    camera = camera_state(lens, focus_mm=focus_mm, sensor_mm=(w, h))  # the lens at the mark, as its file stops it
    diagram = _diagram(camera)
    key = key_numbers(lens, focus_mm, 0.5 * math.hypot(w, h), backend=backend)
    dist = _distortion(lens, focus_mm, w, h, q, backend, notes)
    ill = _illumination(camera, q, backend, notes)
    wide = key["f_number"]
    stops = [("full aperture", None)] + ([("stopped down", stopped_fstop)] if stopped_fstop > wide * 1.05
                                         else [])
    mtf = [_mtf(camera, lab, n, min(0.5 * math.hypot(w, h), key["image_circle_mm"] / 2), q, backend)
           for lab, n in stops]
    if len(mtf) == 1:
        mtf.append(("stopped down", None, f"the lens is f/{wide:.2g} wide open: no stopped-down chart"))
    rows = _breathing(lens, w, notes)
    bokeh = _bokeh(camera, key, w, h, q, backend, notes)
    zpage = None
    if zoom_lens is not None:
        from .zoom_page import zoom_page

        zpage = zoom_page(zoom_lens, encoder, (w, h), curve_fields=q["curve_fields"], backend=backend)
    apage = None
    if lens.squeeze != 1.0:
        from .anamorphic_page import anamorphic_page

        apage = anamorphic_page(lens, camera, rows, (w, h), key["image_circle_mm"], curve_fields=q["curve_fields"],
                                rays=q["rays"] // 2, pixels=q["pixels"], backend=backend)
    return LensCard(lens.name, focus_mm, name, (w, h), key, diagram, mtf, dist, ill, rows, bokeh, page, notes,
                    zpage, apage)


def _zoom_position(lens: Prescription, zoom):
    """(the zoom lens, the encoder value of ``zoom``) for a zoom lens (default its first position);
    (None, None) for a prime, which refuses a ``zoom``."""
    if lens.zoom is None:
        if zoom is not None:
            raise InputError(f"lens {lens.name!r} is not a zoom lens (its file has no zoom table): give no zoom "
                             "position")
        return None, None
    from ...optics.zoom import zoom_encoder

    return lens, zoom_encoder(lens, 0.0 if zoom is None else zoom)


def _named_at(zoom_lens: Prescription, encoder: float) -> Prescription:
    """The zoom lens at ``encoder`` (a plain prescription), named with its position as the CLI's --zoom
    names it: "<lens> at <EFL> mm (zoom <encoder>)"."""
    from dataclasses import replace

    from ...lens.zoom import prescription_at
    from ...optics.paraxial import gaussian

    q = prescription_at(zoom_lens, encoder)
    name = f"{zoom_lens.name} at {gaussian(q).efl:.1f} mm (zoom {encoder:.4g})"
    return replace(q, metadata=replace(q.metadata, name=name))


def _breathing(lens, w, notes):
    """The breathing table from infinity to the close focus; for a lens longer than its close marks (a subject
    there would sit inside the glass), from infinity to the last default mark 1.5 lens lengths away, said
    so in ``notes``."""
    from ...optics import focusing

    try:
        return focusing.breathing_table(lens, sensor_width_mm=w)
    except OpticsError as exc:
        length = lens.total_track + lens.surfaces[-1].thickness
        marks = [m for m in focusing.DEFAULT_BREATHING_MARKS if m > 1.5 * length]
        try:
            rows = focusing.breathing_table(lens, marks, sensor_width_mm=w)
        except OpticsError:
            notes.append(f"breathing: {exc}")
            return []
        notes.append(f"breathing down to {marks[-1] / 1000:g} m only ({str(exc).split(';')[0]})")
        return rows


def key_numbers(lens: Prescription, focus_mm: float, half_diagonal_mm: float, *, backend: str = "auto") -> dict:
    """EFL, wide-open f-number (paraxial, infinity), T-stop when the file gives one, the entrance pupil
    (diameter, and place in front of the film at ``focus_mm``), close focus (from the film plane),
    the image circle (twice the film height of the widest chief ray that passes the lens; mm) and
    whether it covers a sensor of ``half_diagonal_mm``."""
    from ...optics import focusing, paraxial
    from .._chief import field_limit_deg
    from ..distortion.field import _chief_heights

    g = paraxial.gaussian(lens)
    ga = focusing.gaussian_at_focus(lens, focus_mm)
    try:
        close = focusing.close_focus(lens)
    except OpticsError:
        close = None
    limit = field_limit_deg(lens, "y", max_deg=89.0, wavelength_nm=lens.wavelength_nm, backend=backend)
    import numpy as np

    heights, ok = _chief_heights(lens, np.array([0.0, 0.995 * limit]), "y", lens.wavelength_nm, None, backend)
    circle = 2.0 * abs(float(heights[-1])) if ok[-1] else 2.0 * abs(g.efl) * math.tan(math.radians(limit))
    m = lens.metadata
    return {"efl_mm": g.efl, "f_number": g.f_number, "nominal_focal_length_mm": m.focal_length,
            "max_fstop": m.max_fstop, "tstop": m.t_stop,
            "entrance_pupil_diameter_mm": g.entrance_pupil_diameter,
            "entrance_pupil_from_film_mm": ga.in_front_of("entrance_pupil"),
            "close_focus_from_film_mm": None if close is None else close.mark_mm,
            "close_focus_source": None if close is None else close.source,
            "close_focus_words": None if close is None else close.words,
            "minimum_object_distance_mm": m.minimum_object_distance,  # the maker's MOD, from the film
            "image_circle_mm": circle, "field_limit_deg": limit,
            "covers_sensor": circle >= 2.0 * half_diagonal_mm, "total_track_mm": lens.total_track,
            "squeeze": lens.squeeze, "maker": m.maker, "source": m.source, "licence": m.licence}


def _diagram(camera):
    from ...optics.state import camera_state
    from .diagram import lens_diagram

    try:
        return lens_diagram(camera, rays=5)
    except OpticsError:
        return lens_diagram(camera_state(camera.lens), rays=5)


def _distortion(lens, focus_mm, w, h, q, backend, notes):
    """The lens focused at the mark, measured as ``distortion --focus`` and the ST-maps measure it."""
    from ..distortion.field import real_distortion

    try:
        return real_distortion(lens, n_fields=q["curve_fields"], sensor_width_mm=w, sensor_height_mm=h,
                               focus_mm=focus_mm, backend=backend)
    except OpticsError as exc:
        notes.append(f"distortion: {exc}")
        return None


def _illumination(camera, q, backend, notes):
    from ..image_quality.illumination import relative_illumination

    try:
        return relative_illumination(camera, n_fields=q["curve_fields"], grid=q["grid"], backend=backend)
    except OpticsError as exc:
        notes.append(f"relative illumination: {exc}")
        return None


def _mtf(camera, label, fstop, top_mm, q, backend):
    """(label, chart or None, note): the diffraction chart of ``camera`` at ``fstop``, or why there is none."""
    from ..image_quality.mtf import mtf_chart

    try:
        at = camera if fstop is None else camera.with_fstop(fstop)
        chart = mtf_chart(at, max_image_height_mm=max(top_mm, 0.5), n_fields=q["mtf_fields"],
                          max_pupil_samples=q["pupil_cap"], backend=backend)
    except OpticsError as exc:
        return (label, None, str(exc).split(";")[0])
    return (label, chart, "")


def _bokeh(camera, key, w, h, q, backend, notes):
    """Point lights in front of the focus (half the focus distance; 15 focal lengths when focused at
    infinity) imaged at the centre, half the half-diagonal and 90 % of it (or of the image circle), wide open."""
    from ..defocus.bokeh import bokeh_image
    from ._lights import light_distance_mm

    efl = key["efl_mm"]
    depth = light_distance_mm(camera, efl)
    pupil = key["entrance_pupil_from_film_mm"]
    corner = 0.9 * min(0.5 * math.hypot(w, h), 0.5 * key["image_circle_mm"])
    out = []
    for lab, hgt in (("centre", 0.0), ("mid", 0.5 * corner / 0.9), ("corner", corner)):
        # the light's lateral place whose chief ray lands near image height hgt (paraxial angle)
        x = -math.tan(math.atan(hgt / efl)) * max(depth - pupil, efl)
        try:
            img = bokeh_image(camera, depth, x, 0.0, rays=q["rays"], pixels=q["pixels"], backend=backend)
        except (OpticsError, InputError) as exc:
            notes.append(f"bokeh {lab}: {exc}")
            img = None
        out.append((lab, hgt, img))
    return out


# ---- drawing --------------------------------------------------------------------------------------
# Every panel's title is given at figures.TITLE_Y, where matplotlib's automatic placement puts it: no card panel's
# y axis ever shows an offset or a power of ten (a fraction from 0 to 1, an image without y ticks, no axis, the
# lens section's heights in mm about the axis) nor x ticks on top (``Axes._update_title_position`` moves a title
# only above such text), so no draw measures the panel's ticks once more to find that out (docs/performance.md,
# "Round 16"; figures.title_y asks the same of a panel that may have them).


def _draw_diagram(ax, card, units):
    """The lens section in its grid cell, its title set from the cell's left edge at the largest size that
    fits the cell's width on one line: the equal-aspect box of a short (or a very long) lens is narrower
    than the cell and centred in it, and a title set from the box's left ran into the key numbers."""
    from ...figures import STYLE, fit_title

    card.diagram.draw(ax, units=units, width_in=5.0, title=False)
    ax.apply_aspect()  # the box the equal aspect leaves, inside the cell
    box, cell = ax.get_position(), ax.get_position(original=True)
    cell_in = cell.width * ax.figure.get_figwidth()
    text = "lens section, rays from the axis and the widest unvignetted field"
    sizes = [s for s in (STYLE["axes.titlesize"], 8.0, 7.5, 7.0, 6.5) if s <= STYLE["axes.titlesize"]]
    size = next((s for s in sizes if "\n" not in fit_title(text, 0.97 * cell_in, fontsize=s)), sizes[-1])
    ax.set_title(fit_title(text, 0.97 * cell_in, fontsize=size), loc="left", fontsize=size,
                 x=(cell.x0 - box.x0) / box.width, y=TITLE_Y)  # axes fraction of the cell's left edge


def _draw_key(ax, key, units):
    """The key numbers: the close focus, a distance in the scene, in ``units``; the lengths inside the camera
    (EFL, pupil, image circle, track) in millimetres in every unit system (docs/cli.md), as they are engraved."""
    from ...units import format_distance
    from ._page import millimetres

    ax.set_axis_off()

    def dist(v):
        return "–" if v is None else format_distance(v, units)

    def inside(v):
        return "–" if v is None else millimetres(v)

    rows = [("EFL", f"{key['efl_mm']:.2f} mm"), ("f-number (wide open)", f"f/{key['f_number']:.2f}"),
            ("T-stop", "not given in the file" if key["tstop"] is None else f"T{key['tstop']:.2f}"),
            ("entrance pupil", f"Ø {key['entrance_pupil_diameter_mm']:.1f} mm"),
            ("  in front of film", inside(key["entrance_pupil_from_film_mm"])),
            ("close focus" + {"maker": " (MOD)", "focus groups": " (focus groups)"}.get(key["close_focus_source"], ""),
             dist(_shown_close_focus(key))),
            ("image circle", f"Ø {key['image_circle_mm']:.1f} mm"), ("total track", f"{key['total_track_mm']:.1f} mm")]
    if key["close_focus_source"] == "unit focusing limit":  # 1:1, which no real lens of the kind reaches
        rows.insert(6, ("", "unit focusing limit, not the lens's MOD"))
    elif _shown_close_focus(key) != key["close_focus_from_film_mm"]:  # the maker's MOD, closer than the model focuses
        rows.insert(6, ("", f"beyond the focus model (reaches {dist(key['close_focus_from_film_mm'])})"))
    if key["squeeze"] != 1.0:
        rows.append(("squeeze", f"{key['squeeze']:g}x"))
    ax.set_title("key numbers", loc="left", y=TITLE_Y)
    for i, (k, v) in enumerate(rows):
        y = 0.95 - i * 0.1
        note = k == ""  # a qualifier of the row above, in small type
        ax.text(0.0, y, k, transform=ax.transAxes, fontsize=7.5, va="top")
        ax.text(1.0, y, v, transform=ax.transAxes, fontsize=6 if note else 7.5, va="top", ha="right",
                fontweight="normal" if note else "bold", color="0.3" if note else "black")


def _shown_close_focus(key):
    """The close focus a card shows: the maker's MOD where the file gives one (even closer than the
    focus model reaches, key["close_focus_from_film_mm"]), else the model's close focus."""
    mod = key.get("minimum_object_distance_mm")
    return mod if key["close_focus_source"] == "maker" and mod is not None else key["close_focus_from_film_mm"]


def _no_data(ax, text):
    ax.set_axis_off()
    ax.text(0.5, 0.5, _wrap(text, 60), transform=ax.transAxes, ha="center", va="center", fontsize=7, color="0.3")


def _draw_mtf(ax, chart, label, note):
    if chart is None:
        ax.set_title(f"MTF, {label}", loc="left", y=TITLE_Y)
        _no_data(ax, note)
        return
    for k, f in enumerate(chart.frequencies_lpmm):
        lw = 2.0 - 1.2 * k / max(1, len(chart.frequencies_lpmm) - 1)
        ax.plot(chart.image_heights_mm, chart.sagittal[:, k], color=PALETTE[k % len(PALETTE)], lw=lw, label=f"{f:g} lp/mm S")
        ax.plot(chart.image_heights_mm, chart.tangential[:, k], color=PALETTE[k % len(PALETTE)], lw=lw, ls="--", label=f"{f:g} T")
    ax.set_xlim(0, float(chart.image_heights_mm.max()))
    ax.set_ylim(0, 1.0)
    ax.grid(True)
    ax.set_xlabel("image height (mm)")
    ax.set_ylabel("MTF")
    light = "white light" if chart.spectrum.startswith("white light") and "no dispersion" not in chart.spectrum \
        else ("monochromatic: the prescription gives no dispersion" if chart.spectrum.startswith("monochromatic")
              else "white light, some glasses without dispersion")
    from ...figures import fit_title

    ax.set_title(fit_title(f"MTF at f/{chart.fstop:.3g} ({label}), {light}", 3.2, fontsize=7), loc="left", fontsize=7,
                 y=TITLE_Y)
    ax.legend(ncol=3, loc="lower left", fontsize=5.5, handlelength=1.6, columnspacing=0.8)


def _draw_distortion(ax, res):
    ax.set_title("distortion (− barrel, + pincushion)", loc="left")
    if res is None:
        _no_data(ax, "no distortion: see the notes")
        return
    for axis, style in (("y", "-"), ("x", "--")):
        pts = res.meridian(axis)
        if pts:
            ax.plot([abs(p.real_height_mm) for p in pts], [p.distortion_pct for p in pts], style, color=PALETTE[0],
                    label=f"{axis.upper()} meridian")
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.grid(True)
    ax.set_xlabel("image height (mm)")
    ax.set_ylabel("distortion (%)")
    if len({p.axis for p in res.points}) > 1:  # an anamorphic: both meridians
        ax.legend()


def _draw_illumination(ax, res):
    ax.set_title("relative illumination, full aperture", loc="left", y=TITLE_Y)
    if res is None:
        _no_data(ax, "no relative illumination: see the notes")
        return
    pts = [p for p in res.points if p.axis == "y"]
    hs = [abs(p.film_height_mm) for p in pts]
    ax.plot(hs, [p.relative_illumination for p in pts], "-", color=PALETTE[0], label="relative illumination")
    ax.plot(hs, [p.cos4 for p in pts], ":", color="0.4", label="cos⁴ of the field angle")
    ax.set_ylim(0, 1.05)
    ax.grid(True)
    ax.set_xlabel("image height (mm)")
    ax.set_ylabel("relative illumination (fraction)")
    ax.legend(loc="lower left")


def _draw_breathing(ax, card, units):
    from ..framing.breathing_plot import draw_breathing

    ax.set_title(f"focus breathing: horizontal field of view ({card.sensor_mm[0]:g} mm wide sensor) and focal length "
                 "against the focus mark", loc="left")
    if not card.breathing:
        _no_data(ax, "no breathing table: see the notes")
        return
    draw_breathing(ax, card.breathing, units=units, legend_loc="upper right")


def _draw_bokeh(ax, img, label, height_mm):
    import numpy as np

    ax.set_title(f"bokeh, {label} ({height_mm:.1f} mm)", loc="left", fontsize=7.5, y=TITLE_Y)
    if img is None:
        _no_data(ax, "no light reaches the film")
        return
    x0, x1, y0, y1 = img.extent_mm
    a = img.image.sum(axis=2)
    a = a / max(float(a.max()), 1e-300)
    ax.imshow(np.sqrt(a), origin="lower", extent=(0, x1 - x0, 0, y1 - y0), cmap="gray", interpolation="bilinear")
    ax.set_xlabel("film (mm)", fontsize=6.5)
    ax.tick_params(labelsize=6)
    ax.set_yticks([])


# ---- writing --------------------------------------------------------------------------------------
@takes_prescription
def card_pages(lens: Prescription) -> list[str]:
    """The pages of ``lens``'s card, before it is computed: "main", then "zoom" for a zoom lens and
    "anamorphic" for an anamorphic one (what :attr:`LensCard.pages` will say)."""
    return ["main"] + (["zoom"] if lens.zoom is not None else []) + (["anamorphic"] if lens.squeeze != 1.0 else [])


def card_files(card, path) -> list:
    """The files :func:`save_lens_card` writes for ``card`` (a :class:`LensCard`, or its pages' names:
    :func:`card_pages`) at ``path``: the one PDF; for a PNG or SVG, ``path`` (the first page) and one file per
    further page beside it, ``<stem>-zoom<suffix>``, ``<stem>-anamorphic<suffix>``."""
    from pathlib import Path

    from ...errors import WrongTypeError

    pages = card.pages if isinstance(card, LensCard) else card
    if not (isinstance(pages, list) and pages[:1] == ["main"]):
        raise WrongTypeError("card must be a LensCard (physcam.analysis.lens_cards.card.lens_card(lens)) or its "
                             "pages' names (card_pages(lens))")
    p = Path(path)
    if p.suffix.lower() == ".pdf":
        return [p]
    return [p] + [p.with_name(f"{p.stem}-{name}{p.suffix}") for name in pages[1:]]


@styled
def save_lens_card(card: LensCard, path, *, force: bool = False, units: str = "m", dpi: int = 150):
    """Write ``card`` to ``path`` (.pdf, .png or .svg): a PDF with one page per page of the card, or a PNG/SVG
    of its first page and one file per further page (:func:`card_files`); each through atomic_write, none
    written when any exists (without ``force``). Returns ``path``."""
    from ...errors import require_type
    from ...figures import save_figure
    from ...io import check_writable

    require_type("card", card, LensCard, "physcam.analysis.lens_cards.card.lens_card(lens)")
    files = card_files(card, path)
    for f in files:
        check_writable(f, force=force)
    if files[0].suffix.lower() == ".pdf" and len(card.pages) > 1:
        return _save_pdf(card.figures(units=units), files[0], force, dpi)
    return [save_figure(fig, f, force=force, dpi=dpi) for f, fig in zip(files, card.figures(units=units))][0]


def _save_pdf(figs, path, force, dpi):
    """The pages ``figs`` as one PDF at ``path``, written atomically."""
    import io

    from matplotlib.backends.backend_pdf import PdfPages

    from ...figures import pyplot
    from ...io import atomic_write

    buf = io.BytesIO()
    try:
        with PdfPages(buf) as pdf:
            for fig in figs:
                fig.savefig(pdf, format="pdf", dpi=dpi)
    finally:
        for fig in figs:
            pyplot().close(fig)
    return atomic_write(path, buf.getvalue(), force=force)
