"""``physcam distortion LENS``: real distortion, ST-maps and fitted models at any focus (docs/distortion.md).

Examples::

  physcam distortion dgauss_50mm                                  # against field angle, at infinity
  physcam distortion zeiss_distagon_35mm_f4 --focus 2m --sensor "ALEXA 35" --resolution 4608x3164 \\
      --stmap out/ --fit 3de4 --fit brown --fit nuke              # maps, fitted models, a Nuke script
  physcam distortion zuiko_18mm_f3_5 --resolution 2048x1366 --across-focus 0.3m,0.5m,1m,2m,inf
"""

from __future__ import annotations

import math

from ._common import distance, number, print_json
from .lens import mark_repaired

#: Names of the files the fits write into --stmap DIR.
FIT_FILES = {"brown": "brown_conrady.json", "3de4": "3de4_radial_standard_degree_4.txt",
             "usd": "usd_lens_distortion.json", "nuke": "physcam_stmap.nk"}


def _focus_list(text: str):
    """Comma-separated focus marks with units (argparse type)."""
    import argparse

    from ..errors import PhysCamError
    from ..units import parse_distance

    parts = [t.strip() for t in str(text).split(",") if t.strip()]
    if not parts:
        raise argparse.ArgumentTypeError("give focus marks separated by commas, e.g. 0.5m,1m,2m,inf")
    try:
        return [parse_distance(t, name="focus distance", allow_inf=True) for t in parts]
    except PhysCamError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def register(sub) -> None:
    from .analyze import _common, _resolution, _sensor
    from ..analysis.distortion_names import DEFAULT_MAX_RESIDUAL_PX, MODEL_CHOICES

    p = sub.add_parser("distortion", help="real distortion: against field, ST-maps and fitted models at any focus")
    _common(p, "write the distortion plot (field-angle table; with --across-focus the table's plot)")
    p.add_argument("--field", type=number("field angle"), action="append", metavar="DEG",
                   help="field angle in degrees (repeat; default: up to the sensor corner)")
    _sensor(p)
    p.add_argument("--wavelength", type=number("wavelength"), default=None, metavar="NM",
                   help="wavelength in nm (default: the lens's design wavelength, the d line 587.56)")
    p.add_argument("--focus", type=distance("focus distance", allow_inf=True), default=None, metavar="D",
                   help="focus mark from the film plane (e.g. 2m, 6ft; default infinity) for the 2-D field; "
                        "needs --resolution")
    p.add_argument("--resolution", type=_resolution, default=None, metavar="WxH",
                   help="frame size in pixels, e.g. 2048x1366: the full 2-D distortion field at --focus")
    p.add_argument("--stmap", metavar="DIR", default=None,
                   help="write distortion.exr and undistortion.exr (32-bit float ST-maps), PNG previews and the "
                        "files of each --fit into DIR; needs --resolution")
    p.add_argument("--fit", choices=MODEL_CHOICES, action="append", default=None,
                   help="fit a model over the frame (repeat): brown = Brown-Conrady D-U and U-D (OpenTrackIO), "
                        "3de4 = 3DE4 Radial - Standard, Degree 4, usd = Hydra lensDistortion, nuke = a Nuke "
                        "script applying the ST-maps (with --stmap); needs --resolution")
    p.add_argument("--max-residual", type=number("allowed residual", positive=True),
                   default=DEFAULT_MAX_RESIDUAL_PX, metavar="PX",
                   help=f"largest residual in pixels a fit may have to be called good and written "
                        f"(default {DEFAULT_MAX_RESIDUAL_PX:g})")
    p.add_argument("--plate", default="plate.####.exr", metavar="PATH",
                   help="the plate the Nuke script reads (default plate.####.exr)")
    p.add_argument("--across-focus", type=_focus_list, default=None, metavar="LIST",
                   help="a table of distortion across focus marks, e.g. 0.5m,1m,2m,inf; needs --resolution")
    p.set_defaults(handler=run_distortion)


def run_distortion(args) -> int:
    from ..errors import InputError
    from .analyze import _finish, _prepare

    needs = [n for n, v in (("--focus", args.focus), ("--stmap", args.stmap), ("--fit", args.fit),
                            ("--across-focus", args.across_focus)) if v is not None]
    if args.resolution is None and needs:
        raise InputError(f"{', '.join(needs)} need --resolution WxH (the frame size in pixels)")
    if args.across_focus is not None and (args.focus is not None or args.stmap or args.fit):
        raise InputError("--across-focus makes a table of its own focus marks: give it without --focus, --stmap "
                         "and --fit")
    if args.fit and "nuke" in args.fit and args.stmap is None:
        raise InputError("--fit nuke writes a Nuke script beside the ST-maps: give --stmap DIR")
    lens = _prepare(args)
    if args.across_focus is not None:
        return _run_across_focus(args, lens)
    if args.resolution is not None:
        return _run_field(args, lens)
    from ..analysis.distortion import real_distortion

    res = real_distortion(lens, args.field, sensor_width_mm=args.sensor_width, sensor_height_mm=args.sensor_height,
                          wavelength_nm=args.wavelength)
    if not args.json:
        print(f"{res.lens_name}: real distortion at {res.wavelength_nm:g} nm (chief ray vs f tan theta), "
              f"EFL {res.efl_y_mm:.3f} mm")
        print(f"  {'axis':>4} {'field deg':>9} {'real mm':>10} {'f tan mm':>10} {'dist %':>8}")
        for p in res.points:
            print(f"  {p.axis:>4} {p.field_deg:9.3f} {p.real_height_mm:10.4f} {p.paraxial_height_mm:10.4f} "
                  f"{p.distortion_pct:8.3f}")
        f = res.fit
        if f is not None:
            print(f"  standard model: k1 {f.k1:.6f}, k2 {f.k2:.6f} (rho = r / {f.norm_radius_mm:g} mm), "
                  f"max residual {f.max_residual_pct:.4f} %")
        for n in res.notes:
            print(f"  note: {n}")
    _finish(args, res)
    return 0


def _run_across_focus(args, lens) -> int:
    from ..analysis.distortion_focus import distortion_across_focus
    from ..errors import InputError

    if args.field:
        raise InputError("--field is for the field-angle table; --across-focus covers the whole frame")
    tab = distortion_across_focus(lens, args.across_focus, sensor_width_mm=args.sensor_width,
                                  sensor_height_mm=args.sensor_height, width_px=args.resolution[0],
                                  height_px=args.resolution[1], wavelength_nm=args.wavelength)
    if args.output:
        tab.plot(args.output, force=args.force)
    if args.json:
        print_json(mark_repaired(tab.to_dict(), args.loaded_lens))
        return 0
    print(f"{tab.lens_name}: distortion across focus, {tab.sensor_mm[0]:g} x {tab.sensor_mm[1]:g} mm at "
          f"{tab.size_px[0]}x{tab.size_px[1]} px (against the pinhole at each focus)")
    print(f"  {'focus m':>8} {'pinhole mm':>10} {'corner %':>9} {'max px':>7} {'BC k1':>9} {'BC k2':>9} "
          f"{'BC max px':>9} {'3DE c2':>9} {'3DE c4':>9} {'3DE max px':>10}")
    for r in tab.rows:
        f = "inf" if r["focus_from_film_mm"] is None else f"{r['focus_from_film_mm'] / 1000:.3g}"
        b, t = r["brown_du"], r["tde4"]
        print(f"  {f:>8} {r['pinhole_focal_length_mm']:10.3f} {r['corner_distortion_pct']:9.3f} "
              f"{r['max_distortion_px']:7.2f} {b['k1']:9.5f} {b['k2']:9.5f} {b['max_px']:9.3f} "
              f"{t['Distortion - Degree 2']:9.5f} {t['Quartic Distortion - Degree 4']:9.5f} {t['max_px']:10.3f}")
    if args.output:
        print(f"wrote {args.output}")
    return 0


def _fit_payloads(args, res, fits, folder):
    """(path, bytes) of every fit file, after checking each fit may be written."""
    import json
    from pathlib import Path

    from .. import __version__
    from ..analysis.distortion_models import BrownConrady, TDE4RadialStandard, USDStandard
    from ..export.nuke import nuke_stmap_script
    from ..export.tde4 import tde4_lens_text

    d = Path(folder)
    out = []
    brown = [f for f in fits if isinstance(f, BrownConrady)]
    for f in fits:
        f.require_acceptable(FIT_FILES["brown" if f in brown else "3de4" if isinstance(f, TDE4RadialStandard)
                                        else "usd"])
    if brown:
        doc = {"schema": "physcam.distortion.brown_conrady/1", "lens": res.lens_name,
               "opentrackio_lens_distortion": [f.opentrackio() for f in brown],
               "fits": [f.to_dict() for f in brown]}
        out.append((d / FIT_FILES["brown"], json.dumps(doc, indent=2).encode()))
    for f in fits:
        if isinstance(f, TDE4RadialStandard):
            out.append((d / FIT_FILES["3de4"], tde4_lens_text(f, res.lens_name).encode()))
        elif isinstance(f, USDStandard):
            out.append((d / FIT_FILES["usd"], json.dumps(f.to_dict(), indent=2).encode()))
    for f in fits:
        slug = {"D-U": "_du", "U-D": "_ud"}.get(f.direction, "") if isinstance(f, BrownConrady) else ""
        stem = ("brown_conrady" + slug if isinstance(f, BrownConrady)
                else "3de4" if isinstance(f, TDE4RadialStandard) else "usd")
        out.append((d / f"residual_{stem}.png", _png(f)))
    if "nuke" in args.fit:
        w, h = res.size_px
        ox, oy = res.overscan_px
        text = nuke_stmap_script(d.resolve() / "undistortion.exr", d.resolve() / "distortion.exr", plate=args.plate,
                                 plate_size=(w, h), undistorted_size=(w + 2 * ox, h + 2 * oy), version=__version__)
        out.append((d / FIT_FILES["nuke"], text.encode()))
    return out


def _png(fit) -> bytes:
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "r.png"
        fit.plot_residual(p)
        return p.read_bytes()


def _run_field(args, lens) -> int:
    from ..analysis.distortion_models import fit_models, samples_from_field
    from ..analysis.stmap import distortion_field, write_stmaps
    from ..errors import InputError
    from ..io import atomic_write, check_writable

    if args.field:
        raise InputError("--field is for the field-angle table; the 2-D field (--resolution) covers the whole frame")
    if args.output:
        raise InputError("-o draws the field-angle table's plot; with --resolution the maps go to --stmap DIR "
                         "(each EXR with a PNG preview)")
    res = distortion_field(lens, focus_mm=math.inf if args.focus is None else args.focus,
                           sensor_width_mm=args.sensor_width, sensor_height_mm=args.sensor_height,
                           width_px=args.resolution[0], height_px=args.resolution[1], wavelength_nm=args.wavelength,
                           maps=args.stmap is not None)
    fits = fit_models(samples_from_field(res), args.fit or (), max_residual_px=args.max_residual)
    written = []
    if args.stmap is not None:
        payload = _fit_payloads(args, res, fits, args.stmap) if args.fit else []
        for p, _ in payload:  # every name checked before anything is written
            check_writable(p, force=args.force)
        written = write_stmaps(res, args.stmap, force=args.force)
        written += [atomic_write(p, data, force=args.force) for p, data in payload]
    d = res.to_dict()
    d["fits"] = [f.to_dict() for f in fits]
    if args.json:
        d["written"] = [str(p) for p in written]
        print_json(mark_repaired(d, args.loaded_lens))
        return 0
    f = "infinity" if d["focus_from_film_mm"] is None else f"{d['focus_from_film_mm']:g} mm"
    print(f"{res.lens_name}: distortion field at focus {f}, {res.size_px[0]}x{res.size_px[1]} px, "
          f"pinhole f {res.pinhole_focal_length_mm[1]:.3f} mm (Y; the paraxial one at this focus) at the entrance pupil")
    print(f"  largest distortion {res.max_distortion_px:.2f} px; interpolation error {res.interpolation_error_px:.4f} px "
          f"({res.grid_nodes[0]}x{res.grid_nodes[1]} traced chief rays)")
    if res.distortion_stmap is not None:
        print(f"  overscan {res.overscan_px[0]} x {res.overscan_px[1]} px (undistorted frame "
              f"{d['undistorted_size_px'][0]}x{d['undistorted_size_px'][1]}), inverse error {res.inverse_error_px:.4f} px")
    for fit in fits:
        verdict = "good" if fit.acceptable else f"NOT good (> {fit.max_residual_allowed_px:g} px)"
        coeffs = ", ".join(f"{k} {v:.6g}" for k, v in fit.coefficients.items())
        print(f"  {fit.model}: residual RMS {fit.rms_residual_px:.3f} px, max {fit.max_residual_px:.3f} px: {verdict}")
        print(f"    {coeffs}")
    for p in written:
        print(f"wrote {p}")
    return 0
