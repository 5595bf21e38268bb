"""``physcam lens zoom`` and the ``--zoom`` option of the commands that take a lens (docs/zoom.md).

Examples::

  physcam lens zoom --lens nikon_af_s_70_200mm_f2_8e_zoom
  physcam lens zoom --lens canon_ef_70_200mm_f2_8_zoom --json
  physcam lens zoom --lens laikin_zoom_15_150mm -o laikin_zoom.png
  physcam lens show --lens nikon_af_s_70_200mm_f2_8e_zoom --zoom 135mm

A zoom position is a focal length with its unit (``135mm``: the paraxial EFL at infinity focus,
solved along the cams) or the normalised zoom encoder value 0..1 (0 the first tabulated position).
"""

from __future__ import annotations

ZOOM_HELP = ("zoom position of a zoom lens: a focal length with its unit (135mm, the paraxial EFL) or the "
             "normalised encoder value 0..1 (default: the first tabulated position)")


def add_zoom_option(parser) -> None:
    """The ``--zoom`` option of a command that takes a lens."""
    parser.add_argument("--zoom", default=None, metavar="POSITION", help=ZOOM_HELP)


def zoomed(lens, args):
    """``lens`` at ``args.zoom`` (unchanged without one); notes the encoder value on ``args``."""
    zoom = getattr(args, "zoom", None)
    if zoom is None:
        return lens
    from ..optics.zoom import zoom_encoder
    from ..lens.zoom import prescription_at

    u = zoom_encoder(lens, zoom, wavelength_nm=getattr(args, "wavelength", None))
    args.zoom_encoder = u
    return prescription_at(lens, u)


def zoom_info(args, lens) -> dict | None:
    """The ``zoom`` block of a JSON document: the position asked for, its encoder value and EFL."""
    if getattr(args, "zoom_encoder", None) is None:
        return None
    from ..optics import paraxial

    return {"asked": str(args.zoom), "encoder": args.zoom_encoder, "efl_mm": paraxial.gaussian(lens).efl}


def at_zoom_named(lens, args):
    """``lens`` at ``--zoom`` for a command whose outputs carry the lens's name (ST-map headers, cards, tables):
    :func:`physcam.optics.zoom.named_at_zoom`, and ``args.zoom_block`` the JSON ``zoom`` block (None without
    --zoom). A prime given --zoom is refused (InputError)."""
    zoom = getattr(args, "zoom", None)
    args.zoom_block = None
    if zoom is None:
        return lens
    from ..optics.zoom import named_at_zoom

    q, args.zoom_block = named_at_zoom(lens, zoom, wavelength_nm=getattr(args, "wavelength", None))
    args.zoom_encoder = args.zoom_block["encoder"]
    return q


def register_zoom(lsub, add_lens_argument, add_sensor_options, add_output_options, number) -> None:
    """``physcam lens zoom``'s parser."""
    from ._common import figure_file

    z = lsub.add_parser("zoom", help="a zoom lens across its range: EFL, f-number, entrance pupil, back focus and the "
                                     "image-plane shift (parfocality) at every position; breathing over zoom x focus",
                        description="One row per zoom position (default: the tabulated positions and the midpoints "
                                    "between them, where interpolated cams stray most), at infinity focus with the "
                                    "stop full open (docs/zoom.md).")
    add_lens_argument(z)
    z.add_argument("--positions", nargs="+", default=None, metavar="POSITION",
                   help="zoom positions to tabulate instead: focal lengths (135mm) or encoder values 0..1")
    z.add_argument("--steps", type=number("steps"), default=None, metavar="N",
                   help="instead: N evenly spaced encoder values from 0 to 1")
    z.add_argument("--wavelength", type=number("wavelength"), default=None, metavar="NM",
                   help="wavelength in nm (default: the lens's design wavelength)")
    add_sensor_options(z)
    z.add_argument("-o", "--output", default=None, metavar="FILE", type=figure_file,
                   help="also draw breathing (field of view over focus at each tabulated position) and parfocality "
                        "(image-plane shift over the zoom) to this file (.png, .svg, .pdf)")
    z.add_argument("--force", action="store_true", help="overwrite an existing figure")
    add_output_options(z, csv=True, what="the zoom table")
    z.set_defaults(handler=run_zoom)


def _encoders(args, lens):
    from ..errors import InputError

    if args.positions is not None and args.steps is not None:
        raise InputError("give --positions or --steps, not both")
    if args.steps is not None:
        n = args.steps
        if not (2 <= n <= 1001 and n == int(n)):  # NaN and inf fail the range first
            raise InputError(f"--steps takes a whole number from 2 to 1001, got {n:g}")
        return [k / (int(n) - 1) for k in range(int(n))]
    return args.positions


def run_zoom(args) -> int:
    from ..lens.library import load_lens
    from ..optics.zoom import zoom_table
    from ._common import resolve_sensor
    from ._output import Table, document, emit_json, print_csv, print_table

    lens = load_lens(args.lens)
    if lens.zoom is None:
        from ..errors import InputError

        raise InputError(f"lens {lens.name!r} is not a zoom lens (its file has no zoom table; docs/zoom.md)")
    sensor = resolve_sensor(args)
    rows = zoom_table(lens, _encoders(args, lens), sensor_width_mm=sensor.width_mm, wavelength_nm=args.wavelength)
    path = None
    if args.output:
        from ..analysis.framing.zoom_plot import save_zoom_figure

        path = save_zoom_figure(lens, args.output, sensor_width_mm=sensor.width_mm, force=args.force)
    if args.json:
        emit_json(document("lens_zoom", {"lens": lens.name, "sensor": sensor.name, "sensor_width_mm": sensor.width_mm,
                                         "positions": lens.zoom.positions, "rows": [r.to_dict() for r in rows],
                                         "figure": None if path is None else str(path)}))
        return 0
    if args.csv:
        print_csv([r.to_dict() for r in rows])
        return 0
    t = Table(f"{lens.name}: across the zoom (infinity focus, stop full open; {sensor.name} for the field)",
              ("encoder", "EFL (mm)", "stated (mm)", "f-number", "entrance pupil dia. (mm)",
               "pupil from front vertex (mm)", "pupil in front of film (mm)", "BFL (mm)", "film at (mm)",
               "image shift (mm)", "HFOV (deg)"), justify=["right"] * 11)
    for r in rows:
        t.add_row(f"{r.encoder:.3f}{'' if r.tabulated else ' ~'}", f"{r.efl_mm:.3f}",
                  "" if r.stated_focal_length_mm is None else f"{r.stated_focal_length_mm:g}", f"{r.f_number:.3f}",
                  f"{r.entrance_pupil_diameter_mm:.2f}", f"{r.entrance_pupil_from_front_vertex_mm:.2f}",
                  f"{r.entrance_pupil_from_film_mm:.2f}", f"{r.bfl_mm:.3f}", f"{r.film_distance_mm:.3f}",
                  f"{r.image_shift_mm:+.3f}", f"{r.hfov_deg:.2f}")
    print_table(t)
    print("~: between tabulated positions, on the interpolated cams. image shift: paraxial image of infinity minus "
          "the film plane (+ behind the film)")
    if path is not None:
        print(f"wrote {path}")
    return 0
