"""``physcam calibrate IMAGES...``: a lens characterized from chart photographs (docs/calibrate.md).

Examples::

  physcam calibrate charts/ --sensor-width 12.8 --sensor-height 9.6 --chart charuco --corners 24x18 \\
      --square 15mm --marker 11mm --dictionary DICT_5X5_250 --focus 2m -o calib/
  physcam calibrate near/ far/ --marks marks.csv --lens zeiss_distagon_35mm_f4 --sensor S35 ... -o calib/ \\
      --usd lenses/distagon35.usda --variant day_20260301

Every option, output and image header is checked before the fit, and everything is computed
before anything is written: a bad image, too few views, a wrong grid or an output that may not be
written leaves the disk as it was. The folder of deliverables is written as a whole
(:func:`physcam.io.staged_folder`: a temporary folder, a manifest, one rename).
"""

from __future__ import annotations

from ._common import (
    FOCUS_HELP,
    add_sensor_options,
    add_units_option,
    distance,
    focus,
    number,
    whole,
)
from ._output import add_output_options, document, emit_json

#: The files written into -o DIR (per focus mark, in a sub-folder when there are several marks)
FILES = {"calibration": "calibration.json", "sheet": "calibration_sheet.png", "brown": "brown_conrady.json",
         "3de4": "3de4_radial_standard_degree_4.txt", "usd": "usd_lens_distortion.json",
         "opentrackio": "opentrackio_lens.json"}


def register(sub) -> None:
    from ..analysis.calibration.names import CHARTS, CHARUCO_DICTIONARY, MAX_IMAGE_PIXELS, parse_corners
    from ..analysis.distortion.names import DEFAULT_MAX_RESIDUAL_PX

    def corners(text):
        import argparse

        from ..errors import InputError

        try:
            return parse_corners(text)
        except InputError as e:
            raise argparse.ArgumentTypeError(str(e)) from None

    p = sub.add_parser("calibrate", help="characterize a lens from chart photographs (pinhole, distortion, "
                                         "breathing, illumination), against its prescription with --lens")
    p.add_argument("images", nargs="+", metavar="IMAGE", help="chart photographs, or folders of them")
    add_sensor_options(p)
    p.add_argument("--chart", choices=CHARTS, default="checkerboard", help="the chart (default checkerboard)")
    p.add_argument("--corners", type=corners, required=True, metavar="CxR",
                   help="checkerboard: inner corners, e.g. 9x6; charuco: squares, e.g. 12x9")
    p.add_argument("--square", type=distance("chart square"), required=True, metavar="SIZE",
                   help="the side of a square, with units, e.g. 25mm")
    p.add_argument("--marker", type=distance("ChArUco marker"), default=None, metavar="SIZE",
                   help="the side of a ChArUco marker (default 3/4 of a square)")
    p.add_argument("--dictionary", default=CHARUCO_DICTIONARY, metavar="NAME",
                   help=f"the ChArUco board's ArUco dictionary (default {CHARUCO_DICTIONARY})")
    p.add_argument("--focus", type=focus("focus mark"), default=None, metavar="MARK",
                   help=f"the focus mark every image was shot at ({FOCUS_HELP}; hyperfocal needs --lens)")
    p.add_argument("--marks", default=None, metavar="FILE.csv",
                   help="a CSV of image,mark (a header line 'image,mark'; marks as --focus reads them) for "
                        "images shot at several marks: breathing")
    p.add_argument("--lens", default=None, metavar="NAME_OR_FILE",
                   help="compare every figure with physcam's prediction for this lens (bundled name or file)")
    p.add_argument("--fstop", type=number("f-stop", positive=True), default=None, metavar="N",
                   help="the stop the flat fields were shot at (for --lens; default wide open)")
    p.add_argument("--flat", action="append", default=None, metavar="FRAME",
                   help="a flat-field frame (repeat): relative illumination against image height")
    p.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="folder for the deliverables, written as a whole (new, empty, or with --force one physcam "
                        "wrote)")
    p.add_argument("--usd", default=None, metavar="LENS.usda",
                   help="the lens's USD file: add the day's characterization variant, 'current' moved to it")
    p.add_argument("--variant", default=None, metavar="NAME", help="the variant's name (default calibration_DATE)")
    p.add_argument("--bootstrap", type=whole("bootstrap", lo=0), default=30, metavar="N",
                   help="refits over resampled views for the uncertainty (default 30; 3 to 1000, or 0: OpenCV's "
                        "covariance for f and the principal point, the field's not estimated)")
    p.add_argument("--max-pixels", type=whole("largest image", lo=1), default=MAX_IMAGE_PIXELS, metavar="N",
                   help=f"refuse an image (chart or flat) of more pixels, read from its header before decoding "
                        f"(default {MAX_IMAGE_PIXELS:,})")
    p.add_argument("--max-residual", type=number("allowed residual", positive=True),
                   default=DEFAULT_MAX_RESIDUAL_PX, metavar="PX",
                   help=f"largest residual a fit may have to be called good (default {DEFAULT_MAX_RESIDUAL_PX:g} px)")
    p.add_argument("--force", action="store_true",
                   help="replace the deliverables folder (only one physcam wrote, or an empty one)")
    add_output_options(p, what="the calibration")
    add_units_option(p)
    p.set_defaults(handler=run_calibrate)


def _read_marks(path, args) -> dict:
    """image path (as written) -> mark mm, from a CSV of image,mark; an image given two different marks
    is refused (naming both lines)."""
    import argparse
    import csv
    from pathlib import Path

    from ..errors import InputError

    one = focus("focus mark")
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such marks file")
    out, where = {}, {}
    with p.open(newline="", encoding="utf-8") as f:
        for n, row in enumerate(csv.reader(f), 1):
            if not row or (n == 1 and row[0].strip().lower() == "image"):
                continue
            if len(row) != 2:
                raise InputError(f"{p}, line {n}: give image,mark (two cells), got {len(row)}")
            try:
                mark = one(row[1])
            except argparse.ArgumentTypeError as e:  # it carries the sentence
                raise InputError(f"{p}, line {n}: {e}") from None
            key = str(Path(row[0].strip()))
            if key in out and out[key] != mark:
                raise InputError(f"{p}, line {n}: {key} is given the mark {row[1].strip()!r}, line {where[key]} gave "
                                 "it another: give each image one mark")
            out[key], where[key] = mark, n
    if not out:
        raise InputError(f"{p}: no image,mark rows")
    return out


def _views(args, lens):
    from pathlib import Path

    from ..analysis.calibration.chart import ChartSpec, detect_views, image_files
    from ..errors import InputError
    from ._calibrate_files import sensor_of
    from ._common import resolve_focus

    if args.focus is not None and args.marks is not None:
        raise InputError("give --focus MARK (every image) or --marks FILE.csv (each image's), not both")
    if args.chart == "checkerboard" and args.marker is not None:
        raise InputError("--marker is the size of a ChArUco board's markers: a checkerboard has none")
    chart = ChartSpec(args.chart, args.corners, args.square, args.marker, args.dictionary)
    paths = image_files(args.images)
    if args.marks is not None:
        table = _read_marks(args.marks, args)
        marks = []
        for p in paths:
            by_path, by_name = table.get(str(Path(p))), table.get(Path(p).name)
            if by_path is not None and by_name is not None and by_path != by_name:
                raise InputError(f"{p}: {args.marks} gives it one mark by its path and another by its file name "
                                 f"{Path(p).name}: give each image one mark")
            m = by_path if by_path is not None else by_name
            if m is None:
                raise InputError(f"{p}: not in {args.marks} (give every image a mark)")
            marks.append(m)
    else:
        marks = [args.focus] * len(paths)
    sensor = sensor_of(args)
    marks = [None if m is None else resolve_focus(m, lens=lens, sensor=sensor, args=args) for m in marks]
    return detect_views(paths, chart, marks, max_pixels=args.max_pixels)


def compute(args):
    """The calibration of the command line (nothing written)."""
    from ..analysis.calibration.calibrate import calibrate_views
    from ._calibrate_files import sensor_of

    lens = None
    if args.lens is not None:
        from ..lens.library import load_lens

        lens = load_lens(args.lens)
    args.loaded_lens = lens
    views = _views(args, lens)
    s = sensor_of(args)
    name = lens.name if lens is not None else "measured"
    cal = calibrate_views(views, (s.width_mm, s.height_mm), lens_name=name, bootstrap=args.bootstrap,
                          max_residual_px=args.max_residual)
    if args.flat:
        from ..analysis.calibration.flat_field import measure_illumination

        m = cal.marks[0]
        cal.illumination = measure_illumination(args.flat, m.size_px, m.sensor_mm, m.principal_point_px,
                                                max_pixels=args.max_pixels)
    if lens is not None:
        from ..analysis.calibration.compare import compare_with_lens

        cal.comparison = compare_with_lens(cal, lens, fstop=args.fstop)
    return cal, lens


def run_calibrate(args) -> int:
    from ._calibrate_files import UNITS, check_outputs, deliverables, write_all

    plan = check_outputs(args)  # every option, output and image header before the fit
    cal, _lens = compute(args)
    payload, usd = deliverables(cal, args, plan)
    written = write_all(payload, usd, cal, args, plan)
    d = cal.to_dict()
    d["written"] = [str(p) for p in written]
    if args.json:
        emit_json(document("calibrate", d, units=UNITS))
        return 0
    _print(cal, written, args)
    return 0





def _print(cal, written, args) -> None:
    from ..units import format_distance
    from ._common import units_of

    for m in cal.marks:
        where = "focus not given" if m.mark_mm is None else f"focus {format_distance(m.mark_mm, units_of(args))}"
        u = m.uncertainty or {}
        fs = (u.get("focal_length_mm") or {}).get("y")
        good, why = m.verdict
        print(f"{cal.lens_name}, {where}: {len(m.views)} views, pinhole f {m.focal_length_mm[1]:.4f} mm "
              f"({'uncertainty not estimated' if fs is None else f'+- {fs:.4f}'}), principal point ({m.principal_point_px[0]:.2f}, {m.principal_point_px[1]:.2f}) px, "
              f"residual {m.rms_px:.3f} px RMS: {'good' if good else 'NOT good: ' + '; '.join(why)}")
        for f in m.fits:
            print(f"  {f.model}: residual RMS {f.rms_residual_px:.3f} px, max {f.max_residual_px:.3f} px: "
                  f"{'good' if f.acceptable else 'NOT good'}")
    for r in cal.breathing:
        print(f"  breathing at {format_distance(r.mark_mm, units_of(args))}: {r.change_pct:+.3f} % "
              f"(+- {r.change_std_pct:.3f})")
    if cal.comparison is not None:
        c = cal.comparison
        print(f"against {c.lens_name}: {'agrees' if c.agrees else 'does NOT agree'} within {c.k:g} standard "
              "uncertainties")
        for r in c.rows:
            print(f"  {r['figure']}: measured {r['measured']:.5g}, predicted {r['predicted']:.5g} {r['unit']} "
                  f"(+- {r['std']:.2g}): {'agrees' if r['agrees'] else 'DIFFERS'}")
    for p in written:
        print(f"wrote {p}")
