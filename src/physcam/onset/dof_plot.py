"""Depth-of-field pictures for a DP to read at a glance.

:func:`dof_chart_figure` is the chart of the set's apps (pCam, the ARRI, ZEISS and Cooke
calculators, printed DOF cards): near and far limits against the focus mark, one band per f-stop
between them, on log axes with distances in metres or feet and inches at round marks, each stop's
hyperfocal marked where its far limit reaches infinity, and the report's own focus marked. Every
point is a lens report of that stop and mark from a ``solve(fstop, focus_mm)`` the caller gives
(the same solver, sensor, CoC and model as the report, so chart and report agree).
:func:`dof_zone_figure` is the zone of one report on a distance axis. All distances from the film plane.
"""

from __future__ import annotations

import math

from ..figures import styled

#: Millimetres per axis unit, and the axis label, per unit system (``--units``).
_AXIS = {"m": (1000.0, "m"), "ft": (304.8, "ft")}


@styled
def plot_dof_zone(report, path, *, force: bool = False, units: str = "m"):
    """Draw near, focus, far and hyperfocal on a distance axis (from the film plane); PNG, SVG or PDF.

    ``units``: ``m`` (metres) or ``ft`` (feet; the marks in feet and inches). Written atomically
    through :func:`physcam.io.atomic_write`.
    """
    from ..figures import save_figure
    from ..io import check_writable

    check_writable(path, force=force)
    return save_figure(dof_zone_figure(report, units=units), path, force=force)


def plot_title(report, units: str = "m") -> str:
    """Lens, f-stop, focus, CoC and sensor: what a depth-of-field picture is of."""
    from ..figures import unbroken
    from ..units import format_distance

    lens = report.lens_name or f"{report.focal_length_mm:g} mm"
    focus = unbroken(f"focus {format_distance(report.focus_from_film_mm, units)}")
    coc = unbroken(f"CoC {report.coc_mm:.4g} mm")
    return (f"{lens}  f/{report.fstop:.3g}  {focus}  {coc} ({report.coc_convention})  "
            f"{report.sensor.name}")


@styled
def dof_zone_figure(report, *, size_in=(9.0, 2.6), units: str = "m"):
    """The figure :func:`plot_dof_zone` saves, as a matplotlib Figure on its own Agg canvas (no pyplot
    state, so a server can draw it in memory with :func:`physcam.figures.figure_bytes`); ``size_in``
    is (width, height) in inches (a phone screen reads a narrower one); ``units`` m or ft."""
    from matplotlib.ticker import FuncFormatter, LogLocator

    from ..errors import UnitError
    from ..figures import PALETTE, fit_title, new_figure
    from ..units import format_distance

    if units not in _AXIS:
        raise UnitError(f"units must be one of {', '.join(_AXIS)}, got {units!r}")
    per, label = _AXIS[units]
    d = report.dof
    near, far = d.near_from_film_mm / per, d.far_from_film_mm / per
    focus = report.focus_from_film_mm / per
    hyper = d.hyperfocal_from_film_mm / per
    finite_focus = math.isfinite(focus)
    top = max(hyper, focus if finite_focus else 0.0)
    right = top * 1.3 if math.isinf(far) else max(far, focus) * 1.4
    right = max(right, near * 2)
    fig = new_figure(figsize=tuple(size_in), dpi=120)
    ax = fig.add_subplot(1, 1, 1)
    ax.axvspan(near, min(far, right), color=PALETTE[2], alpha=0.35, label="acceptably sharp")
    if report.dof_horizontal is not None:
        dh = report.dof_horizontal
        ax.axvspan(dh.near_from_film_mm / per, min(dh.far_from_film_mm / per, right), ymin=0.0, ymax=0.25,
                   color=PALETTE[0], alpha=0.5, label="horizontal (anamorphic)")
    left = min(near, focus) / 3.0
    marks = [(near, "near", "-", 0.82, "right"), (far, "far", "-", 0.28, "left"),
             (hyper, "hyperfocal", ":", 0.82, "left")]
    if finite_focus:
        marks.insert(1, (focus, "focus", "-", 0.55, "left"))
    for x, lab, style, y, ha in marks:
        if x < right:
            ax.axvline(x, color="k", ls=style, lw=1.2)
            dx = 0.98 if ha == "right" else 1.02
            ax.text(x * dx, y, f"{lab} {format_distance(x * per, units)}", transform=ax.get_xaxis_transform(), ha=ha,
                    va="center", fontsize=8, bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.8))
    if math.isinf(far):
        ax.text(right, 0.5, "→ ∞", ha="right", va="center", fontsize=12)
    ax.set_xscale("log")
    ax.set_xlim(left, right)
    ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))
    ax.set_yticks([])
    ax.set_xlabel(f"distance from the film plane ({label}, log scale)")
    ax.set_title(fit_title(plot_title(report, units), 0.85 * size_in[0]))
    ax.legend(loc="lower right", fontsize=7)
    fig.tight_layout()
    return fig


# ---- the chart of the set's apps: near / far against focus, one band per stop ---------------------
#: Round distances a person reads on a log axis: metres, and feet (ticks in whole feet).
_ROUND = {"m": (0.1, 0.15, 0.2, 0.3, 0.5, 0.7, 1, 1.5, 2, 3, 5, 7, 10, 15, 20, 30, 50, 70, 100, 150, 200, 300, 500,
                1000),
          "ft": (0.5, 1, 1.5, 2, 3, 4, 5, 6, 8, 10, 12, 15, 20, 25, 30, 40, 50, 75, 100, 150, 200, 300, 500, 1000, 2000,
                 3000)}


def chart_fstops(fstop: float) -> list[float]:
    """The stops a chart shows around ``fstop``: one stop faster, itself, two and four stops slower,
    on the full-stop scale (f/1, 1.4, 2, 2.8, 4, 5.6, 8, 11, 16, 22, 32) when ``fstop`` is on it."""
    scale = (1.0, 1.4, 2.0, 2.8, 4.0, 5.6, 8.0, 11.0, 16.0, 22.0, 32.0, 45.0, 64.0, 90.0, 128.0)
    k = min(range(len(scale)), key=lambda i: abs(math.log(scale[i] / fstop)))
    if abs(math.log(scale[k] / fstop)) < 0.02:
        return [scale[i] for i in (k - 1, k, k + 2, k + 4) if 0 <= i < len(scale)]
    return [fstop / math.sqrt(2.0), fstop, 2.0 * fstop, 4.0 * fstop]


def dof_chart_data(report, solve, *, fstops=None, marks: int = 28) -> dict:
    """Near, far and hyperfocal (mm from the film plane) at ``marks`` focus marks spaced evenly in log
    distance, for each of ``fstops`` (default :func:`chart_fstops` of the report's), from
    ``solve(fstop, focus_mm) -> LensReport``. A stop or mark the solver refuses (faster than the
    lens, closer than it focuses) is left out. Returns {"fstops": [...], "curves": {fstop: rows},
    "hyperfocal": {fstop: mm}, "range_mm": (lo, hi)}, rows as (focus, near, far) with far ``inf``
    beyond the hyperfocal."""
    from ..errors import PhysCamError

    fstops = chart_fstops(report.fstop) if fstops is None else [float(n) for n in fstops]
    hyper = {}
    for n in fstops:
        try:
            hyper[n] = solve(n, "hyperfocal").focus_from_film_mm
        except PhysCamError:
            continue
    if not hyper:  # the solver takes no "hyperfocal" focus: the report's own stop
        hyper[report.fstop] = report.dof.hyperfocal_from_film_mm
    focus = report.focus_from_film_mm
    hs = [h for h in hyper.values() if math.isfinite(h)]
    lo = max(min([focus / 3.0 if math.isfinite(focus) else min(hs) / 6.0] + [min(hs) / 10.0]), 10 * report.focal_length_mm)
    hi = max([2.0 * max(hs)] + ([2.0 * focus] if math.isfinite(focus) else []))
    xs = [lo * (hi / lo) ** (i / (marks - 1)) for i in range(marks)]
    curves = {}
    for n in hyper:
        rows = []
        h = hyper[n]  # the far limit climbs to infinity just below the hyperfocal: sample it there
        near_h = [h * (1.0 - e) for e in (0.4, 0.2, 0.1, 0.05, 0.02, 0.005)] if math.isfinite(h) else []
        for x in sorted(xs + [v for v in near_h if lo < v < hi]):
            try:
                d = solve(n, x).dof
            except PhysCamError:
                continue
            rows.append((x, d.near_from_film_mm, d.far_from_film_mm))
        if rows:
            curves[n] = rows
    return {"fstops": sorted(curves), "curves": curves, "hyperfocal": hyper, "range_mm": (lo, hi)}


def _round_ticks(ax, lo_mm: float, hi_mm: float, units: str, which: str, most: int = 9) -> None:
    """Ticks at round distances (:data:`_ROUND`) between ``lo_mm`` and ``hi_mm`` on the log ``which`` axis,
    at most ``most``, spread evenly in log distance; labels in m, or whole feet with a ' ."""
    from matplotlib.ticker import FixedFormatter, FixedLocator, NullLocator

    per = 1000.0 if units == "m" else 304.8
    cand = [v for v in _ROUND[units] if lo_mm / per <= v <= hi_mm / per]
    if len(cand) > most:
        step = math.log(cand[-1] / cand[0]) / (most - 1)
        keep, last = [], None
        for v in cand:
            if last is None or math.log(v / last) >= 0.85 * step:
                keep.append(v)
                last = v
        cand = keep
    labels = [f"{v:g}" if units == "m" else f"{v:g}'" for v in cand]
    axis = ax.xaxis if which == "x" else ax.yaxis
    axis.set_major_locator(FixedLocator([v * per for v in cand]))
    axis.set_major_formatter(FixedFormatter(labels))
    axis.set_minor_locator(NullLocator())


@styled
def dof_chart_figure(report, solve, *, fstops=None, size_in=(7.0, 4.6), units: str = "m", data=None):
    """The chart of the set's apps (module notes) for ``report``: near and far limits against the focus
    mark, a band per stop (``fstops``, default :func:`chart_fstops`), each hyperfocal marked, the
    report's focus and limits marked; ``solve(fstop, focus_mm)`` gives the lens report of any cell
    (or pass ``data`` from :func:`dof_chart_data`). A matplotlib Figure on an Agg canvas; the chart's
    numbers are in ``fig.physcam_chart`` (what the web page's cursor reads)."""
    from ..errors import UnitError
    from ..figures import fit_title, new_figure

    if units not in _AXIS:
        raise UnitError(f"units must be one of {', '.join(_AXIS)}, got {units!r}")
    data = dof_chart_data(report, solve, fstops=fstops) if data is None else data
    fig = new_figure(figsize=tuple(size_in), dpi=120)
    ax = fig.add_subplot(1, 1, 1)
    draw_dof_chart(ax, report, data, units=units)
    ax.set_title(fit_title(plot_title(report, units), 0.8 * size_in[0]))
    fig.tight_layout()
    fig.physcam_chart = _chart_numbers(ax, data, units)
    return fig


@styled
def draw_dof_chart(ax, report, data, *, units: str = "m") -> None:
    """Draw the chart (:func:`dof_chart_figure`) of :func:`dof_chart_data` ``data`` into ``ax``: a band per
    stop, each hyperfocal, the report's focus and limits; log axes with ticks a person reads."""
    from ..figures import PALETTE
    from ..units import format_distance

    lo, hi = data["range_mm"]
    top = hi * 1.6  # far limits at infinity are drawn to the top edge
    colours = [PALETTE[i] for i in (0, 2, 3, 4, 5, 1)]
    order = {n: k for k, n in enumerate(data["fstops"])}
    for n in reversed(data["fstops"]):  # slowest (widest band) first, underneath
        c = colours[order[n] % len(colours)]
        rows = data["curves"][n]
        xs = [r[0] for r in rows]
        nears = [r[1] for r in rows]
        fars = [min(r[2], top) for r in rows]
        ax.fill_between(xs, nears, fars, color=c, alpha=0.28, lw=0)
        ax.plot(xs, nears, color=c, lw=1.3, label=f"f/{n:.3g}")
        ax.plot(xs, fars, color=c, lw=1.3)
        h = data["hyperfocal"].get(n)
        if h is not None and lo <= h <= hi:
            ax.axvline(h, color=c, ls=":", lw=1.0)
            ax.text(h, lo * 1.05, f" H f/{n:.3g}", rotation=90, color=c, fontsize=6.5, ha="right", va="bottom")
    ax.plot([lo, hi], [lo, hi], color="0.35", lw=0.8, ls="--", label="focus (near = far)")
    f = report.focus_from_film_mm
    if math.isfinite(f) and lo <= f <= hi:
        d = report.dof
        ax.axvline(f, color="k", lw=1.0)
        ax.plot([f, f], [d.near_from_film_mm, min(d.far_from_film_mm, top)], "o", color="k", ms=3.5)
        far_txt = format_distance(d.far_from_film_mm, units)
        ax.annotate(f"f/{report.fstop:.3g} at {format_distance(f, units)}:\nnear {format_distance(d.near_from_film_mm, units)}"
                    f", far {far_txt}\ntotal {format_distance(d.total_mm, units)}", (f, d.near_from_film_mm), textcoords="offset points", xytext=(6, -4),
                    fontsize=7, va="top", bbox=dict(boxstyle="round,pad=0.25", fc="white", ec="0.6", alpha=0.9))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(lo, hi)
    ax.set_ylim(lo, top)
    _round_ticks(ax, lo, hi, units, "x")
    _round_ticks(ax, lo, hi, units, "y", most=7)
    ax.text(1.0, 1.0, "∞ ", transform=ax.transAxes, ha="right", va="top", fontsize=9)
    words = "m" if units == "m" else "feet"
    ax.set_xlabel(f"focus mark from the film plane ({words})")
    ax.set_ylabel(f"near and far limits ({words})")
    ax.grid(True, which="major")
    handles, labels = ax.get_legend_handles_labels()
    by_stop = sorted(zip(handles, labels), key=lambda hl: float(hl[1][2:]) if hl[1].startswith("f/") else 1e9)
    ax.legend([h for h, _ in by_stop], [lab for _, lab in by_stop], loc="upper left", ncol=2, fontsize=6.5, title="bands: sharp from near to far", title_fontsize=6.5)


def _chart_numbers(ax, data, units: str) -> dict:
    """What the web page needs to mark the chart under the cursor: the axes' place in the figure
    (fractions, from the bottom left), the x range (mm, log axis) and the curves per stop (mm)."""
    x0, y0, w, h = ax.get_position().bounds
    lo, hi = ax.get_xlim()
    ylo, yhi = ax.get_ylim()

    def mm(v):
        return None if not math.isfinite(v) else round(v, 1)

    return {"axes": [x0, y0, w, h], "x_mm": [lo, hi], "y_mm": [ylo, yhi], "log": True, "units": units,
            "stops": [{"fstop": n, "hyperfocal_mm": mm(data["hyperfocal"].get(n, math.inf)),
                       "rows": [[mm(a), mm(b), mm(c)] for a, b, c in data["curves"][n]]} for n in data["fstops"]]}


@styled
def plot_dof_chart(report, solve, path, *, force: bool = False, units: str = "m", fstops=None):
    """Write :func:`dof_chart_figure` to ``path`` (.png, .svg or .pdf) through :func:`physcam.figures.save_figure`."""
    from ..figures import save_figure
    from ..io import check_writable

    check_writable(path, force=force)
    return save_figure(dof_chart_figure(report, solve, units=units, fstops=fstops), path, force=force)
