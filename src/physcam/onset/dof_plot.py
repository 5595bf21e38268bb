"""A picture of the depth-of-field zone against distance, for a DP to read at a glance."""

from __future__ import annotations


def plot_dof_zone(report, path, *, force: bool = False):
    """Draw near, focus, far and hyperfocal on a distance axis (from the film plane); PNG or SVG.

    Written atomically through :func:`physcam.io.atomic_write`.
    """
    from ..figures import save_figure
    from ..io import check_writable

    check_writable(path, force=force)
    return save_figure(dof_zone_figure(report), path, force=force)


def dof_zone_figure(report, *, size_in=(9.0, 2.6)):
    """The figure :func:`plot_dof_zone` saves, as a matplotlib Figure on its own Agg canvas (no pyplot
    state, so a server can draw it in memory with :func:`physcam.figures.figure_bytes`); ``size_in``
    is (width, height) in inches (a phone screen reads a narrower one)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    d = report.dof
    near, focus, far = d.near_from_film_mm / 1000, report.focus_from_film_mm / 1000, d.far_from_film_mm / 1000
    hyper = d.hyperfocal_from_film_mm / 1000
    right = max(hyper, focus) * 1.3 if far == float("inf") else max(far, focus) * 1.4
    right = max(right, near * 2)
    fig = Figure(figsize=tuple(size_in), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.axvspan(near, min(far, right), color="#9fd3a8", alpha=0.7, label="acceptably sharp")
    if report.dof_horizontal is not None:
        dh = report.dof_horizontal
        ax.axvspan(dh.near_from_film_mm / 1000, min(dh.far_from_film_mm / 1000, right), ymin=0.0, ymax=0.25,
                   color="#5b8fd6", alpha=0.6, label="horizontal (anamorphic)")
    left = min(near, focus) / 3.0
    marks = ((near, "near", "-", 0.82, "right"), (focus, "focus", "-", 0.55, "left"),
             (far, "far", "-", 0.28, "left"), (hyper, "hyperfocal", ":", 0.82, "left"))
    for x, lab, style, y, ha in marks:
        if x < right:
            ax.axvline(x, color="k", ls=style, lw=1.2)
            dx = 0.98 if ha == "right" else 1.02
            ax.text(x * dx, y, f"{lab} {x:.2f} m", transform=ax.get_xaxis_transform(), ha=ha, va="center",
                    fontsize=8, bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.8))
    if far == float("inf"):
        ax.text(right, 0.5, "→ ∞", ha="right", va="center", fontsize=12)
    ax.set_xscale("log")
    ax.set_xlim(left, right)
    from matplotlib.ticker import FuncFormatter, LogLocator

    ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))
    ax.set_yticks([])
    ax.set_xlabel("distance from the film plane (m, log scale)")
    title = f"{report.focal_length_mm:g} mm  f/{report.fstop:.2g}  CoC {report.coc_mm:.3f} mm  {report.sensor.name}"
    ax.set_title(title, fontsize=9)
    ax.legend(loc="lower right", fontsize=7)
    fig.tight_layout()
    return fig
