"""``physcam dof-table``: near, far, total depth of field and hyperfocal for f-stops x focus marks.

Every cell is the lens report of that f-stop and focus mark (the same solver, sensor, CoC and
model as ``physcam report``), so the table and the report agree cell by cell. Distances are
from the film plane. An anamorphic (``--squeeze S``, ``--squeeze format`` for the desqueeze the camera
table gives the format, or an anamorphic ``--lens``) gets the report's horizontal limits beside the
vertical ones (a defocused point's blur is oval, so across the frame the CoC is c / blur aspect:
docs/anamorphic.md) and every row says the horizontal and vertical field at its mark; ``--units ft`` prints feet and inches (1/8 inch below 10 ft). ``-o
card.pdf`` draws a printable card (PDF, PNG or SVG), the chart an assistant tapes to the camera.
"""

from __future__ import annotations

import math

from ..figures import styled
from ._common import FOCUS_HELP, add_sensor_options, add_units_option, distance, focus_list, list_items, number, figure_file

EPILOG = """\
examples:
  physcam dof-table --focal 35 --fstops 2,2.8,4,5.6 --focus 1m,2m,3m,5m,10m
  physcam dof-table --focal 50 --sensor "ALEXA 35" --units ft --focus 4ft,6ft,8ft,10ft,15ft,hyperfocal
  physcam dof-table --lens dgauss_50mm --fstops 2.8,4 --focus 1m,2m,inf --csv
  physcam dof-table --focal 35 --fstops 2,2.8,4,5.6 --focus 1m,2m,3m,5m,10m -o card.pdf
  physcam dof-table --focal 50 --sensor "ALEXA 35 3.3K 6:5" --squeeze format --fstops 2.8,4 --focus 2m,3m
"""

#: The f-stops and marks of a table when none are given: physcam.onset.dof_table's (a test holds them equal;
#: written out here so that the command's help does not import the solver).
DEFAULT_FSTOPS = (1.4, 2.0, 2.8, 4.0, 5.6, 8.0, 11.0, 16.0)
DEFAULT_FOCUS = "1m,1.5m,2m,3m,5m,10m,hyperfocal,inf"


def _fstops(text):
    """Comma-separated f-stops (argparse type): f-numbers, bare or as "f/2.8"; a T-stop ("T2.8") is refused
    with the report's explanation (:func:`physcam.cli._common.number`), not read as the f-number."""
    import argparse

    one = number("f-stop", positive=True)
    parts = list_items(text, "f-stops", "2,2.8,4,5.6")
    if len(parts) > 24:
        raise argparse.ArgumentTypeError(f"a table takes up to 24 f-stops, got {len(parts)}")
    return [one(t.removeprefix("f/")) for t in parts]  # "T2.8" refused: a T-stop is not the f-number


def _squeeze(text):
    """--squeeze: a number (0.1-10) or ``format`` (the sensor format's desqueeze, camera table)."""
    if text.strip().lower() == "format":
        return "format"
    return number("squeeze", positive=True)(text)


def squeeze_of(args, sensor) -> float:
    """The desqueeze the table takes: --squeeze's number, or with ``format`` the one the camera table
    gives the format (:func:`physcam.onset.dof_table.format_squeeze`; refused, with what it offers, when it
    gives none or several)."""
    from ..onset.dof_table import format_squeeze

    sq = getattr(args, "squeeze", 1.0)
    return format_squeeze(sensor) if sq == "format" else float(sq)


def register(sub) -> None:
    import argparse

    from ._output import add_output_options
    from ._zoom import add_zoom_option
    from ._common import add_lenient
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
    add_zoom_option(g)
    g.add_argument("--fstops", type=_fstops, default=None, metavar="LIST",
                   help="f-stops (geometric f-numbers), comma-separated (default 1.4,2,2.8,4,5.6,8,11,16; with "
                        "--lens those it opens to, from its widest, with a note)")
    g.add_argument("--focus", type=focus_list("focus marks"), default=None, metavar="LIST",
                   help=f"focus marks from the film plane, comma-separated (default {DEFAULT_FOCUS}; {FOCUS_HELP})")
    add_sensor_options(g, what="group")
    g.add_argument("--squeeze", metavar="S", type=_squeeze, default=1.0,
                   help="anamorphic desqueeze: a number, or `format` for the one the camera table gives the sensor "
                        "format (default 1: spherical, or an anamorphic --lens's own); adds the horizontal limits")
    add_coc_option(g)
    add_units_option(p)
    add_output_options(p, csv=True, what="the table")
    p.add_argument("-o", "--output", metavar="CARD", type=figure_file, help="draw a printable card (.pdf, .png or .svg)")
    p.add_argument("--page", choices=("a4", "letter"), default="a4",
                   help="the card's page, portrait: a4 (210 x 297 mm, default) or letter (8.5 x 11 in)")
    p.add_argument("--force", action="store_true", help="overwrite an existing card")
    p.set_defaults(handler=run)


def build(args) -> dict:
    """The table as a dict (the JSON payload): :func:`physcam.onset.dof_table.dof_table` of the options
    (``--zoom`` its ``zoom``)."""
    from ..errors import InputError
    from ..onset.dof_table import MAX_MARKS, dof_table

    _lens_option(args)
    marks = args.focus if args.focus is not None else focus_list("focus marks")(DEFAULT_FOCUS)
    if len(marks) > MAX_MARKS:  # before the sensor is resolved: the command's own order of refusals
        raise InputError(f"a table takes up to {MAX_MARKS} focus marks, got {len(marks)}")
    return dof_table(**_table_options(args), fstops=args.fstops, focus_marks_mm=marks)


def _lens_option(args):
    """The --lens prescription (loaded once, kept as ``args.loaded_lens``), or None for a thin --focal lens;
    InputError for the lens options the command refuses: both, neither, --zoom without --lens."""
    from ..errors import InputError

    if args.lens:
        if args.focal is not None:
            raise InputError("give either --lens or --focal: the lens sets its own focal length")
        if getattr(args, "loaded_lens", None) is None:
            from ..lens.library import load_lens

            args.loaded_lens = load_lens(args.lens, lenient=args.lenient)
        return args.loaded_lens
    if getattr(args, "zoom", None) is not None:
        raise InputError("--zoom takes a zoom lens: give it with --lens NAME (a thin --focal lens has no zoom)")
    if args.focal is None:
        raise InputError("give the focal length, e.g. --focal 35, or a lens with --lens NAME")
    return None


def _table_options(args) -> dict:
    """The keywords of :func:`physcam.onset.dof_table.dof_table` and ``dof_cells`` the options give (all but
    the stops and marks): the lens or focal length, sensor, CoC, squeeze and zoom."""
    from ._common import coc_of, resolve_sensor

    lens, sensor = _lens_option(args), resolve_sensor(args)
    return dict(focal_length_mm=None if lens is not None else args.focal, lens=lens, sensor=sensor, coc=coc_of(args),
                squeeze=squeeze_of(args, sensor), zoom=getattr(args, "zoom", None))


def _label(m, units) -> str:
    from ..units import format_distance

    return "at hyperfocal" if m == "hyperfocal" else format_distance(math.inf if m == "infinity" else m, units)


def _title(d, units) -> str:
    lens = d["lens"] or f"{d['focal_length_mm']:g} mm"
    s = d["sensor"]
    anamorphic = "; vertical limits (up the frame)" if "near_horizontal_from_film_mm" in d["rows"][0] else ""
    return (f"depth of field: {lens}, {s['name']} ({s['width_mm']:g} x {s['height_mm']:g} mm), CoC "
            f"{d['coc_mm']:.4g} mm ({d['coc_convention']}); from the film plane, in {'feet' if units == 'ft' else 'metres'}"
            f"{anamorphic}")


def grid(d, units, horizontal: bool = False):
    """(row labels, f-stop headers, cells[row][col] = (near, far, total) text) of the table; ``horizontal``:
    an anamorphic's limits across the frame."""
    from ..units import format_distance

    x = "_horizontal" if horizontal else ""
    fs = d["fstops"]
    nm = len(d["focus"])
    cells = []
    for i, m in enumerate(d["focus"]):
        row = []
        for j in range(len(fs)):
            r = d["rows"][j * nm + i]
            far = math.inf if r[f"far{x}_from_film_mm"] is None else r[f"far{x}_from_film_mm"]
            total = math.inf if r[f"total{x}_mm"] is None else r[f"total{x}_mm"]
            row.append((format_distance(r[f"near{x}_from_film_mm"], units), format_distance(far, units),
                        format_distance(total, units)))
        cells.append(row)
    labels = []
    for i, m in enumerate(d["focus"]):
        labels.append(_label(m, units))
    return labels, [f"f/{n:g}" for n in fs], cells


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
        from ._common import mark_repaired

        d = mark_repaired(d, args.loaded_lens)
    for text in d["notes"]:
        from ._common import note

        note(text)
    if args.output:
        card(d, args.output, units=units, force=args.force, chart=_card_chart(args, d["fstops"]), page=args.page)
    if args.json:
        emit_json(document("dof_table", d))
        return 0
    if args.csv:
        print_csv(d["rows"], units=units)
        return 0
    labels, heads, cells = grid(d, units)
    t = Table(_title(d, units), ["focus", *(f"{h} near - far" for h in heads)], justify=["left"] + ["right"] * len(heads))
    for lab, row in zip(labels, cells):
        t.add_row(lab, *(f"{near} - {far}" for near, far, _ in row))
    from ..units import format_distance

    t.add_row("hyperfocal distance", *(format_distance(h["hyperfocal_from_film_mm"], units) for h in d["hyperfocal"]))
    print_table(t)
    if "near_horizontal_from_film_mm" in d["rows"][0]:
        _print_horizontal(d, units, heads, labels)
    t = Table("total depth of field", ["focus", *heads], justify=["left"] + ["right"] * len(heads))
    for lab, row in zip(labels, cells):
        t.add_row(lab, *(total for _, _, total in row))
    print_table(t)
    if args.output:
        print(f"wrote {args.output}")
    return 0


def _print_horizontal(d, units, heads, labels) -> None:
    """An anamorphic's horizontal limits (CoC c / blur aspect across the frame) and the field at each mark."""
    from ..units import format_distance
    from ._output import Table, print_table

    _, _, cells = grid(d, units, horizontal=True)
    aspect = d["dof_aspect"]
    t = Table(f"horizontal (across the frame): squeeze {d['squeeze']:.4g}, a blur {aspect:.3g} as wide as tall, CoC "
              f"{d['coc_mm'] / aspect:.4g} mm", ["focus", *(f"{h} near - far" for h in heads)],
              justify=["left"] + ["right"] * len(heads))
    for lab, row in zip(labels, cells):
        t.add_row(lab, *(f"{near} - {far}" for near, far, _ in row))
    nm = len(labels)
    hyper = [d["rows"][j * nm + nm - 1]["hyperfocal_horizontal_from_film_mm"] for j in range(len(heads))]
    t.add_row("hyperfocal distance", *(format_distance(h, units) for h in hyper))
    print_table(t)
    t = Table("field of view at the mark (desqueezed picture, degrees)", ["focus", "horizontal", "vertical"],
              justify=["left", "right", "right"])
    for lab, r in zip(labels, d["rows"][:nm]):
        t.add_row(lab, f"{r['hfov_deg']:.2f}", f"{r['vfov_deg']:.2f}")
    print_table(t)


def _card_chart(args, fstops):
    """(report, chart data) of the DOF chart under the card's table: the table's ``fstops`` (up to six of them,
    spread from its first to its last: never a stop the table does not have) against focus, every cell a
    cell of the table (:func:`physcam.onset.dof_table.dof_cells` of the same options)."""
    import warnings

    from ..errors import PhysCamWarning
    from ..onset.dof_plot import dof_chart_data
    from ..onset.dof_table import dof_cells

    cell = dof_cells(**_table_options(args))
    marks = [m for m in (args.focus or []) if isinstance(m, float) and math.isfinite(m)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysCamWarning)
        report = cell(fstops[0], marks[len(marks) // 2] if marks else 3000.0)
        stops = list(fstops)
        if len(stops) > CHART_STOPS:
            stops = [stops[round(k * (len(stops) - 1) / (CHART_STOPS - 1))] for k in range(CHART_STOPS)]
        data = dof_chart_data(report, cell, fstops=stops)
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
    across = grid(d, units, horizontal=True)[2] if "near_horizontal_from_film_mm" in d["rows"][0] else None
    nrow, ncol = len(labels) + 2, len(heads) + 1
    page_w, h = PAGES[page]
    chart_in = 0.0 if chart is None else (4.2 if across is None else 3.4)  # an anamorphic's table takes more
    per_row = 0.5 if across is None else 0.8  # an anamorphic's cells take two lines more: the horizontal limits
    table_in = min(h - chart_in - 0.5, max(3.0, per_row * nrow + 0.9))  # taller for long tables, within the page
    fig = new_figure(figsize=(page_w, h))
    top = h - 0.15  # the table and its title from the top of the page, the chart below it
    ax = fig.add_axes((0.03, (top - 0.92 * table_in) / h, 0.94, (0.86 * table_in - 0.25) / h))  # 2 title lines
    if chart is not None:
        from ..onset.dof_plot import draw_dof_chart

        bottom = top - table_in - chart_in + 0.75
        draw_dof_chart(fig.add_axes((0.09, bottom / h, 0.88, (chart_in - 1.1) / h)), *chart, units=units)
    ax.set_axis_off()
    text = [["focus", *heads]]
    for i, (lab, row) in enumerate(zip(labels, cells)):
        text.append([lab, *(f"{near}\n{far}\n({total})" + ("" if across is None else
                                                           f"\n↔ {across[i][j][0]}\n↔ {across[i][j][1]}")
                            for j, (near, far, total) in enumerate(row))])
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
    foot = "each cell: near / far / (total depth of field); physcam dof-table"
    if across is not None:
        foot = (f"each cell: near / far / (total depth of field) up the frame; ↔ near / far across it (anamorphic, "
                f"squeeze {d['squeeze']:.3g}: CoC {d['coc_mm'] / d['dof_aspect']:.4g} mm); physcam dof-table")
    fig.text(0.5, 0.08 / h, foot, ha="center", fontsize=6, color="0.35")
    return fig
