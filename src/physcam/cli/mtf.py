"""``physcam mtf --lens LENS``: the lens maker's MTF chart, or one field's wavefront, Strehl and MTF (docs/image-quality.md).

The chart: sagittal and tangential MTF at 10, 20 and 40 lp/mm against image height, in the d, F
and C lines (white light where the lens's glasses have dispersion; the chart says which), the lens focused at ``--focus`` and stopped to ``--fstop``; printed as a table
and drawn in characters, ``-o FILE.png`` for the picture, ``--json`` and ``--csv`` (one row per
image height and frequency) for pipelines.
``--field DEG`` reports one field instead: RMS and peak-to-valley wavefront, Strehl ratio and
the MTF at the frequencies (``-o`` draws its MTF curve).
"""

from __future__ import annotations

import math

from ._common import add_lens_argument, FOCUS_HELP, add_sensor_options, add_units_option, distance, focus, number, whole, figure_file
from ._output import add_output_options, document, emit_json, print_csv
from ._common import add_lenient, mark_repaired, units_of
from .lens import WAVE_UNITS

#: The CLI's largest pupil grids (the Python API goes to 1024): bound a chart's time and memory
#: (15 fields x 3 wavelengths), and one field's.
CLI_MAX_PUPIL_SAMPLES = 512
CHART_MAX_PUPIL_SAMPLES = 256

EPILOG = """\
examples:
  physcam mtf --lens dgauss_50mm --fstop 4 --focus 3m --sensor FF  (the vendor chart, full frame)
  physcam mtf --lens dgauss_50mm --fstop 2.8 --sensor "ALEXA 35" -o mtf.png
  physcam mtf --lens dgauss_50mm --fstop 8 --field 14             (one field: RMS, Strehl, MTF)
  physcam mtf --lens dgauss_50mm --wavelength 550 --frequency 10 --frequency 30 --json
  physcam mtf --lens dgauss_50mm --fstop 4 --csv > mtf.csv        (one row per image height and frequency)
  physcam mtf --lens dgauss_50mm --fstop 2.8 --best-focus 40      (the film at the best focus for 40 lp/mm)
  physcam mtf --lens dgauss_50mm --fstop 4 --field 14 --method huygens  (MTF from the Huygens PSF)
"""


def register(sub) -> None:
    import argparse

    p = sub.add_parser("mtf", help="MTF chart at 10/20/40 lp/mm against image height (lens makers' style), "
                                   "or one field's wavefront, Strehl and MTF",
                       description="Diffraction MTF from real rays: the vendor chart, or one field with --field.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_lens_argument(p)
    add_lenient(p)
    p.add_argument("--fstop", type=number("f-stop", positive=True), default=None,
                   help="stop the lens down to this f-number (default: the stop in the lens file)")
    p.add_argument("--focus", type=focus("focus distance"), default=None, metavar="DIST",
                   help=f"focus mark from the film plane (default infinity; {FOCUS_HELP})")
    p.add_argument("--frequency", type=number("frequency"), action="append", metavar="LPMM",
                   help="spatial frequency in line pairs per mm (repeat; default 10, 20 and 40)")
    p.add_argument("--wavelength", type=number("wavelength"), action="append", metavar="NM",
                   help="wavelength in nm (repeat; the first is the primary; default the d, F and C lines)")
    p.add_argument("--weight", type=number("wavelength weight"), action="append", metavar="W",
                   help="weight of each --wavelength, in the same order (repeat; default equal)")
    p.add_argument("--fields", type=whole("fields", lo=0), default=15, metavar="N",
                   help="image heights on the chart, from the centre to --max-height (2-41; default 15)")
    p.add_argument("--max-height", type=distance("largest image height"), default=None, metavar="MM",
                   help="largest image height of the chart (default: the sensor's half diagonal)")
    p.add_argument("--field", type=number("field angle"), default=None, metavar="DEG",
                   help="report one field angle (degrees, Y meridian) instead of the chart")
    p.add_argument("--pupil-samples", type=whole("pupil samples", lo=0), default=None, metavar="N",
                   help=f"pupil grid cells across (16-{CHART_MAX_PUPIL_SAMPLES} for the chart, to {CLI_MAX_PUPIL_SAMPLES} "
                        "with --field; default chosen by the sampling rules)")
    p.add_argument("--method", choices=("fft", "huygens"), default="fft",
                   help="fft: autocorrelation of the pupil function (default); huygens: the Fourier transform of the "
                        "Huygens PSF, wavelets summed from the exit-pupil wavefront (slower; docs/image-quality.md)")
    p.add_argument("--best-focus", type=number("best-focus frequency", positive=True), default=None, metavar="LPMM",
                   help="put the chart's film at the best focus for this frequency instead of the paraxial image plane "
                        "of --focus (the shift is printed in µm)")
    p.add_argument("--best-focus-rule", choices=("axis", "field"), default="axis",
                   help="best focus on the axis (default) or averaged over the image by ring area, as makers weigh "
                        "a chart")
    add_sensor_options(p)
    add_units_option(p)
    add_output_options(p, csv=True, what="the chart (or the field's figures)")
    p.add_argument("-o", "--output", metavar="FILE.png", type=figure_file, help="write the chart (or the field's MTF curve) as PNG/SVG/PDF")
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p.set_defaults(handler=run)


def _spectrum(args):
    from ..analysis.image_quality.mtf import WHITE_LIGHT_NM
    from ..errors import InputError

    wls = tuple(args.wavelength) if args.wavelength else WHITE_LIGHT_NM
    if args.weight and len(args.weight) != len(wls):
        raise InputError(f"give one --weight per wavelength: {len(wls)} wavelengths, {len(args.weight)} weights")
    return wls, (tuple(args.weight) if args.weight else None)


def run(args) -> int:
    from ..errors import InputError
    from ..io import check_writable
    from ..lens.library import load_lens
    from .report import resolve_sensor

    if args.force and not args.output:
        raise InputError("--force overwrites the -o file; without -o there is nothing to overwrite")
    if args.pupil_samples is not None and not 16 <= args.pupil_samples <= CLI_MAX_PUPIL_SAMPLES:
        raise InputError(f"--pupil-samples must lie between 16 and {CLI_MAX_PUPIL_SAMPLES}, got {args.pupil_samples}")
    if args.output:
        check_writable(args.output, force=args.force)
    from ._common import HYPERFOCAL

    # the sensor sets the chart's corner and the hyperfocal CoC; one field (--field) or a given
    # --max-height without --focus hyperfocal does not use it, so a defaulted sensor goes unsaid there
    unused = (args.field is not None or args.max_height is not None) and args.focus != HYPERFOCAL
    sensor = resolve_sensor(args, quiet=unused)
    lens = load_lens(args.lens, lenient=args.lenient)
    from ._common import resolve_focus

    args.focus = resolve_focus(args.focus, lens=lens, fstop=args.fstop, sensor=sensor, args=args)
    wls, weights = _spectrum(args)
    freqs = tuple(args.frequency) if args.frequency else (10.0, 20.0, 40.0)
    focus = None if args.focus is None or math.isinf(args.focus) else args.focus
    from ..optics.state import camera_state

    camera = camera_state(lens, focus_mm=focus, fstop=args.fstop)  # the one camera of the command
    if args.field is not None:
        if args.max_height is not None or args.fields != 15:
            raise InputError("--fields and --max-height set the chart; with --field one field is reported")
        if args.best_focus is not None:
            raise InputError("--best-focus places the chart's film; with --field the film stays at the focus mark")
        return _one_field(args, camera, wls, weights, freqs)
    from ..analysis.image_quality.mtf import mtf_chart
    from ._common import progress_bar

    top = sensor.diagonal_mm / 2 if args.max_height is None else args.max_height
    with progress_bar("MTF chart", enabled=not (args.json or args.csv)) as bar:
        chart = mtf_chart(camera, max_image_height_mm=top, n_fields=args.fields, frequencies=freqs, wavelengths_nm=wls,
                          weights=weights, pupil_samples=args.pupil_samples,
                          max_pupil_samples=CHART_MAX_PUPIL_SAMPLES, progress=bar, best_focus=args.best_focus,
                          best_focus_rule=args.best_focus_rule, method=args.method)
    if args.output:
        chart.plot(args.output, force=args.force, units=units_of(args))
    if args.json:
        d = chart.to_dict()
        d["sensor"] = {"name": sensor.name, "width_mm": sensor.width_mm, "height_mm": sensor.height_mm}
        emit_json(document("mtf_chart", mark_repaired(d, lens), units=dict(WAVE_UNITS, frequency="lp/mm")))
        return 0
    if args.csv:
        print_csv(chart.points(), units=units_of(args))
        return 0
    from ..units import format_distance

    foc = format_distance(math.inf if focus is None else focus, units_of(args))
    print(f"{chart.lens_name}: MTF at f/{chart.fstop:.3g}, focus {foc} from the film "
          f"({sensor.name}, corner at {sensor.diagonal_mm / 2:.2f} mm), {args.method.upper()} method")
    print(f"  light: {chart.spectrum}")
    print(f"  film: {chart.focus_words()}")
    print("  S = sagittal (lines radial), T = tangential (lines tangential to circles about the centre)")
    for line in chart.table().splitlines():
        print("  " + line)
    print()
    print(chart.text_chart())
    if args.output:
        print(f"wrote {args.output}")
    return 0


def _field_points(m) -> list[dict]:
    """One field's MTF as flat rows, one per frequency (``--csv`` with ``--field``; ``points`` in its JSON)."""

    def at(a, i):
        return None if a is None else float(a[i])

    return [{"field_deg": float(m.field_deg), "frequency_lpmm": float(f), "sagittal": float(m.sagittal[i]),
             "tangential": float(m.tangential[i]), "diffraction_limit_sagittal": at(m.diffraction_limit_sagittal, i),
             "diffraction_limit_tangential": at(m.diffraction_limit_tangential, i)}
            for i, f in enumerate(m.frequencies_lpmm)]


def _one_field(args, camera, wls, weights, freqs) -> int:
    from ..analysis.image_quality.mtf import mtf
    from ..analysis.image_quality.psf import psf
    from ..analysis.image_quality.wavefront import wavefront

    lens = camera.lens
    wf = wavefront(camera, args.field, wavelength_nm=wls[0], pupil_samples=args.pupil_samples)
    ps = psf(camera, args.field, wavelength_nm=wls[0], pupil_samples=args.pupil_samples,
             max_pupil_samples=CLI_MAX_PUPIL_SAMPLES)
    m = mtf(camera, args.field, frequencies=freqs, wavelengths_nm=wls, weights=weights, pupil_samples=args.pupil_samples,
            max_pupil_samples=CLI_MAX_PUPIL_SAMPLES)
    if args.method == "huygens":  # the MTF from the Huygens PSF; the Strehl ratio from the monochromatic one
        import dataclasses

        import numpy as np

        from ..analysis.image_quality.huygens import huygens_mtf, huygens_psf

        t, s, _ = huygens_mtf(camera, args.field, frequencies=freqs, wavelengths_nm=wls, weights=weights)
        m = dataclasses.replace(m, method="huygens", tangential=np.asarray(t), sagittal=np.asarray(s))
        hp = huygens_psf(camera, args.field, wavelengths_nm=[wls[0]])
        ps = dataclasses.replace(ps, strehl=float(hp.strehl))
    if args.output:
        curve = mtf(camera, args.field, wavelengths_nm=wls, weights=weights, pupil_samples=args.pupil_samples,
                    max_pupil_samples=CLI_MAX_PUPIL_SAMPLES)
        curve.plot(args.output, force=args.force)
    points = _field_points(m)
    if args.json:
        emit_json(document("mtf_field", mark_repaired({"wavefront": wf.to_dict(), "psf": ps.to_dict(),
                                                        "mtf": m.to_dict(), "points": points}, lens),
                           units=dict(WAVE_UNITS, wavefront="waves", frequency="lp/mm", psf="um")))
        return 0
    if args.csv:
        print_csv(points, units=units_of(args))
        return 0
    print(f"{wf.lens_name}: field {wf.field_deg:g} deg (chief ray at {wf.chief_image_height_mm:.3f} mm), "
          f"f/{wf.fstop:.3g}")
    print(f"  wavefront at {wf.wavelength_nm:g} nm: RMS {wf.rms_waves:.4f} waves (to centroid "
          f"{wf.rms_to_centroid_waves:.4f}), PV {wf.pv_waves:.4f} waves")
    print(f"  Strehl ratio {ps.strehl:.4f} (Marechal estimate {wf.strehl_marechal:.4f}); Airy radius "
          f"{ps.airy_radius_um:.2f} µm")
    z = wf.zernike
    print("  Zernike (Noll, waves): " + ", ".join(f"Z{j + 1} {c:+.4f}" for j, c in enumerate(z[:11])))
    from ..analysis.image_quality.mtf import spectrum_words

    print(f"  light: {spectrum_words(lens, m.wavelengths_nm)}")
    print("  MTF: " + ", ".join(f"{f:g} lp/mm S {s:.3f} T {t:.3f}" for f, s, t in
                                         zip(m.frequencies_lpmm, m.sagittal, m.tangential)))
    if args.output:
        print(f"wrote {args.output}")
    return 0
