"""``physcam distortion --lens LENS``: real distortion, ST-maps and fitted models at any focus (docs/distortion.md).

Examples::

  physcam distortion --lens dgauss_50mm                           # against field angle, at infinity
  physcam distortion --lens zeiss_distagon_35mm_f4 --focus 2m --sensor "ALEXA 35" --resolution 4608x3164 \\
      --stmap out/ --fit 3de4 --fit brown --fit nuke              # maps, fitted models, a Nuke script
  physcam distortion --lens zuiko_18mm_f3_5 --resolution 2048x1366 --across-focus 0.3m,0.5m,1m,2m,inf
"""

from __future__ import annotations

import math

from ._common import FOCUS_HELP, add_units_option, focus, focus_list, number, units_of
from ._output import document, emit_json, print_csv
from ._zoom import add_zoom_option, at_zoom_named
from ._common import mark_repaired
from .lens import WAVE_UNITS

#: Names of the files the fits write into --stmap DIR.
FIT_FILES = {"brown": "brown_conrady.json", "3de4": "3de4_radial_standard_degree_4.txt",
             "usd": "usd_lens_distortion.json", "nuke": "physcam_stmap.nk",
             "3de4-anamorphic-4": "3de4_anamorphic_standard_degree_4.txt",
             "3de4-anamorphic-6": "3de4_anamorphic_standard_degree_6.txt",
             "unreal-anamorphic": "unreal_anamorphic_distortion.json"}


_focus_list = focus_list("focus marks")


def register(sub) -> None:
    from .analyze import _common, _resolution, _sensor
    from ..analysis.distortion.names import DEFAULT_MAX_RESIDUAL_PX, MODEL_CHOICES

    p = sub.add_parser("distortion", help="real distortion: against field, ST-maps and fitted models at any focus")
    _common(p, "write the distortion plot (field-angle table; with --across-focus the table's plot)")
    p.add_argument("--field", type=number("field angle"), action="append", metavar="DEG",
                   help="field angle in degrees (repeat; default: up to the sensor corner)")
    _sensor(p)
    p.add_argument("--wavelength", type=number("wavelength"), default=None, metavar="NM",
                   help="wavelength in nm (default: the lens's design wavelength, the d line 587.56)")
    p.add_argument("--focus", type=focus("focus distance"), default=None, metavar="D",
                   help=f"focus mark from the film plane (default infinity; {FOCUS_HELP}; hyperfocal wide open): "
                        "the field-angle table of the lens focused there, or with --resolution the 2-D field")
    p.add_argument("--resolution", type=_resolution, default=None, metavar="WxH",
                   help="frame size in pixels, e.g. 2048x1366: the full 2-D distortion field at --focus")
    p.add_argument("--stmap", metavar="DIR", default=None,
                   help="write distortion.exr and undistortion.exr (32-bit float ST-maps), PNG previews and the "
                        "files of each --fit into DIR; needs --resolution")
    p.add_argument("--desqueeze", action="store_true",
                   help="an anamorphic lens: the undistortion map makes the desqueezed picture (the round pinhole's, "
                        "square pixels, round(width x f_y / f_x) wide) in one STMap; needs --stmap")
    p.add_argument("--fit", choices=MODEL_CHOICES, action="append", default=None,
                   help="fit a model over the frame (repeat): brown = Brown-Conrady D-U and U-D (OpenTrackIO), "
                        "3de4 = 3DE4 Radial - Standard, Degree 4, usd = Hydra lensDistortion, 3de4-anamorphic-4 and -6 = 3DE4 Anamorphic - Standard, Degree 4 and 6 (with --stmap: their 3DE4 lens files, and Unreal's anamorphic parameters for degree 4), nuke = a Nuke "
                        "script applying the ST-maps (with --stmap); needs --resolution")
    p.add_argument("--max-residual", type=number("allowed residual", positive=True),
                   default=DEFAULT_MAX_RESIDUAL_PX, metavar="PX",
                   help=f"largest residual in pixels a fit may have to be called good and written "
                        f"(default {DEFAULT_MAX_RESIDUAL_PX:g})")
    p.add_argument("--plate", default="plate.####.exr", metavar="PATH",
                   help="the plate the Nuke script reads (default plate.####.exr)")
    p.add_argument("--fstop", type=number("f-stop", positive=True), default=None, metavar="N",
                   help="map the lens's blur centroids at this f-stop (the plate's stop) instead of its chief rays "
                        "(a small stop); needs --resolution")
    p.add_argument("--across-focus", type=_focus_list, default=None, metavar="LIST",
                   help="a table of distortion across focus marks, e.g. 0.5m,1m,2m,inf (hyperfocal too); "
                        "needs --resolution")
    add_zoom_option(p)
    add_units_option(p)
    p.set_defaults(handler=run_distortion, output_folders=("stmap",))


def run_distortion(args) -> int:
    from ..errors import InputError
    from .analyze import _finish, _prepare

    needs = [n for n, v in (("--stmap", args.stmap), ("--fit", args.fit),
                            ("--across-focus", args.across_focus), ("--fstop", args.fstop)) if v is not None]
    if args.resolution is None and needs:
        raise InputError(f"{', '.join(needs)} {'needs' if len(needs) == 1 else 'need'} --resolution WxH "
                         "(the frame size in pixels)")
    if args.desqueeze and args.stmap is None:
        raise InputError("--desqueeze shapes the undistortion ST-map: give --stmap DIR (and --resolution WxH)")
    if args.across_focus is not None and (args.focus is not None or args.stmap or args.fit):
        raise InputError("--across-focus makes a table of its own focus marks: give it without --focus, --stmap "
                         "and --fit")
    if args.across_focus is not None and args.fstop is not None:
        raise InputError("--across-focus tables chief-ray distortion; centroid distortion at a stop (--fstop) is "
                         "made for one focus (--focus) at a time")
    if args.fit and "nuke" in args.fit and args.stmap is None:
        raise InputError("--fit nuke writes a Nuke script beside the ST-maps: give --stmap DIR")
    if args.csv and args.resolution is not None and args.across_focus is None:
        raise InputError("--csv prints a table's rows: the field-angle table (without --resolution) or "
                         "--across-focus; the 2-D field writes --stmap files")
    lens = at_zoom_named(_prepare(args), args)
    if args.focus is not None or args.across_focus is not None:
        from ..optics.sensors import custom_sensor
        from ._common import resolve_focus

        sensor = custom_sensor(args.sensor_width, args.sensor_height)
        args.focus = resolve_focus(args.focus, lens=lens, sensor=sensor, args=args)
        args.across_focus = resolve_focus(args.across_focus, lens=lens, sensor=sensor, args=args)
    if args.across_focus is not None:
        return _run_across_focus(args, lens)
    if args.resolution is not None:
        return _run_field(args, lens)
    from ..analysis.distortion.field import real_distortion

    res = real_distortion(lens, args.field, sensor_width_mm=args.sensor_width, sensor_height_mm=args.sensor_height,
                          wavelength_nm=args.wavelength, focus_mm=math.inf if args.focus is None else args.focus)
    if args.csv and not args.json:
        print_csv(res.to_dict()["points"], units=units_of(args))
    elif not args.json:
        from ._output import Table, print_table

        if res.focus_from_film_mm is None or math.isinf(res.focus_from_film_mm):  # Y's pinhole there is its EFL
            against = f"EFL {res.efl_y_mm:.3f} mm"
        else:
            from ..units import format_distance

            against = (f"focused at {format_distance(res.focus_from_film_mm, units_of(args))}, pinhole f "
                       f"{res.efl_y_mm:.3f} mm (Y) at the entrance pupil")
        t = Table(f"{res.lens_name}: real distortion at {res.wavelength_nm:g} nm (chief ray vs f tan theta), "
                  f"{against}, {args.sensor_name}",
                  ("axis", "field deg", "real mm", "f tan mm", "dist %"), justify=["right"] * 5)
        for p in res.points:
            t.add_row(p.axis, f"{p.field_deg:.3f}", f"{p.real_height_mm:.4f}", f"{p.paraxial_height_mm:.4f}",
                      f"{p.distortion_pct:.3f}")
        print_table(t)
        f = res.fit
        if f is not None:
            print(f"standard model: k1 {f.k1:.6f}, k2 {f.k2:.6f} (rho = r / {f.norm_radius_mm:g} mm), "
                  f"max residual {f.max_residual_pct:.4f} %")
    _finish(args, res, "distortion")
    return 0


def _run_across_focus(args, lens) -> int:
    from ..analysis.distortion.across_focus import distortion_across_focus
    from ..errors import InputError

    if args.field:
        raise InputError("--field is for the field-angle table; --across-focus covers the whole frame")
    tab = distortion_across_focus(lens, args.across_focus, sensor_width_mm=args.sensor_width,
                                  sensor_height_mm=args.sensor_height, width_px=args.resolution[0],
                                  height_px=args.resolution[1], wavelength_nm=args.wavelength)
    if args.output:
        tab.plot(args.output, force=args.force, units=units_of(args))
    if args.json:
        emit_json(document("distortion_across_focus", mark_repaired({**tab.to_dict(), "zoom": args.zoom_block},
                                                                     args.loaded_lens),
                           units=dict(WAVE_UNITS, image="pixel")))
        return 0
    rows = [dict(r, brown_du_k1=r["brown_du"]["k1"], brown_du_k2=r["brown_du"]["k2"],
                 brown_du_max_px=r["brown_du"]["max_px"], tde4_c2=r["tde4"]["Distortion - Degree 2"],
                 tde4_c4=r["tde4"]["Quartic Distortion - Degree 4"], tde4_max_px=r["tde4"]["max_px"]) for r in tab.rows]
    if args.csv:
        print_csv(rows, units=units_of(args))
        return 0
    from ..units import format_distance
    from ._output import Table, print_table

    units = units_of(args)
    t = Table(f"{tab.lens_name}: distortion across focus, {tab.sensor_mm[0]:g} x {tab.sensor_mm[1]:g} mm at "
              f"{tab.size_px[0]}x{tab.size_px[1]} px (against the pinhole at each focus)",
              ("focus", "pinhole mm", "corner %", "max px", "BC k1", "BC k2", "BC max px", "3DE c2", "3DE c4",
               "3DE max px"), justify=["right"] * 10)
    for r in rows:
        f = r["focus_from_film_mm"]
        t.add_row(format_distance(float("inf") if f is None else f, units), f"{r['pinhole_focal_length_mm']:.3f}",
                  f"{r['corner_distortion_pct']:.3f}", f"{r['max_distortion_px']:.2f}", f"{r['brown_du_k1']:.5f}",
                  f"{r['brown_du_k2']:.5f}", f"{r['brown_du_max_px']:.3f}", f"{r['tde4_c2']:.5f}",
                  f"{r['tde4_c4']:.5f}", f"{r['tde4_max_px']:.3f}")
    print_table(t)
    if args.output:
        print(f"wrote {args.output}")
    return 0



#: Units of the fit files' numbers (their coefficients are dimensionless: normalised coordinates)
FIT_UNITS = {"coefficients": "dimensionless (coordinates normalised as each fit's notes say)",
             "fx_mm": "mm", "fy_mm": "mm", "focal_length_mm": "mm", "residual_px": "px", "sensor_mm": "mm",
             "focus_from_film_mm": "mm from the film plane (null: infinity)",
             "opentrackio_lens_distortion": "OpenLensIO: mm on the sensor from its centre, y down"}


def brown_conrady_document(lens_name: str, fits) -> dict:
    """``brown_conrady.json``: both Brown-Conrady fits and their OpenTrackIO ``lens.distortion``
    entries, as a versioned document (schema ``physcam.distortion_brown_conrady``)."""
    from ._output import document

    return document("distortion_brown_conrady", {
        "lens": lens_name, "opentrackio_lens_distortion": [f.opentrackio() for f in fits],
        "fits": [f.to_dict() for f in fits]}, units=FIT_UNITS)


def usd_distortion_document(lens_name: str, fit) -> dict:
    """``usd_lens_distortion.json``: the USD ``lensDistortion`` standard fit and its attributes, as a
    versioned document (schema ``physcam.distortion_usd``)."""
    from ._output import document

    return document("distortion_usd", {"lens": lens_name, **fit.to_dict()}, units=FIT_UNITS)

def _fit_payloads(args, res, fits, folder):
    """(path, bytes) of every fit file, after checking each fit may be written."""
    import json
    from pathlib import Path

    from .. import __version__
    from ..analysis.distortion.models import BrownConrady, TDE4RadialStandard, USDStandard
    from ..export.nuke import nuke_stmap_script
    from ..export.tde4 import tde4_lens_text
    from ._common import units_of

    d = Path(folder)
    out = []
    from ..analysis.distortion.anamorphic import TDE4Anamorphic
    from ..export.tde4 import tde4_anamorphic_lens_text

    brown = [f for f in fits if isinstance(f, BrownConrady)]
    for f in fits:
        f.require_acceptable(FIT_FILES["brown" if f in brown else "3de4" if isinstance(f, TDE4RadialStandard)
                                        else _anamorphic_key(f) if isinstance(f, TDE4Anamorphic) else "usd"])
    if brown:
        out.append((d / FIT_FILES["brown"], (json.dumps(brown_conrady_document(res.lens_name, brown), indent=2)
                                             + "\n").encode()))
    for f in fits:
        if isinstance(f, TDE4RadialStandard):
            out.append((d / FIT_FILES["3de4"], tde4_lens_text(f, res.lens_name).encode()))
        elif isinstance(f, TDE4Anamorphic):
            out.append((d / FIT_FILES[_anamorphic_key(f)], tde4_anamorphic_lens_text(f, res.lens_name).encode()))
            if f.coefficients["degree"] == 4:  # Unreal's anamorphic lens model is the degree-4 one
                doc = document("distortion_unreal_anamorphic", {"lens": res.lens_name, **f.to_dict()},
                               units=FIT_UNITS)
                out.append((d / FIT_FILES["unreal-anamorphic"], (json.dumps(doc, indent=2) + "\n").encode()))
        elif isinstance(f, USDStandard):
            out.append((d / FIT_FILES["usd"], (json.dumps(usd_distortion_document(res.lens_name, f), indent=2)
                                               + "\n").encode()))
    for f in fits:
        slug = {"D-U": "_du", "U-D": "_ud"}.get(f.direction, "") if isinstance(f, BrownConrady) else ""
        stem = ("brown_conrady" + slug if isinstance(f, BrownConrady)
                else "3de4" if isinstance(f, TDE4RadialStandard)
                else _anamorphic_key(f).replace("-", "_") if isinstance(f, TDE4Anamorphic) else "usd")
        out.append((d / f"residual_{stem}.png", _png(f, units_of(args))))
    if "nuke" in args.fit:
        (fw, fh), (ox, oy) = res.frame_px, res.overscan_px
        text = nuke_stmap_script(d.resolve() / "undistortion.exr", d.resolve() / "distortion.exr", plate=args.plate,
                                 plate_size=res.size_px, undistorted_size=(fw + 2 * ox, fh + 2 * oy),
                                 undistorted_frame=res.frame_px, version=__version__)
        out.append((d / FIT_FILES["nuke"], text.encode()))
    return out


def _anamorphic_key(fit) -> str:
    return f"3de4-anamorphic-{int(fit.coefficients['degree'])}"


def _fits(samples, names, max_residual_px):
    """The fitted models named by --fit: physcam.analysis.distortion.models' and the 3DE4 anamorphic ones."""
    from ..analysis.distortion.anamorphic import fit_tde4_anamorphic
    from ..analysis.distortion.models import fit_models
    from ..analysis.distortion.names import ANAMORPHIC_CHOICES

    names = list(names or ())
    fits = fit_models(samples, [n for n in names if n not in ANAMORPHIC_CHOICES], max_residual_px=max_residual_px)
    return fits + [fit_tde4_anamorphic(samples, ANAMORPHIC_CHOICES[n], max_residual_px=max_residual_px)
                   for n in dict.fromkeys(names) if n in ANAMORPHIC_CHOICES]


def _png(fit, units: str = "m") -> bytes:
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "r.png"
        fit.plot_residual(p, units=units)
        return p.read_bytes()


def _run_field(args, lens) -> int:
    from ..analysis.distortion.models import samples_from_field
    from ..analysis.distortion.stmap import distortion_field, write_stmaps
    from ..errors import InputError
    import contextlib
    from pathlib import Path

    from ..io import atomic_write
    from ..optics.state import camera_state
    from ._common import output_folder, relocated

    if args.field:
        raise InputError("--field is for the field-angle table; the 2-D field (--resolution) covers the whole frame")
    if args.output:
        raise InputError("-o draws the field-angle table's plot; with --resolution the maps go to --stmap DIR "
                         "(each EXR with a PNG preview)")
    if args.stmap is not None:  # say so before the tracing, not after it
        from ..extras import require_extra

        require_extra("exr", "writing ST-maps as EXR (physcam distortion --stmap)")
    cam = camera_state(lens, focus_mm=args.focus, fstop=args.fstop, sensor_mm=(args.sensor_width, args.sensor_height))
    written = []
    with contextlib.ExitStack() as stack:  # the --stmap folder is written whole, and checked before the work
        tmp = None if args.stmap is None else stack.enter_context(
            output_folder(args.stmap, force=args.force, command="distortion --stmap"))
        res = distortion_field(cam, width_px=args.resolution[0], height_px=args.resolution[1],
                               wavelength_nm=args.wavelength, maps=args.stmap is not None, desqueeze=args.desqueeze)
        fits = _fits(samples_from_field(res), args.fit, args.max_residual)
        if tmp is not None:
            payload = _fit_payloads(args, res, fits, args.stmap) if args.fit else []  # named in the final folder
            maps = write_stmaps(res, tmp)
            for p, data in payload:
                atomic_write(tmp / Path(p).relative_to(args.stmap), data)
            written = relocated(maps, tmp, args.stmap) + [p for p, _ in payload]
    d = res.to_dict()
    d["fits"] = [f.to_dict() for f in fits]
    d["zoom"] = args.zoom_block
    if args.json:
        d["written"] = [str(p) for p in written]
        emit_json(document("distortion_field", mark_repaired(d, args.loaded_lens),
                           units=dict(WAVE_UNITS, image="pixel")))
        return 0
    from ..units import format_distance

    f = format_distance(res.focus_from_film_mm, units_of(args))
    print(f"{res.lens_name}: distortion field at focus {f}, {res.size_px[0]}x{res.size_px[1]} px, "
          f"pinhole f {res.pinhole_focal_length_mm[1]:.3f} mm (Y; the paraxial one at this focus) at the entrance pupil")
    print(f"  largest distortion {res.max_distortion_px:.2f} px; interpolation error {res.interpolation_error_px:.4f} px "
          f"({res.grid_nodes[0]}x{res.grid_nodes[1]} traced chief rays)")
    print(f"  the map is for {d['map_for']}; its residual there: RMS {res.residual_px[0]:.3f} px, "
          f"max {res.residual_px[1]:.3f} px")
    if res.distortion_stmap is not None:
        desq = f", desqueezed x{d['desqueeze']:.4f}" if res.frame_px != res.size_px else ""
        print(f"  overscan {res.overscan_px[0]} x {res.overscan_px[1]} px (undistorted frame "
              f"{d['undistorted_size_px'][0]}x{d['undistorted_size_px'][1]}{desq}), inverse error {res.inverse_error_px:.4f} px")
    for fit in fits:
        coeffs = ", ".join(f"{k} {v:.6g}" for k, v in fit.coefficients.items())
        print(f"  {fit.model}: residual RMS {fit.rms_residual_px:.3f} px, max {fit.max_residual_px:.3f} px: "
              f"{fit.verdict}")
        print(f"    {coeffs}")
    for p in written:
        print(f"wrote {p}")
    return 0
