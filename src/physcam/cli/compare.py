"""``physcam compare --lens LENS_A --lens LENS_B ...``: lenses side by side (field of view, depth of field,
breathing, distortion, illumination, bokeh) in one table and one figure; ``physcam compare
blender``: the same point light through physcam's tracer and through Cycles."""

from __future__ import annotations

import argparse
import math
import sys

from ..figures import styled
from ._common import (FOCUS_HELP, FOLDER_FORCE_HELP, add_lens_argument, add_sensor_options, add_units_option, distance,
                      focus, number, whole, figure_file)

EPILOG = """\
example:
  physcam compare blender --lens dgauss_50mm --focus 2m --fstop 2.8 --light 0.7m --blades 6 -o cmp/
Writes cmp/compare.png (the two images side by side) and cmp/compare.json (the measured table).
Blender: --blender-python PATH (a Python with bpy, or a blender executable), else $PHYSCAM_BLENDER_PYTHON, else
the user config's blender_python, else `blender` on PATH, else a source checkout's .venv-blender (make blender).
"""

LENSES_EPILOG = """\
examples:
  physcam compare --lens dgauss_50mm --lens sonnar_50mm_f1_5 --lens tessar_50mm_f2_8 --focus 2m --fstop 2.8 --sensor S35
  physcam compare --lens zeiss_distagon_35mm_f4 --lens zuiko_18mm_f3_5 --focus hyperfocal --fstop 5.6 -o compare.png --units ft
  physcam compare --lens dgauss_50mm --lens canon_rf_85mm_f1_2 --focus 3m --csv
Each lens is measured alike: the lens report at the focus and f-stop (fields of view, depth of field),
the breathing table (field of view from infinity to the focus and to the closest focus), real
distortion and relative illumination at the widest field the sensor asks for (clamped to what the lens
images) and the bokeh of a point light on the axis at twice the focus distance (1 m when focused at
infinity). A lens slower than --fstop is compared wide open, with a note.
"""


class _LensesByDefault(argparse._SubParsersAction):
    """``physcam compare A B ...`` (the old spelling) means ``physcam compare lenses A B ...``; ``compare blender``
    stays. ``physcam compare --lens A --lens B`` is routed to ``lenses`` by :func:`physcam.cli.main`."""

    class _AnyName(dict):
        accept_any = False  # set once the subcommands are added (add_parser checks for duplicates)

        def __contains__(self, key):  # then any first word is accepted: a lens name goes to `lenses`
            return self.accept_any or dict.__contains__(self, key)

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._name_parser_map = self._AnyName()
        self.choices = self._name_parser_map

    def __call__(self, parser, namespace, values, option_string=None):
        if values and not dict.__contains__(self._name_parser_map, values[0]):
            values = ["lenses", *values]
        super().__call__(parser, namespace, values, option_string)


def register(sub) -> None:
    p = sub.add_parser("compare", help="lenses side by side (FOV, DOF, breathing, distortion, illumination, bokeh), "
                                       "or physcam against a renderer (compare blender)",
                       description="Compare lenses side by side (`physcam compare --lens LENS_A --lens LENS_B ...`), "
                                   "or render one point light through physcam's OSL camera in Blender and trace it "
                                   "with physcam (`physcam compare blender --lens LENS`, docs/blender.md).",
                       epilog=LENSES_EPILOG + EPILOG,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    s = p.add_subparsers(dest="compare_command", metavar="--lens A --lens B ... | blender", action=_LensesByDefault)
    _register_lenses(s)
    b = s.add_parser("blender", help="Cycles through physcam's OSL lens camera", epilog=EPILOG,
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    add_lens_argument(b)
    b.add_argument("--focus", type=focus("focus distance", allow_inf=False), required=True, metavar="D",
                   help="focus mark from the film plane (e.g. 2m; or hyperfocal at --fstop)")
    b.add_argument("--fstop", type=number("f-number", positive=True), required=True, metavar="N", help="f-number")
    b.add_argument("--light", type=distance("light distance"), required=True, metavar="D",
                   help="the point light's distance from the film plane, on the axis (e.g. 0.7m)")
    b.add_argument("--blades", type=whole("blade count", lo=0), default=0, metavar="N", help="iris blades (0: round; 3 or more: a polygon)")
    b.add_argument("--blade-angle", type=number("blade angle"), default=0.0, metavar="DEG",
                   help="angle of the first iris corner, degrees")
    b.add_argument("--crop", type=distance("crop"), default=3.0, metavar="MM",
                   help="width of the film crop around the axis that both images cover (default 3 mm)")
    b.add_argument("--pixels", type=whole("pixels", lo=0), default=128, help="image width and height in pixels (32 to 1024)")
    b.add_argument("--samples", type=whole("samples", lo=0), default=512, help="Cycles samples per pixel (default 512)")
    b.add_argument("--blender-python", metavar="PATH",
                   help="a Python with Blender's bpy (default: $PHYSCAM_BLENDER_PYTHON or ./.venv-blender)")
    b.add_argument("--lenient", action="store_true", help="load a lens file that is not buildable as written, repaired")
    b.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="folder for compare.png and compare.json (written whole, with a physcam-manifest.json)")
    b.add_argument("--force", action="store_true", help=FOLDER_FORCE_HELP)
    from ._output import add_output_options

    add_output_options(b, what="the measured table")
    add_units_option(b)
    b.set_defaults(handler=run_blender, output_folders=("output",))
    p.set_defaults(handler=lambda args: (p.print_help(), 0)[1])
    s._name_parser_map.accept_any = True


def run_blender(args) -> int:
    import json
    from pathlib import Path

    from ..errors import InputError
    from ..export.blender_compare import compare_bokeh
    from ..io import atomic_write
    from ..lens.library import load_lens
    from ..trace.aperture import Aperture
    from ._common import output_folder

    out = Path(args.output)
    png, js = out / "compare.png", out / "compare.json"
    if not (args.blades == 0 or 3 <= args.blades <= 64):
        raise InputError(f"--blades must be 0 (round) or 3 to 64, got {args.blades}")
    aperture = Aperture(args.blades, args.blade_angle) if args.blades else None
    lens = load_lens(args.lens, lenient=args.lenient)
    from ._common import resolve_focus

    args.focus = resolve_focus(args.focus, lens=lens, fstop=args.fstop, args=args)
    from ..optics.state import camera_state

    state = camera_state(lens, focus_mm=args.focus, fstop=args.fstop, aperture=aperture)
    from ._common import units_of

    with output_folder(out, force=args.force, command="compare blender") as tmp:  # the folder is written whole
        res = compare_bokeh(state, light_mm=args.light,
                            crop_mm=args.crop, pixels=args.pixels, samples=args.samples,
                            blender_python=args.blender_python, config_blender=_config_blender())
        table = {k: v for k, v in res.items() if k != "images"}
        atomic_write(tmp / js.name, json.dumps(table, indent=2, allow_nan=False) + "\n")
        _figure(res, tmp / png.name, units=units_of(args))
    if args.json:
        from ._output import document, emit_json

        emit_json(document("compare_blender", dict(table, files=[str(png), str(js)])))
        return 0
    from ..units import format_distance
    from ._common import units_of

    u = units_of(args)
    m = table["measured"]
    d = m["equivalent_diameter_mm"]
    print(f"{res['lens']}: light {format_distance(res['light_from_film_mm'], u)} from the film, focus "
          f"{format_distance(res['focus_from_film_mm'], u)}, f/{res['fstop']:g}")
    print(f"  bokeh diameter: Cycles {d['cycles']:.4f} mm, physcam {d['physcam']:.4f} mm, ratio {d['ratio']:.4f}")
    if "corners" in m:
        print(f"  iris corners: Cycles {m['corners']['cycles']}, physcam {m['corners']['physcam']}")
    print(f"  rendered by {res['blender']}")
    print(f"wrote {png} and {js}")
    return 0


@styled
def _figure(res, path=None, *, force=False, units="m"):
    """physcam's and Cycles' bokeh side by side; the light and focus distances in the title in ``units``
    (m, or ft for feet and inches; film coordinates stay in mm). Saved to ``path``, or the Figure."""
    import numpy as np

    from ..figures import save_figure, subplots
    from ..units import format_distance

    fig, axes = subplots(1, 2, figsize=(7.4, 3.8))
    h = res["crop_mm"] / 2
    for ax, key, title in zip(axes, ("physcam", "cycles"), ("physcam (numba tracer)", "Cycles (OSL camera)")):
        img = res["images"][key]
        top = float(np.percentile(img[img > 0], 90)) if (img > 0).any() else 1.0  # render noise: not the max
        ax.imshow(np.clip(img / top, 0, 1), origin="lower", extent=(-h, h, -h, h), cmap="magma")
        d = res["measured"]["equivalent_diameter_mm"][key]
        ax.set_title(f"{title}\nequivalent diameter {d:.4f} mm", fontsize=9)
        ax.set_xlabel("film x (mm)")
    for ax in axes:
        ax.set_ylabel("film y (mm)")
    fig.suptitle(f"{res['lens']}: light {format_distance(res['light_from_film_mm'], units)}, focus "
                 f"{format_distance(res['focus_from_film_mm'], units)}, f/{res['fstop']:g}", fontsize=10)
    return fig if path is None else save_figure(fig, path, force=force)


# ---- physcam compare --lens LENS_A --lens LENS_B --lens ... ------------------------------------------------------------
def _register_lenses(s) -> None:
    from ._output import add_output_options
    from ._common import add_lenient
    from .report import add_coc_option

    c = s.add_parser("lenses", help="lenses side by side: FOV, DOF, breathing, distortion, illumination, bokeh "
                                    "(the default: `physcam compare --lens A --lens B` is `physcam compare lenses --lens A --lens B`)",
                     epilog=LENSES_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_lens_argument(c, dest="lenses", many=True, metavar="LENS", help="bundled lens names (see `physcam lenses`) or lens files")
    c.add_argument("--focus", type=focus("focus distance"), default=2000.0, metavar="D",
                   help=f"focus mark from the film plane for every lens (default 2m; {FOCUS_HELP})")
    c.add_argument("--fstop", type=number("f-stop", positive=True), default=None, metavar="N",
                   help="f-stop for every lens (default: each wide open; a slower lens stays wide open, with a note)")
    add_sensor_options(c)
    add_coc_option(c)
    c.add_argument("--light", type=distance("light distance"), default=None, metavar="D",
                   help="the bokeh light's distance from the film (default twice the focus; 1m at infinity focus)")
    c.add_argument("--rays", type=whole("rays", lo=0), default=100_000, metavar="N",
                   help="rays per bokeh image (1000 to 1e7; default 100000)")
    add_lenient(c)
    add_units_option(c)
    add_output_options(c, csv=True, what="the comparison")
    c.add_argument("-o", "--output", metavar="FIGURE", type=figure_file, help="draw the comparison figure (.png, .svg or .pdf)")
    c.add_argument("--force", action="store_true", help="overwrite an existing figure")
    c.set_defaults(handler=run_lenses)


def measure_lens(lens, *, focus_mm, fstop, sensor, coc, light_mm, rays, units="m"):
    """Everything ``physcam compare`` shows of one lens, as a flat dict (lengths mm, angles degrees),
    with the curves for the figure under ``_curves``; the warnings of its analyses become its notes."""
    import warnings

    from ..errors import PhysCamWarning

    with warnings.catch_warnings(record=True) as caught:  # warnings become this lens's notes
        warnings.simplefilter("always", PhysCamWarning)
        out = _measure(lens, focus_mm=focus_mm, fstop=fstop, sensor=sensor, coc=coc, light_mm=light_mm, rays=rays)
    out["notes"] += list(dict.fromkeys(str(w.message) for w in caught if issubclass(w.category, PhysCamWarning)))
    return out


def _measure(lens, *, focus_mm, fstop, sensor, coc, light_mm, rays):
    """physcam.onset.lens_compare's measurements at the command's focus (``hyperfocal`` resolved here,
    with its note)."""
    from ..onset.lens_compare import fstop_for_comparison, lens_measurements
    from ._common import resolve_focus

    n, notes = fstop_for_comparison(lens, fstop)
    mark = resolve_focus(focus_mm, lens=lens, fstop=n, sensor=sensor, coc=coc)
    out = lens_measurements(lens, focus_mm=mark, fstop=n, sensor=sensor, coc=coc, light_mm=light_mm, rays=rays)
    out["notes"] = notes + out["notes"]
    return out


#: (key, label, kind) of the comparison table's rows; kind: "dist" (a scene distance), or a format.
ROWS = [
    ("efl_mm", "EFL (mm)", "{:.2f}"), ("fstop", "f-stop", "f/{:.3g}"), ("focus_from_film_mm", "focus", "dist"),
    ("hfov_deg", "HFOV at focus (deg)", "{:.2f}"), ("vfov_deg", "VFOV at focus (deg)", "{:.2f}"),
    ("dfov_deg", "DFOV at focus (deg)", "{:.2f}"), ("hfov_real_deg", "HFOV real rays (deg)", "{:.2f}"),
    ("near_from_film_mm", "near limit", "dist"), ("far_from_film_mm", "far limit", "dist"),
    ("dof_total_mm", "depth of field", "dist"), ("hyperfocal_from_film_mm", "hyperfocal", "dist"),
    ("breathing_at_focus_pct", "HFOV change from ∞ to focus (%)", "{:+.2f}"),
    ("breathing_closest_pct", "HFOV change from ∞ to near mark (%)", "{:+.2f}"),
    ("breathing_near_mm", "  near mark", "dist"),
    ("closest_focus_mm", "closest focus", "close"),
    ("distortion_pct", "distortion at widest field (%)", "{:+.2f}"),
    ("distortion_field_deg", "  at field (deg)", "{:.2f}"),
    ("illumination_corner", "relative illumination at corner", "{:.3f}"),
    ("illumination_corner_stops", "  corner falloff (stops)", "{:.2f}"),
    ("bokeh_diameter_mm", "bokeh diameter (mm, on film)", "{:.3f}"),
    ("bokeh_light_from_film_mm", "  of a light at", "dist"),
    ("entrance_pupil_from_film_mm", "entrance pupil from film (mm)", "{:.1f}"),
]


def _cell(v, kind, units) -> str:
    from ..units import format_distance

    if kind == "dist":
        return format_distance(math.inf if v is None else v, units)
    if kind == "close":  # (mark, source, MOD): a unit-focusing lens's 1:1 limit is not a close focus it has
        mark, source, mod = v
        if source == "maker" and mod is not None:  # the maker's figure, even where the focus model stops short
            return format_distance(mod, units) + (" (MOD)" if mod >= mark else
                                                  f" (MOD; beyond the focus model, which reaches {format_distance(mark, units)})")
        return format_distance(mark, units) + {"maker": " (MOD)", "focus groups": " (focus groups)"}.get(
            source, " (unit focusing limit, not the lens's MOD)")
    return "-" if v is None else kind.format(v)


def run_lenses(args) -> int:
    from ..errors import InputError
    from ..io import check_writable
    from ..lens.library import load_lens
    from ._common import coc_of, resolve_sensor, units_of
    from ._output import Table, document, emit_json, print_csv, print_table

    if len(args.lenses) > 8:
        raise InputError(f"compare takes up to 8 lenses, got {len(args.lenses)}")
    if not 1000 <= args.rays <= 10**7:
        raise InputError(f"--rays must lie in 1000..1e7, got {args.rays}")
    if args.output:
        check_writable(args.output, force=args.force)
    sensor = resolve_sensor(args)
    units = units_of(args)
    lenses = [load_lens(name, lenient=args.lenient) for name in args.lenses]
    rows = [measure_lens(lens, focus_mm=args.focus, fstop=args.fstop, sensor=sensor, coc=coc_of(args),
                         light_mm=args.light, rays=args.rays) for lens in lenses]
    curves = [r.pop("_curves") for r in rows]
    for name, r in zip(args.lenses, rows):
        r["name"] = name
    if args.output and (args.json or args.csv):  # a pipeline's document follows the file it names
        compare_figure(rows, curves, args.output, sensor=sensor, units=units, force=args.force)
    d = {"sensor": {"name": sensor.name, "width_mm": sensor.width_mm, "height_mm": sensor.height_mm},
         "focus": args.focus if isinstance(args.focus, str) else (None if math.isinf(args.focus) else args.focus),
         "fstop": args.fstop, "lenses": rows,
         "definition": "each lens at the same focus mark and f-stop (wide open when slower) on the same sensor; "
                       "distances from the film plane; distortion and illumination at the widest field measured "
                       "(Y meridian); bokeh: equivalent diameter of a point light on the axis"}
    if args.json:
        emit_json(document("compare", d))
        return 0
    if args.csv:
        print_csv(rows, units=units)
        return 0
    t = Table(f"lenses compared on {sensor.name} ({sensor.width_mm:g} x {sensor.height_mm:g} mm)",
              ["", *args.lenses], justify=["left"] + ["right"] * len(rows))
    for key, label, kind in ROWS:
        t.add_row(label, *(_cell((r[key], r["closest_focus_source"], r["minimum_object_distance_mm"]) if kind == "close" else r[key], kind, units)
                           for r in rows))
    print_table(t)
    for name, r in zip(args.lenses, rows):
        for n in r["notes"]:
            print(f"note: {name}: {n}")
    if args.output:  # the table is read while the figure is drawn (the figure is most of a cold run's time)
        sys.stdout.flush()
        compare_figure(rows, curves, args.output, sensor=sensor, units=units, force=args.force)
        print(f"wrote {args.output}")
    return 0


#: Most bokeh panels in one row of the comparison figure; more lenses take a second row.
BOKEH_PER_ROW = 4
#: Most lenses whose curves each carry their own legend; more share one legend beside the curves.
LEGENDS_UP_TO = 3


@styled
def compare_figure(rows, curves, path=None, *, sensor, units="m", force=False, dpi=None):
    """One figure: breathing, distortion and illumination curves of every lens, and their bokeh (all at one
    film scale, the widest image's, so that their sizes compare at a glance; up to :data:`BOKEH_PER_ROW` a
    row); the focus and light distances in the title and the breathing axis (1 / mark) in ``units`` (m, or
    ft for feet and inches; film coordinates and bokeh sizes stay in mm). Saved to ``path``, or the Figure.

    ``dpi``: the figure's own, at which it is laid out (default matplotlib's for a returned Figure; for a
    file, the dpi it is saved at, :data:`physcam.figures.SAVE_DPI`: the layout's text metrics are then the
    drawing's, measured once, issue 47 round 21)."""
    from ..figures import SAVE_DPI, new_figure, save_figure
    from ..units import format_distance

    n = len(rows)
    per_row = n if n <= BOKEH_PER_ROW else math.ceil(n / 2)
    bokeh_rows = math.ceil(n / per_row)
    cols = math.lcm(3, per_row)  # the curves take a third each, the bokeh panels an equal share each
    fig = new_figure(figsize=(11.0, 7.0 + 2.6 * (bokeh_rows - 1)),
                     dpi=dpi if dpi is not None or path is None else SAVE_DPI)
    gs = fig.add_gridspec(1 + bokeh_rows, cols)
    _curve_panels(fig, [gs[0, j * cols // 3: (j + 1) * cols // 3] for j in range(3)], rows, curves, units)
    span = cols // per_row
    _bokeh_panels(fig, [gs[1 + k // per_row, (k % per_row) * span: (k % per_row + 1) * span] for k in range(n)],
                  rows, curves)
    r0 = rows[0]
    focus = format_distance(math.inf if r0["focus_from_film_mm"] is None else r0["focus_from_film_mm"], units)
    stops = ", ".join(dict.fromkeys(f"f/{r['fstop']:.3g}" for r in rows))
    fig.suptitle(f"focus {focus} ({rows[0]['name']}), {stops}, {sensor.name} ({sensor.width_mm:g} x "
                 f"{sensor.height_mm:g} mm); bokeh: light at {format_distance(r0['bokeh_light_from_film_mm'], units)}",
                 fontsize=9)
    fig.tight_layout()
    return fig if path is None else save_figure(fig, path, force=force)


def _curve_panels(fig, slots, rows, curves, units) -> None:
    """Breathing (against 1 / mark in ``units``), distortion and illumination of every lens, in ``slots``; a
    legend in each, or one beside the three for more than :data:`LEGENDS_UP_TO` lenses."""
    from ..figures import title_y

    ax_b, ax_d, ax_i = (fig.add_subplot(slot) for slot in slots)
    per = 1000.0 if units == "m" else 304.8
    for r, c in zip(rows, curves):
        if "breathing" in c:
            marks, chg = c["breathing"]
            x = [0.0 if math.isinf(m) else per / m for m in marks]
            ax_b.plot(x, chg, marker="o", ms=3, label=r["name"])
        if "distortion" in c:
            ax_d.plot(*c["distortion"], marker="o", ms=2, label=r["name"])
        if "illumination" in c:
            ax_i.plot(*c["illumination"], marker="o", ms=2, label=r["name"])
    ax_b.set_xlabel(f"1 / focus mark (1/{'m' if units == 'm' else 'ft'}; 0 = infinity)")
    ax_b.set_ylabel("HFOV change from infinity (%)")
    ax_b.set_title("focus breathing", fontsize=9, y=title_y(ax_b))  # (placed once where matplotlib would leave it)
    ax_d.set_xlabel("field angle (deg)")
    ax_d.set_ylabel("real distortion (%)")
    ax_d.set_title("distortion", fontsize=9, y=title_y(ax_d))
    ax_i.set_xlabel("field angle (deg)")
    ax_i.set_ylabel("relative illumination")
    ax_i.set_ylim(0, 1.05)
    ax_i.set_title("illumination", fontsize=9, y=title_y(ax_i))
    for ax in (ax_b, ax_d, ax_i):
        ax.grid(True, alpha=0.3)
        if len(rows) <= LEGENDS_UP_TO:
            ax.legend(fontsize=6)
    if len(rows) > LEGENDS_UP_TO:
        handles, labels = ax_b.get_legend_handles_labels()
        if len(labels) < len(rows):  # a lens without breathing still has its colour in the others
            handles, labels = max((a.get_legend_handles_labels() for a in (ax_b, ax_d, ax_i)), key=lambda hl: len(hl[1]))
        ax_i.legend(handles, labels, fontsize=6, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)


def _bokeh_panels(fig, slots, rows, curves) -> None:
    """Each lens's bokeh in its slot, every panel sharing the first's axes at the widest image's half-width
    about the axis; film y labelled on the first panel of each row."""
    import numpy as np

    from ..figures import title_y

    first = None
    for slot, r, c in zip(slots, rows, curves):
        if "bokeh" not in c:
            ax = fig.add_subplot(slot)
            ax.set_axis_off()
            ax.set_title(f"{r['name']}\n(no bokeh)", fontsize=7, y=title_y(ax))
            continue
        ax = fig.add_subplot(slot, **({} if first is None else {"sharex": first, "sharey": first}))
        img, ext = c["bokeh"]
        top = float(np.percentile(img[img > 0], 95)) if (img > 0).any() else 1.0
        ax.imshow(np.clip(img / top, 0, 1), origin="lower", extent=ext, cmap="magma")
        ax.set_facecolor(ax.images[0].cmap(0.0))  # beyond a smaller image's edge: its own dark
        ax.set_title(f"{r['name']}\nbokeh {r['bokeh_diameter_mm']:.3f} mm", fontsize=7, y=title_y(ax))
        ax.set_xlabel("film x (mm)", fontsize=7)
        if first is None or slot.colspan.start == 0:
            ax.set_ylabel("film y (mm)", fontsize=7)
        else:
            ax.tick_params(labelleft=False)
        first = first or ax
        ax.tick_params(labelsize=6)
    if first is not None:
        half = max(abs(v) for c in curves if "bokeh" in c for v in c["bokeh"][1])
        first.set_xlim(-half, half)
        first.set_ylim(-half, half)


def _config_blender():
    from ._config import load_config

    return load_config().blender_python
