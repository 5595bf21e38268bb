"""The lens report as a table for people, from the same dict as ``--json``.

Scene distances (focus mark, object distance, near, far, hyperfocal, depth of field) are printed
in the chosen unit system (``units``: ``m`` or ``ft``, :func:`physcam.units.format_distance`);
lengths inside the camera (focal length, principal planes, pupil, CoC) stay in millimetres, as
they are engraved and written on set.
"""

from __future__ import annotations

from ..units import format_distance


def signed(value: float, digits: int) -> str:
    """``value`` with its sign, to ``digits`` decimals; one that rounds to zero reads +0 (never -0.000)."""
    text = f"{value:+.{digits}f}"
    return text if float(text) != 0.0 else f"{0.0:+.{digits}f}"


def exactly_determined(d: dict) -> bool:
    """Whether the report's focus and f-stop were both solved from its measured near and far limits: two
    limits, two unknowns, so the check of one limit against the other is zero by construction."""
    return "focus_from_film_mm" in d["solved"] and "fstop" in d["solved"]


def report_title(report) -> str:
    return f"physcam lens report — {report.model} model"


def report_rows(report, units: str = "m", *, notes: bool = True) -> list[tuple[str, str, str]]:
    """(quantity, value, measured from) rows of the report's main figures (and its notes)."""
    d = report.to_dict()
    rows: list[tuple[str, str, str]] = []

    def add(*cells):
        rows.append(tuple(cells))

    def _len(mm) -> str:
        return "∞" if mm is None else format_distance(mm, units)

    if d["lens"]:
        add("lens", d["lens"], "")
    add("focal length", f"{d['focal_length_mm']:.2f} mm", "")
    fs = f"f/{d['fstop']:.2f}" + (" (solved)" if "fstop" in d["solved"] else "")
    add("f-stop", fs, "")
    if d["tstop"] is not None:
        add("T-stop", f"T{d['tstop']:.2f}  (drift {signed(d['solved'].get('tstop_drift_stops', 0), 2)} stops)", "")
    s = d["sensor"]
    add("sensor", f"{s['name']}  {s['width_mm']:.2f} x {s['height_mm']:.2f} mm", "")
    if d["squeeze"] != 1.0:
        add("anamorphic squeeze", f"{d['squeeze']:g}x", "")
    add("circle of confusion", f"{d['coc_mm']:.4f} mm  ({d['coc_convention']})", "")
    how = " (solved)" if "focus_from_film_mm" in d["solved"] else (
        " (hyperfocal)" if d["solved"].get("focus") == "hyperfocal" else "")
    add("focus mark", _len(d["focus_from_film_mm"]) + how, "film plane")
    add("object distance s", _len(d["object_distance_mm"]), "H1")
    add("image distance s'", f"{d['image_distance_mm']:.2f} mm", "H2")
    add("H1 / H2", f"{d['h1_from_film_mm']:.2f} / {d['h2_from_film_mm']:.2f} mm", "film plane")
    if d["model"] == "technical":
        add("focus error", f"{signed(d['focus_error_mm'], 3)} mm (+ = image in front of film)", "film plane")
    m = d["magnification"]
    add("magnification", f"{m:.5f}  (1:{1 / abs(m):.1f}, inverted image)" if m else "0  (subject at infinity)", "")
    fr = d["frame_at_focus"]
    if fr is not None:
        add("frame at the focus (w x h)", f"{_len(fr['width_mm'])} x {_len(fr['height_mm'])}", "subject plane")
    dof = d["dof"]
    add("hyperfocal", _len(dof["hyperfocal_from_film_mm"]), "film plane")
    add("near limit", _len(dof["near_from_film_mm"]), "film plane")
    add("far limit", _len(dof["far_from_film_mm"]), "film plane")
    add("depth of field", _len(dof["total_mm"]), "")
    sf = d["split_focus"]
    if sf is not None:
        asked = f"{_len(sf['near_asked_from_film_mm'])} – {_len(sf['far_asked_from_film_mm'])}"
        given = "holds them" if sf["holds"] else f"f/{sf['fstop_given']:.2g} holds only the limits above"
        add("stop needed (split focus)", f"f/{sf['fstop_needed']:.2g} for {asked} at this CoC  ({given})", "")
    if d["dof_horizontal"]:
        dh = d["dof_horizontal"]
        add("horizontal near / far", f"{_len(dh['near_from_film_mm'])} / {_len(dh['far_from_film_mm'])}", "film plane")
    fi, ff = d["fov_deg"]["infinity"], d["fov_deg"]["focus"]
    add("FOV h / v / d (infinity)", f"{fi['horizontal']:.2f}° / {fi['vertical']:.2f}° / {fi['diagonal']:.2f}°", "")
    add("FOV h / v / d (at focus)", f"{ff['horizontal']:.2f}° / {ff['vertical']:.2f}° / {ff['diagonal']:.2f}°", "")
    real = fi and d["fov_deg"].get("real")
    if real:
        fmt = lambda v: "not covered" if v is None else f"{v:.2f}°"  # noqa: E731
        add("FOV h / v / d (real rays)", f"{fmt(real['horizontal'])} / {fmt(real['vertical'])} / "
            f"{fmt(real['diagonal'])}" + ("  [differs from the pinhole]" if d["fov_deg"]["real_differs"] else ""), "")
    pin = d["pinhole"]
    add("pinhole (render camera)", f"{pin['focal_length_mm']:.3f} mm" + (
        f", squeeze {pin['squeeze']:.4g}" if pin["squeeze"] != 1.0 else "") + "  [frames like the lens at focus]",
        "entrance pupil")
    eps = d.get("entrance_pupils") or {}
    if eps.get("separation_mm"):  # an anamorphic's two pupils: say which pivot is which
        add("entrance pupil, horizontal (pan pivot)", f"{eps['horizontal_from_film_mm']:.2f} mm  "
            f"[{d['entrance_pupil_source']}, X meridian]", "film plane")
        add("entrance pupil, vertical (tilt pivot)", f"{eps['vertical_from_film_mm']:.2f} mm  "
            f"[{d['entrance_pupil_source']}, Y meridian]", "film plane")
    elif d["entrance_pupil_from_film_mm"] is not None:
        add("entrance pupil (pivot)", f"{d['entrance_pupil_from_film_mm']:.2f} mm  [{d['entrance_pupil_source']}]",
            "film plane")
    sv = d["solved"]
    if sv.get("coc_mm") is not None:
        add("circle of confusion (solved)", f"{sv['coc_mm']:.4f} mm", "")
    if sv.get("fstop_drift_stops") is not None:
        add("f-stop drift (solved)", f"{signed(sv['fstop_drift_stops'], 2)} stops from the marked f-stop", "")
    if sv.get("far_error_mm") is not None and not exactly_determined(d):  # else zero by construction
        add("far limit: predicted − measured", f"{signed(sv['far_error_mm'], 1)} mm", "")
    for n in d["notes"] if notes else ():
        add("note", n, "")
    return rows
