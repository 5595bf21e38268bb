"""The lens report as a table for people (rich), from the same dict as ``--json``."""

from __future__ import annotations

from ..units import format_feet_inches


def _len(mm) -> str:
    if mm is None:
        return "∞"
    if abs(mm) >= 1000:
        return f"{mm / 1000:.3f} m  ({format_feet_inches(mm)})"
    return f"{mm:.2f} mm"


def report_table(report):
    """A rich Table of the report's main figures."""
    from rich.table import Table

    d = report.to_dict()
    t = Table(title=f"physcam lens report — {d['model']} model", show_header=True, header_style="bold")
    t.add_column("quantity")
    t.add_column("value")
    t.add_column("measured from")
    add = t.add_row
    if d["lens"]:
        add("lens", d["lens"], "")
    add("focal length", f"{d['focal_length_mm']:.2f} mm", "")
    fs = f"f/{d['fstop']:.2f}" + (" (solved)" if "fstop" in d["solved"] else "")
    add("f-stop", fs, "")
    if d["tstop"] is not None:
        add("T-stop", f"T{d['tstop']:.2f}  (drift {d['solved'].get('tstop_drift_stops', 0):+.2f} stops)", "")
    s = d["sensor"]
    add("sensor", f"{s['name']}  {s['width_mm']:.2f} x {s['height_mm']:.2f} mm", "")
    if d["squeeze"] != 1.0:
        add("anamorphic squeeze", f"{d['squeeze']:g}x", "")
    add("circle of confusion", f"{d['coc_mm']:.4f} mm  ({d['coc_convention']})", "")
    add("focus mark", _len(d["focus_from_film_mm"]) + (" (solved)" if "focus_from_film_mm" in d["solved"] else ""),
        "film plane")
    add("object distance s", _len(d["object_distance_mm"]), "H1")
    add("image distance s'", _len(d["image_distance_mm"]), "H2")
    add("H1 / H2", f"{d['h1_from_film_mm']:.2f} / {d['h2_from_film_mm']:.2f} mm", "film plane")
    if d["model"] == "technical":
        add("focus error", f"{d['focus_error_mm']:+.3f} mm (+ = image in front of film)", "film plane")
    add("magnification", f"{d['magnification']:.5f}  (1:{1 / d['magnification']:.1f})", "")
    dof = d["dof"]
    add("hyperfocal", _len(dof["hyperfocal_from_film_mm"]), "film plane")
    add("near limit", _len(dof["near_from_film_mm"]), "film plane")
    add("far limit", _len(dof["far_from_film_mm"]), "film plane")
    add("depth of field", _len(dof["total_mm"]), "")
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
    if d["entrance_pupil_from_film_mm"] is not None:
        add("entrance pupil (pivot)", f"{d['entrance_pupil_from_film_mm']:.2f} mm  [{d['entrance_pupil_source']}]",
            "film plane")
    for k in ("coc_mm", "consistency", "far_error_mm", "fstop_drift_stops"):
        if k in d["solved"] and d["solved"][k] is not None:
            add(f"solved {k}", f"{d['solved'][k]:.6g}", "")
    for n in d["notes"]:
        add("note", n, "")
    return t
