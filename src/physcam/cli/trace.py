"""``physcam spot --lens LENS`` and ``physcam bokeh --lens LENS``: real-ray analyses (see docs/ray-tracing.md)."""

from __future__ import annotations

from ._common import add_lens_argument, FOCUS_HELP, add_sensor_options, add_units_option, distance, focus, hidden_alias, number, whole, figure_file
from ._output import add_output_options, document, emit_json, print_csv
from ._common import add_lenient, mark_repaired
from .lens import WAVE_UNITS


def register(sub) -> None:
    p = sub.add_parser("spot", help="spot diagram (RMS and geometric radius per field) by real ray tracing")
    add_lens_argument(p)
    add_lenient(p)
    p.add_argument("--field", type=number("field angle"), action="append", metavar="DEG",
                   help="field angle in degrees (repeat; default 0 and 5)")
    p.add_argument("--wavelength", type=number("wavelength"), default=None, metavar="NM",
                   help="wavelength in nm (default: the lens's design wavelength, the d line 587.56)")
    p.add_argument("--rings", type=whole("rings", lo=0), default=64, metavar="N",
                   help="divisions of the pupil radius squared (1-500; about 3 n^2 equal-area rays per field, "
                        "plus the refined beam edge; default 64)")
    p.add_argument("--fstop", type=number("f-stop"), default=None, help="stop the lens down to this f-number")
    p.add_argument("--no-clip", dest="clip", action="store_false",
                   help="no element rim or stop clips: trace the whole paraxial entrance pupil")
    add_output_options(p, csv=True, what="the spot sizes")
    p.add_argument("-o", "--output", metavar="FILE.png", type=figure_file, help="write the spot diagram plot")
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p.set_defaults(handler=run_spot)

    b = sub.add_parser("bokeh", help="PSF / bokeh image of a point light by real ray tracing")
    add_lens_argument(b)
    add_lenient(b)
    b.add_argument("--light", dest="depth", type=distance("light distance"), default=1000.0, metavar="D",
                   help="the point light's distance in front of the film plane (default 1m; units ok: 2m, 6ft; "
                        "bare number = mm)")
    hidden_alias(b, "--depth", "depth", type=distance("light distance"))
    b.add_argument("--x", type=number("light x"), default=0.0, metavar="MM", help="light lateral x (mm)")
    b.add_argument("--y", type=number("light y"), default=0.0, metavar="MM", help="light lateral y (mm)")
    b.add_argument("--rays", type=whole("rays", lo=0), default=250_000, metavar="N",
                   help="rays to trace (1 to 1e11; default 250000, low-discrepancy: as clean an image as 1e6 "
                        "random rays; 1000000 gives one three times cleaner)")
    b.add_argument("--pixels", type=whole("pixels", lo=0), default=256, metavar="PX",
                   help="image width and height in pixels (8 to 4096; default 256)")
    b.add_argument("--spectral", action="store_true", help="three wavelengths (620/550/460 nm) as RGB")
    b.add_argument("--focus", type=focus("focus distance"), default=None, metavar="D",
                   help=f"focus mark from the film plane; the lens is focused there (default infinity; {FOCUS_HELP})")
    b.add_argument("--fstop", type=number("f-stop"), default=None, help="stop the lens down to this f-number")
    b.add_argument("--blades", type=whole("blade count", lo=0), default=0, metavar="N", help="iris blades (< 3: circular; seed 002 nsides)")
    b.add_argument("--blade-angle", type=number("blade angle"), default=0.0, metavar="DEG",
                   help="rotation of the iris polygon (degrees)")
    b.add_argument("--roundness", type=number("roundness"), default=0.0,
                   help="-1..1: 0 straight blades, 1 bowed out to a circle, -1 bowed in (star)")
    b.add_argument("--density", type=number("density"), default=0.0,
                   help="-1..1: brightness ramp across the aperture (+ brighter rim, - brighter centre)")
    add_output_options(b, what="the bokeh measurements")
    add_units_option(b)
    b.add_argument("-o", "--output", metavar="FILE.png", type=figure_file, help="write the bokeh plot (film millimetre axes)")
    b.add_argument("--image", metavar="NAME", default=None,
                   help="write the bokeh as a photograph: NAME.exr (linear, RGB with --spectral) and NAME.png "
                        "(tone-mapped, with a scale bar in sensor pixels)")
    add_sensor_options(b)
    b.add_argument("--pixel-pitch", type=number("pixel pitch", positive=True), default=None, metavar="UM",
                   help="sensor pixel pitch for --image's scale bar (micrometres; default the sensor's own, or its "
                        "width over 4096 pixels)")
    b.add_argument("--exposure", type=number("exposure", positive=True), default=1.0,
                   help="--image PNG exposure: 1 puts the brightest lit pixels at the shoulder (default 1)")
    b.add_argument("--force", action="store_true", help="overwrite an existing output file")
    b.set_defaults(handler=run_bokeh)


def run_spot(args) -> int:
    from ..analysis.image_quality.spot import spot_diagram
    from ..io import check_writable
    from ..lens.library import load_lens

    if args.output:
        check_writable(args.output, force=args.force)
    lens = load_lens(args.lens, lenient=args.lenient)
    # the lens as designed, its film at --wavelength's paraxial focus (camera_state would keep the film where
    # the lens focuses at its design wavelength)
    from ..optics.state import as_designed

    res = spot_diagram(as_designed(lens, fstop=args.fstop), tuple(args.field or (0.0, 5.0)),
                       wavelength_nm=args.wavelength, rings=args.rings, clip=args.clip)
    if args.output:  # the context line laid out with the panels in one pass (save_plot lays a figure out again)
        res.plot(args.output, force=args.force,
                 context=(f"f/{args.fstop:g}" if args.fstop else "wide open") + ", focused at infinity")
    if args.json:
        emit_json(document("spot", mark_repaired(res.to_dict(), lens), units=dict(WAVE_UNITS, spot="um")))
    elif args.csv:
        print_csv(res.to_dict()["fields"])
    else:
        from ._output import Table, print_table

        t = Table(f"{res.lens_name}: spot diagram at {res.wavelength_nm:g} nm, film z = {res.film_z_mm:.4f} mm"
                  + ("" if res.clip else ", no clipping"),
                  ("field deg", "RMS um", "GEO um", "passed", "clipped", "missed", "TIR"), justify=["right"] * 7)
        for f in res.fields:
            rms = "undefined" if f.rms_radius_um is None else f"{f.rms_radius_um:.3f}"
            geo = "undefined" if f.geometric_radius_um is None else f"{f.geometric_radius_um:.3f}"
            t.add_row(f"{f.field_deg:.2f}", rms, geo, str(f.rays_passed), str(f.rays_clipped), str(f.rays_missed),
                      str(f.rays_tir))
        print_table(t)
        for f in res.fields:
            if f.reason:
                print(f"note: {f.reason}")
        if args.output:
            print(f"wrote {args.output}")
    return 0


def run_bokeh(args) -> int:
    from ..analysis.defocus.bokeh import bokeh_image
    from ..io import check_writable
    from ..lens.library import load_lens

    if args.output:
        check_writable(args.output, force=args.force)
    import math

    from ..optics.state import camera_state
    from ..trace.aperture import Aperture

    lens = load_lens(args.lens, lenient=args.lenient)
    from ._common import resolve_focus

    args.focus = resolve_focus(args.focus, lens=lens, fstop=args.fstop, args=args)
    aperture = None
    if args.blades >= 3 or args.density != 0.0 or args.roundness != 0.0 or args.blade_angle != 0.0:
        aperture = Aperture(nsides=args.blades, angle_deg=args.blade_angle, roundness=args.roundness,
                            density=args.density)
    state = camera_state(lens, focus_mm=args.focus, fstop=args.fstop, aperture=aperture)
    from ._common import progress_bar

    with progress_bar("tracing bokeh rays", enabled=not args.json) as bar:
        res = bokeh_image(state, args.depth, args.x, args.y, rays=args.rays, pixels=args.pixels,
                          spectral=args.spectral, chunk=min(args.rays, 250_000) if args.rays >= 1000 else 1000,
                          progress=bar)
    if args.output:
        from ..units import format_distance
        from ._common import units_of
        from ._output import save_plot

        u = units_of(args)
        save_plot(res, args.output, force=args.force,
                  context=f"light at {format_distance(args.depth, u)}, focus "
                          f"{format_distance(math.inf if args.focus is None else args.focus, u)}, "
                          + (f"f/{args.fstop:g}" if args.fstop else "wide open"))
    photo = _bokeh_photo(res, args) if args.image else None
    if args.json:
        d = res.to_dict()
        if photo is not None:
            d["image"] = photo
        d.update(light_from_film_mm=args.depth, focus_from_film_mm=None if args.focus in (None, math.inf) else args.focus,
                 fstop=args.fstop)
        emit_json(document("bokeh", mark_repaired(d, lens), units=WAVE_UNITS))
    else:
        from ..units import format_distance
        from ._common import units_of

        d = res.to_dict()
        u = units_of(args)
        focus_txt = format_distance(math.inf if args.focus is None else args.focus, u)
        print(f"{res.lens_name}: bokeh of a light at {format_distance(args.depth, u)} from the film, focus {focus_txt}"
              + (f", f/{args.fstop:g}" if args.fstop else "")
              + f", {d['rays_passed']}/{d['rays_traced']} rays reach the film"
              + ("" if None in d["centroid_mm"] else
                 ", centroid ({:.4f}, {:.4f}) mm on the film".format(*d["centroid_mm"])))
        if args.output:
            print(f"wrote {args.output}")
        if photo is not None:
            print(f"wrote {photo['exr']} and {photo['png']} (scale bar {photo['scale_bar_px']} px of "
                  f"{photo['sensor']}, {photo['pixel_pitch_um']:g} µm pitch)")
    return 0


def _bokeh_photo(res, args) -> dict:
    """``physcam bokeh --image``: the EXR and PNG photograph, and what its scale bar means."""
    from ..analysis.defocus.bokeh import scale_bar_pixels, write_bokeh_photo
    from ._common import resolve_sensor

    sensor = resolve_sensor(args)
    pitch = args.pixel_pitch or sensor.pitch_um or sensor.width_mm * 1000.0 / 4096
    exr, png = write_bokeh_photo(res, args.image, pixel_pitch_um=pitch, sensor_name=sensor.name,
                                 exposure=args.exposure, force=args.force)
    x0, x1 = res.extent_mm[:2]
    return {"exr": str(exr), "png": str(png), "sensor": sensor.name, "pixel_pitch_um": pitch,
            "pitch_source": "--pixel-pitch" if args.pixel_pitch else ("sensor" if sensor.pitch_um else
                                                                       "sensor width / 4096"),
            "scale_bar_px": scale_bar_pixels(x1 - x0, pitch), "image_width_px_of_sensor": (x1 - x0) * 1000.0 / pitch}
