"""``physcam dof-table``: near, far, total depth of field and hyperfocal for f-stops x focus marks.

Every cell is the lens report of that f-stop and focus mark (the same solver, sensor, CoC and
model as ``physcam report``), so the table and the report agree cell by cell. Distances are
from the film plane; ``--units ft`` prints feet and inches (1/8 inch below 10 ft). ``-o
card.pdf`` draws a printable card (PDF, PNG or SVG), the chart an assistant tapes to the camera.
"""

from __future__ import annotations

import math

from ..figures import styled
from ._common import FOCUS_HELP, add_sensor_options, add_units_option, distance, focus_list, list_items, number

EPILOG = """\
examples:
  physcam dof-table --focal 35 --fstops 2,2.8,4,5.6 --focus 1m,2m,3m,5m,10m
  physcam dof-table --focal 50 --sensor "ALEXA 35" --units ft --focus 4ft,6ft,8ft,10ft,15ft,hyperfocal
  physcam dof-table --lens dgauss_50mm --fstops 2.8,4 --focus 1m,2m,inf --csv
  physcam dof-table --focal 35 --fstops 2,2.8,4,5.6 --focus 1m,2m,3m,5m,10m -o card.pdf
"""

#: The f-stops and marks of a table when none are given (the full stops of a cine lens; common marks).
DEFAULT_FSTOPS = (1.4, 2.0, 2.8, 4.0, 5.6, 8.0, 11.0, 16.0)
DEFAULT_FOCUS = "1m,1.5m,2m,3m,5m,10m,hyperfocal,inf"


def _fstops(text):
    """Comma-separated f-stops (argparse type)."""
    import argparse

    one = number("f-stop", positive=True)
    parts = list_items(text, "f-stops", "2,2.8,4,5.6")
    if len(parts) > 24:
        raise argparse.ArgumentTypeError(f"a table takes up to 24 f-stops, got {len(parts)}")
    return [one(t.removeprefix("f/").removeprefix("T")) for t in parts]


def register(sub) -> None:
    import argparse

    from ._output import add_output_options
    from .lens import add_lenient
    from .report import add_coc_option

    p = sub.add_parser("dof-table", help="depth-of-field table: near, far, total, hyperfocal for f-stops x focus marks",
                       description="A depth-of-field table for one lens: near and far limits, total depth of field and "
                                   "hyperfocal distance for each f-stop and focus mark (distances from the film plane), "
                                   "as a table, CSV, JSON or a printable card.", epilog=EPILOG,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    g = p.add_argument_group("lens and sensor")
    g.add_argument("--focal", metavar="MM", type=distance("focal length"), help="focal length (mm): a thin lens")
    g.add_argument("--lens", metavar="NAME_OR_FILE",
                   help="a real lens (bundled name or prescription file) instead of --focal: the technical model")
    add_lenient(p)
    g.add_argument("--fstops", type=_fstops, default=list(DEFAULT_FSTOPS), metavar="LIST",
                   help="f-stops (geometric f-numbers), comma-separated (default 1.4,2,2.8,4,5.6,8,11,16)")
    g.add_argument("--focus", type=focus_list("focus marks"), default=None, metavar="LIST",
                   help=f"focus marks from the film plane, comma-separated (default {DEFAULT_FOCUS}; {FOCUS_HELP})")
    add_sensor_options(g, what="group")
    add_coc_option(g)
    add_units_option(p)
    add_output_options(p, csv=True, what="the table")
    p.add_argument("-o", "--output", metavar="CARD", help="draw a printable card (.pdf, .png or .svg)")
    p.add_argument("--page", choices=("a4", "letter"), default="a4",
                   help="the card's page, portrait: a4 (210 x 297 mm, default) or letter (8.5 x 11 in)")
    p.add_argument("--force", action="store_true", help="overwrite an existing card")
    p.set_defaults(handler=run)


def cell_report(args, lens, sensor, fstop, focus):
    """The lens report of one cell: what `physcam report` gives for these options."""
    from ..onset.report import report_camera, solve_report
    from ._common import coc_of

    return solve_report(report_camera(focal_length_mm=None if lens is not None else args.focal, lens=lens, sensor=sensor,
                         fstop=fstop, focus_mm=focus, coc=coc_of(args)))


def build(args) -> dict:
    """The table as a dict (the JSON payload): inputs, rows (one per f-stop and mark) and hyperfocals."""
    import warnings

    from ..errors import InputError, PhysCamWarning
    from ._common import resolve_sensor

    lens = None
    if args.lens:
        if args.focal is not None:
            raise InputError("give either --lens or --focal: the lens sets its own focal length")
        from ..lens.library import load_lens

        lens = load_lens(args.lens, lenient=args.lenient)
        args.loaded_lens = lens
    elif args.focal is None:
        raise InputError("give the focal length, e.g. --focal 35, or a lens with --lens NAME")
    marks = args.focus if args.focus is not None else focus_list("focus marks")(DEFAULT_FOCUS)
    if len(marks) > 40:
        raise InputError(f"a table takes up to 40 focus marks, got {len(marks)}")
    sensor = resolve_sensor(args)
    rows, hyper, first = [], [], None
    with warnings.catch_warnings():  # one warning per lens, not per cell (the real field of view)
        warnings.simplefilter("ignore", PhysCamWarning)
        for n in args.fstops:
            for m in marks:
                r = cell_report(args, lens, sensor, n, m)
                first = first or r
                d = r.dof
                rows.append({
                    "fstop": r.fstop,
                    "focus": m if isinstance(m, str) else ("infinity" if math.isinf(m) else None),
                    "focus_from_film_mm": None if math.isinf(r.focus_from_film_mm) else r.focus_from_film_mm,
                    "near_from_film_mm": d.near_from_film_mm,
                    "far_from_film_mm": None if d.far_is_infinite else d.far_from_film_mm,
                    "total_mm": None if d.far_is_infinite else d.total_mm,
                    "far_is_infinite": d.far_is_infinite,
                    "hyperfocal_from_film_mm": d.hyperfocal_from_film_mm,
                    "focal_length_mm": r.focal_length_mm,
                })
            hyper.append({"fstop": n, "hyperfocal_from_film_mm": rows[-1]["hyperfocal_from_film_mm"]})
    return {
        "lens": None if lens is None else lens.name, "model": first.model, "focal_length_mm": first.focal_length_mm,
        "sensor": {"name": sensor.name, "width_mm": sensor.width_mm, "height_mm": sensor.height_mm},
        "coc_mm": first.coc_mm, "coc_convention": first.coc_convention, "fstops": list(args.fstops),
        "focus": [m if isinstance(m, str) else ("infinity" if math.isinf(m) else m) for m in marks],
        "rows": rows, "hyperfocal": hyper,
        "definition": "distances from the film plane; each row is `physcam report` at that f-stop and focus mark "
                      "(null far and total: infinite)",
    }


def _label(m, units) -> str:
    from ..units import format_distance

    return "at hyperfocal" if m == "hyperfocal" else format_distance(math.inf if m == "infinity" else m, units)


def _title(d, units) -> str:
    lens = d["lens"] or f"{d['focal_length_mm']:g} mm"
    s = d["sensor"]
    return (f"depth of field: {lens}, {s['name']} ({s['width_mm']:g} x {s['height_mm']:g} mm), CoC "
            f"{d['coc_mm']:.4g} mm ({d['coc_convention']}); from the film plane, in {'feet' if units == 'ft' else 'metres'}")


def grid(d, units):
    """(row labels, f-stop headers, cells[row][col] = (near, far, total) text) of the table."""
    from ..units import format_distance

    fs = d["fstops"]
    nm = len(d["focus"])
    cells = []
    for i, m in enumerate(d["focus"]):
        row = []
        for j in range(len(fs)):
            r = d["rows"][j * nm + i]
            far = math.inf if r["far_from_film_mm"] is None else r["far_from_film_mm"]
            total = math.inf if r["total_mm"] is None else r["total_mm"]
            row.append((format_distance(r["near_from_film_mm"], units), format_distance(far, units),
                        format_distance(total, units)))
        cells.append(row)
    labels = []
    for i, m in enumerate(d["focus"]):
        labels.append(_label(m, units))
    return labels, [f"f/{n:g}" for n in fs], cells


def csv_rows(d, units) -> list[dict]:
    """The rows for --csv: the JSON rows in mm, or with --units ft every distance in decimal feet
    (columns named ``*_ft``), the millimetres divided by 304.8."""
    if units == "m":
        return d["rows"]
    out = []
    for r in d["rows"]:
        q = {}
        for k, v in r.items():
            if k.endswith("_mm") and k != "focal_length_mm":
                q[k[:-3] + "_ft"] = None if v is None else v / 304.8
            else:
                q[k] = v
        out.append(q)
    return out


def run(args) -> int:
    from ..io import check_writable
    from ._common import units_of
    from ._output import Table, document, emit_json, print_csv, print_table

    if args.output:
        check_writable(args.output, force=args.force)
    elif args.force:
        from ..errors import InputError

        raise InputError("--force overwrites the card (-o); without -o there is nothing to overwrite")
    units = units_of(args)
    d = build(args)
    if getattr(args, "loaded_lens", None) is not None:
        from .lens import mark_repaired

        d = mark_repaired(d, args.loaded_lens)
    if args.output:
        card(d, args.output, units=units, force=args.force, chart=_card_chart(args), page=args.page)
    if args.json:
        emit_json(document("dof_table", d))
        return 0
    if args.csv:
        print_csv(csv_rows(d, units))
        return 0
    labels, heads, cells = grid(d, units)
    t = Table(_title(d, units), ["focus", *(f"{h} near - far" for h in heads)], justify=["left"] + ["right"] * len(heads))
    for lab, row in zip(labels, cells):
        t.add_row(lab, *(f"{near} - {far}" for near, far, _ in row))
    from ..units import format_distance

    t.add_row("hyperfocal distance", *(format_distance(h["hyperfocal_from_film_mm"], units) for h in d["hyperfocal"]))
    print_table(t)
    t = Table("total depth of field", ["focus", *heads], justify=["left"] + ["right"] * len(heads))
    for lab, row in zip(labels, cells):
        t.add_row(lab, *(total for _, _, total in row))
    print_table(t)
    if args.output:
        print(f"wrote {args.output}")
    return 0


def _card_chart(args):
    """(report, chart data) of the DOF chart under the card's table: the table's stops (up to six of them,
    spread from its first to its last: never a stop the table does not have) against focus, every cell a
    report as the table's."""
    import warnings

    from ..errors import PhysCamWarning
    from ..onset.dof_plot import dof_chart_data
    from ._common import resolve_sensor

    lens, sensor = getattr(args, "loaded_lens", None), resolve_sensor(args)
    marks = [m for m in (args.focus or []) if isinstance(m, float) and math.isfinite(m)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysCamWarning)
        report = cell_report(args, lens, sensor, args.fstops[0], marks[len(marks) // 2] if marks else 3000.0)
        stops = list(args.fstops)
        if len(stops) > CHART_STOPS:
            stops = [stops[round(k * (len(stops) - 1) / (CHART_STOPS - 1))] for k in range(CHART_STOPS)]
        data = dof_chart_data(report, lambda n, m: cell_report(args, lens, sensor, n, m), fstops=stops)
    return report, data


#: The most f-stops the card's chart draws (its bands stay readable).
CHART_STOPS = 6


@styled
def card(d, path, *, units: str = "m", force: bool = False, chart=None, page: str = "a4"):
    """Write :func:`card_figure` to ``path`` (PDF, PNG or SVG) through :func:`physcam.figures.save_figure`."""
    from ..figures import save_figure

    return save_figure(card_figure(d, units=units, chart=chart, page=page), path, force=force)


@styled
def card_figure(d, *, units: str = "m", chart=None, page: str = "a4"):
    """A printable depth-of-field card on one A4 or US Letter page (``page``, portrait): focus marks down,
    f-stops across, near / far / total in each cell, hyperfocal at the foot; with ``chart`` (a report and
    its :func:`physcam.onset.dof_plot.dof_chart_data`), the DOF chart of the set's apps below the table."""

    from ..analysis.lens_cards.card import PAGES
    from ..figures import new_figure
    from ..units import format_distance

    labels, heads, cells = grid(d, units)
    nrow, ncol = len(labels) + 2, len(heads) + 1
    page_w, h = PAGES[page]
    chart_in = 4.2 if chart is not None else 0.0
    table_in = min(h - chart_in - 0.5, max(3.0, 0.5 * nrow + 0.9))  # taller for long tables, within the page
    fig = new_figure(figsize=(page_w, h))
    top = h - 0.15  # the table and its title from the top of the page, the chart below it
    ax = fig.add_axes((0.03, (top - 0.92 * table_in) / h, 0.94, (0.86 * table_in - 0.25) / h))  # 2 title lines
    if chart is not None:
        from ..onset.dof_plot import draw_dof_chart

        bottom = top - table_in - chart_in + 0.75
        draw_dof_chart(fig.add_axes((0.09, bottom / h, 0.88, (chart_in - 1.1) / h)), *chart, units=units)
    ax.set_axis_off()
    text = [["focus", *heads]]
    for lab, row in zip(labels, cells):
        text.append([lab, *(f"{near}\n{far}\n({total})" for near, far, total in row)])
    text.append(["hyperfocal", *(format_distance(hf["hyperfocal_from_film_mm"], units) for hf in d["hyperfocal"])])
    first = 1.3 / (ncol + 0.3)  # the label column a little wider than the others
    tab = ax.table(cellText=text, cellLoc="center", bbox=(0.0, 0.0, 1.0, 1.0),
                   colWidths=[first] + [(1.0 - first) / (ncol - 1)] * (ncol - 1))
    tab.auto_set_font_size(False)
    tab.set_fontsize(6.5 if ncol > 6 or nrow > 10 else 8)
    for (r, c), cell in tab.get_celld().items():
        cell.set_linewidth(0.5)
        if r in (0, nrow - 1) or c == 0:
            cell.set_facecolor("#e8eef5")
            cell.set_text_props(weight="bold")
    from ..figures import fit_title

    fig.suptitle(fit_title(_title(d, units), 0.95 * page_w, fontsize=8), fontsize=8, y=(h - 0.05) / h, va="top")
    fig.text(0.5, 0.08 / h, "each cell: near / far / (total depth of field); physcam dof-table", ha="center", fontsize=6,
             color="0.35")
    return fig
