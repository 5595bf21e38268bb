"""Depth-of-field tables: near, far, total depth of field and hyperfocal for f-stops x focus marks.

The Python side of ``physcam dof-table`` (the command prints, writes CSV and cards from this dict;
``--json`` is this dict in a versioned document). Every cell is the lens report of that f-stop and
focus mark (:func:`physcam.onset.request.solve_report`: the same solver, sensor, CoC and model as
``physcam report``), so the table and the report agree cell by cell. Distances in mm from the film
plane. An anamorphic (``squeeze`` > 1 or an anamorphic lens) gets the horizontal limits beside the
vertical ones: a defocused point's blur is oval, so across the frame the CoC is c / blur aspect
(docs/anamorphic.md).
"""

from __future__ import annotations

import math
import numbers
import warnings

from ..errors import InputError, PhysCamWarning
from ..units import parse_distance
from .report import HYPERFOCAL, solve_report
from .request import report_camera

__all__ = ["DEFAULT_FOCUS", "DEFAULT_FSTOPS", "default_fstops", "dof_cells", "dof_table", "format_squeeze"]

#: The f-stops and marks of a table when none are given (the full stops of a cine lens; common marks).
DEFAULT_FSTOPS = (1.4, 2.0, 2.8, 4.0, 5.6, 8.0, 11.0, 16.0)
DEFAULT_FOCUS = ("1m", "1.5m", "2m", "3m", "5m", "10m", HYPERFOCAL, "inf")
#: The most f-stops and focus marks one table takes (the command's limits too).
MAX_FSTOPS, MAX_MARKS = 24, 40

DEFINITION = ("distances from the film plane; each row is `physcam report` at that f-stop and focus mark "
              "(null far and total: infinite); hfov_deg and vfov_deg: the desqueezed picture's field at the "
              "mark; *_horizontal_*: an anamorphic's limits across the frame, where the CoC is c / dof_aspect")


def _mark(m):
    """A focus mark: mm from the film (a number), ``inf``, :data:`HYPERFOCAL`, or text with a unit ("2m", "6ft")."""
    if isinstance(m, str):
        t = m.strip().lower()
        if t in (HYPERFOCAL, "hyper"):
            return HYPERFOCAL
        return parse_distance(m, name="focus mark", allow_inf=True)
    if isinstance(m, bool) or not isinstance(m, numbers.Real) or math.isnan(m) or m <= 0:
        raise InputError(f"a focus mark is a distance in mm from the film, text with a unit ('2m') or "
                         f"'hyperfocal', got {m!r}")
    return float(m)


def _fstop(n) -> float:
    """An f-number of the table: a positive finite number (numpy's included)."""
    if isinstance(n, bool) or not isinstance(n, numbers.Real) or not math.isfinite(n) or n <= 0:
        raise InputError(f"an f-stop of the table is a positive number (2.8), got {n!r}")
    return float(n)


def _listed(values, what: str) -> list:
    """``values`` as a list: one number or text is one entry (focus_marks_mm="2m", fstops=2.8)."""
    if isinstance(values, (str, bytes, numbers.Real)):
        return [values]
    try:
        return list(values)
    except TypeError:
        raise InputError(f"{what}: give a number, text or a list of them, got {type(values).__name__}") from None


def _row(report, mark) -> dict:
    """One cell of the table: the report's limits at its f-stop and mark."""
    d = report.dof
    row = {
        "fstop": report.fstop,
        "focus": mark if isinstance(mark, str) else ("infinity" if math.isinf(mark) else None),
        "focus_from_film_mm": None if math.isinf(report.focus_from_film_mm) else report.focus_from_film_mm,
        "near_from_film_mm": d.near_from_film_mm,
        "far_from_film_mm": None if d.far_is_infinite else d.far_from_film_mm,
        "total_mm": None if d.far_is_infinite else d.total_mm,
        "far_is_infinite": d.far_is_infinite,
        "hyperfocal_from_film_mm": d.hyperfocal_from_film_mm,
        "focal_length_mm": report.focal_length_mm,
        "hfov_deg": report.hfov_focus_deg, "vfov_deg": report.vfov_focus_deg,
    }
    if report.dof_horizontal is not None:  # an anamorphic: the limits across the frame (oval blur)
        dh = report.dof_horizontal
        row.update({
            "near_horizontal_from_film_mm": dh.near_from_film_mm,
            "far_horizontal_from_film_mm": None if dh.far_is_infinite else dh.far_from_film_mm,
            "total_horizontal_mm": None if dh.far_is_infinite else dh.total_mm,
            "far_horizontal_is_infinite": dh.far_is_infinite,
            "hyperfocal_horizontal_from_film_mm": dh.hyperfocal_from_film_mm})
    return row


def format_squeeze(sensor) -> float:
    """The anamorphic desqueeze the camera table gives ``sensor``'s recording format (``squeeze="format"``,
    ``--squeeze format``); InputError, saying what it offers, when it gives none or several."""
    from ..optics.sensors import Sensor, find_sensor

    if isinstance(sensor, str):
        sensor = find_sensor(sensor)
    elif not isinstance(sensor, Sensor):
        raise InputError(f"squeeze format needs a sensor (a name or a Sensor), got {type(sensor).__name__}")
    offered = tuple(getattr(sensor, "anamorphic", ()) or ())
    if len(offered) != 1:
        what = "no anamorphic desqueeze" if not offered else "desqueezes " + ", ".join(f"{v:g}" for v in offered)
        raise InputError(f"squeeze format: the camera table gives {sensor.name} {what}; give the squeeze as a number "
                         "(--squeeze S)")
    return float(offered[0])


def _table_lens(focal_length_mm, lens, sensor, squeeze, zoom):
    """(lens at its zoom position, squeeze, the ``zoom`` block or None) of a table's options, checked."""
    if (lens is None) == (focal_length_mm is None):
        raise InputError("give either a focal length (focal_length_mm=35) or a lens (lens=load_lens(name))")
    zoom_block = None
    if zoom is not None:
        if lens is None:
            raise InputError("a zoom position takes a zoom lens (lens=load_lens(name)): a thin lens of "
                             "focal_length_mm has no zoom")
        from ..optics.zoom import named_at_zoom

        lens, zoom_block = named_at_zoom(lens, zoom)
    if isinstance(squeeze, str) and squeeze.strip().lower() == "format":
        squeeze = format_squeeze(sensor)
    return lens, squeeze, zoom_block


def _cells(focal_length_mm, lens, sensor, coc, squeeze, zoom):
    """(``cell(fstop, mark) -> LensReport``, the lens at its zoom position, the ``zoom`` block) of a table's
    options: each cell ``physcam report`` of this lens at that stop and mark, the lens zoomed and the squeeze read
    once. A cell reads its limits and the paraxial field: its report leaves out a traced lens's real-ray field of
    view (``real_fov=False``: tracing it took most of a real lens's cell)."""
    lens, squeeze, zoom_block = _table_lens(focal_length_mm, lens, sensor, squeeze, zoom)

    def cell(fstop, mark):
        return solve_report(report_camera(focal_length_mm=focal_length_mm, lens=lens, sensor=sensor, fstop=fstop,
                                          focus_mm=mark, coc=coc, squeeze=squeeze), real_fov=False)

    return cell, lens, zoom_block


def dof_cells(focal_length_mm: float | None = None, *, lens=None, sensor, coc=None, squeeze: float | str = 1.0,
              zoom=None):
    """``cell(fstop, focus_mark) -> LensReport``: the report of one cell of :func:`dof_table` with these options
    (its own names and checks), at any stop and mark, for a chart drawn beside the table (``physcam dof-table -o``'s
    card) that must agree with it cell by cell: the table's rows are made by the same function."""
    return _cells(focal_length_mm, lens, sensor, coc, squeeze, zoom)[0]


def default_fstops(lens) -> tuple[list[float], list[str]]:
    """(the stops of a table not given any, notes): :data:`DEFAULT_FSTOPS` from ``lens``'s widest.

    A thin lens (None), or a lens model that does not know its widest, takes them all. A lens takes those it
    opens to, led by its widest f-stop (rounded to 3 significant figures, as the report's note prints it) where
    it left some out and no kept stop is within :data:`physcam.onset.lens_compare.FSTOP_SLACK` of it:
    ``physcam compare``'s rule ("compared wide open") of the stop a lens opens to, its engraved widest f-stop or
    the file's own stop's f-number when slower (:meth:`physcam.optics.lens_model.PrescriptionLens.wide_open`)."""
    from ..optics.lens_model import lens_model_of
    from .lens_compare import FSTOP_SLACK

    wide = None if lens is None else lens_model_of(lens).wide_open()
    if wide is None:
        return list(DEFAULT_FSTOPS), []
    kept = [n for n in DEFAULT_FSTOPS if n >= wide * (1 - FSTOP_SLACK)]
    if len(kept) == len(DEFAULT_FSTOPS):
        return kept, []
    dropped = ", ".join(f"f/{n:g}" for n in DEFAULT_FSTOPS[:len(DEFAULT_FSTOPS) - len(kept)])
    widest = float(f"{wide:.3g}")
    if not kept or kept[0] > wide * (1 + FSTOP_SLACK):
        kept.insert(0, widest)
    return kept, [f"the lens opens only to f/{widest:g}: the default f-stops start there, wide open "
                  f"({dropped} left out)"]


def dof_table(focal_length_mm: float | None = None, *, lens=None, sensor, fstops=None,
              focus_marks_mm=DEFAULT_FOCUS, coc=None, squeeze: float | str = 1.0, zoom=None) -> dict:
    """The depth-of-field table of a thin lens of ``focal_length_mm`` or of ``lens`` (a prescription,
    the technical model) on ``sensor`` (a name or a Sensor; required, as the report's): one row per
    f-stop and focus mark, each the lens report there, and the hyperfocal distance per f-stop.

    ``focus_marks_mm``: marks from the film plane, each mm (a number), ``math.inf``, ``"hyperfocal"`` or text
    with a unit ("2m", "6ft"); ``coc``: mm or a convention's name (None: the sensor's default);
    ``squeeze``: an anamorphic desqueeze, or ``"format"`` for the one the camera table gives the sensor's
    format (:func:`format_squeeze`); ``zoom``: a zoom lens's position, a focal length with its unit ("135mm")
    or the encoder value 0..1 (``--zoom``; default its first tabulated position; out of the zoom range, and
    for a prime, an InputError: :func:`physcam.optics.zoom.named_at_zoom`); ``fstops``: f-numbers (one faster than
    the lens opens refused), or None for :data:`DEFAULT_FSTOPS` from the lens's widest (:func:`default_fstops`,
    at its zoom position, its note in ``notes``). Returns the dict ``physcam
    dof-table --json`` prints (without its ``schema``/``version``/``units`` keys): keys ``rows`` (fstop, focus,
    ``*_from_film_mm``, ``total_mm``, fields of view), ``hyperfocal``, ``sensor``, ``coc_mm``, ``zoom`` (the
    position's block, None without one), ``notes`` (what the table chose for the user), ...
    """
    cell, lens, zoom_block = _cells(focal_length_mm, lens, sensor, coc, squeeze, zoom)
    notes = []
    if fstops is None:
        fstops, notes = default_fstops(lens)
    fstops = [_fstop(n) for n in _listed(fstops, "fstops")]
    marks = [_mark(m) for m in _listed(focus_marks_mm, "focus_marks_mm")]
    if not fstops or len(fstops) > MAX_FSTOPS:
        raise InputError(f"a table takes 1 to {MAX_FSTOPS} f-stops, got {len(fstops)}")
    if not marks or len(marks) > MAX_MARKS:
        raise InputError(f"a table takes 1 to {MAX_MARKS} focus marks, got {len(marks)}")
    rows, hyper, first = [], [], None
    with warnings.catch_warnings():  # one warning per lens, not per cell (the real field of view)
        warnings.simplefilter("ignore", PhysCamWarning)
        for n in fstops:
            for m in marks:
                r = cell(n, m)
                first = first or r
                rows.append(_row(r, m))
            hyper.append({"fstop": n, "hyperfocal_from_film_mm": rows[-1]["hyperfocal_from_film_mm"]})
    s = first.sensor
    return {
        "lens": None if lens is None else lens.name, "model": first.model, "focal_length_mm": first.focal_length_mm,
        "sensor": {"name": s.name, "width_mm": s.width_mm, "height_mm": s.height_mm},
        "coc_mm": first.coc_mm, "coc_convention": first.coc_convention, "squeeze": first.squeeze,
        "dof_aspect": first.dof_aspect, "fstops": fstops,
        "focus": [m if isinstance(m, str) else ("infinity" if math.isinf(m) else m) for m in marks],
        "rows": rows, "hyperfocal": hyper, "zoom": zoom_block, "notes": notes, "definition": DEFINITION,
    }
