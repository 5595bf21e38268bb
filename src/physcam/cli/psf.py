"""``physcam psf --lens LENS``: one field's point spread function, by FFT of the pupil or by Huygens
summation (docs/image-quality.md)."""

from __future__ import annotations

from ._common import add_lens_argument, FOCUS_HELP, focus, number, whole, figure_file
from ._output import add_output_options, document, emit_json
from ._common import add_lenient, mark_repaired
from .lens import WAVE_UNITS

EPILOG = """\
examples:
  physcam psf --lens dgauss_50mm --field 14 --fstop 4 --method huygens -o psf.png
  physcam psf --lens dgauss_50mm --fstop 8 --json                 (on axis, FFT: Strehl ratio and pixel size)
  physcam psf --lens zuiko_18mm_f3_5 --field 20 --fstop 5.6 --method huygens --tilt 0,1.5
"""


def register(sub) -> None:
    import argparse

    p = sub.add_parser("psf", help="one field's point spread function and Strehl ratio (FFT or Huygens)",
                       description="The diffraction PSF of one field from real rays: the FFT of the pupil function, "
                                   "or the Huygens sum of wavelets from the exit-pupil wavefront (--method huygens), "
                                   "which also takes a tilted film.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_lens_argument(p)
    add_lenient(p)
    p.add_argument("--field", type=number("field angle"), default=0.0, metavar="DEG",
                   help="field angle in degrees, Y meridian (default 0: on the axis)")
    p.add_argument("--fstop", type=number("f-stop", positive=True), default=None,
                   help="stop the lens down to this f-number (default: the stop in the lens file)")
    p.add_argument("--focus", type=focus("focus distance"), default=None, metavar="DIST",
                   help=f"focus mark from the film plane (default infinity; {FOCUS_HELP})")
    p.add_argument("--wavelength", type=number("wavelength"), default=None, metavar="NM",
                   help="wavelength in nm (default: the lens's design wavelength)")
    p.add_argument("--defocus", type=number("defocus"), default=0.0, metavar="UM",
                   help="film moved away from the lens, micrometres (default 0)")
    p.add_argument("--method", choices=("fft", "huygens"), default="fft",
                   help="fft: Fourier transform of the pupil function (default); huygens: wavelets summed from the "
                        "exit-pupil wavefront")
    p.add_argument("--tilt", type=_tilt, default=(0.0, 0.0), metavar="X,Y",
                   help="film tilt about x and y in degrees (Huygens only; default 0,0)")
    p.add_argument("--samples", type=whole("samples", lo=0), default=None, metavar="N",
                   help="Huygens image grid points per side (8-1024; default 129)")
    p.add_argument("--pixel", type=number("pixel size", positive=True), default=None, metavar="UM",
                   help="Huygens image pixel in micrometres (default a quarter of lambda N)")
    add_output_options(p, what="the PSF's figures")
    p.add_argument("-o", "--output", metavar="FILE.png", type=figure_file, help="draw the PSF (log scale) as PNG/SVG/PDF")
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p.set_defaults(handler=run)


def _tilt(text):
    import argparse

    from ._common import list_items

    try:
        vals = [float(v) for v in list_items(text, "the film tilt about x and y", "0,1.5")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"the film tilt is X,Y in degrees, e.g. 0,1.5; got {text!r}") from None
    if len(vals) != 2 or any(v != v or abs(v) >= 45.0 for v in vals):
        raise argparse.ArgumentTypeError(f"the film tilt is X,Y in degrees, each under 45; got {text!r}")
    return vals[0], vals[1]


def run(args) -> int:
    import math

    from ..errors import InputError
    from ..io import check_writable
    from ..lens.library import load_lens
    from ._common import resolve_focus

    if args.force and not args.output:
        raise InputError("--force overwrites the -o file; without -o there is nothing to overwrite")
    if args.method == "fft" and (args.tilt != (0.0, 0.0) or args.samples is not None or args.pixel is not None):
        raise InputError("--tilt, --samples and --pixel shape the Huygens PSF: add --method huygens")
    if args.output:
        check_writable(args.output, force=args.force)
    lens = load_lens(args.lens, lenient=args.lenient)
    args.focus = resolve_focus(args.focus, lens=lens, fstop=args.fstop, args=args)
    focus_mm = None if args.focus is None or math.isinf(args.focus) else args.focus
    from ..optics.state import camera_state

    camera = camera_state(lens, focus_mm=focus_mm, fstop=args.fstop)  # the one camera of the command
    kw = dict(defocus_mm=args.defocus * 1e-3)
    if args.method == "huygens":
        from ..analysis.image_quality.huygens import DEFAULT_IMAGE_SAMPLES, huygens_psf

        p = huygens_psf(camera, args.field, wavelengths_nm=None if args.wavelength is None else [args.wavelength],
                        tilt_deg=args.tilt, image_samples=args.samples or DEFAULT_IMAGE_SAMPLES, pixel_um=args.pixel,
                        **kw)
        d = dict(p.to_dict(), method="huygens")
        line = (f"Strehl {p.strehl:.4f}; {p.image.shape[0]} x {p.image.shape[1]} px of {p.pixel_um:.3f} um about the "
                f"blur's centroid, holding {p.energy_in_grid:.1%} of the power")
    else:
        from ..analysis.image_quality.psf import psf

        p = psf(camera, args.field, wavelength_nm=args.wavelength, **kw)
        d = dict(p.to_dict(), method="fft")
        line = (f"Strehl {p.strehl:.4f}; pixels {p.pixel_um[0]:.3f} x {p.pixel_um[1]:.3f} um; Airy radius "
                f"{p.airy_radius_um:.2f} um")
    if args.output:
        p.plot(args.output, force=args.force)
    if args.json:
        emit_json(document("psf", mark_repaired(d, lens), units=dict(WAVE_UNITS, psf="um")))
        return 0
    print(f"{p.lens_name}: PSF at {args.field:g} deg, f/{p.fstop:.3g}, {args.method.upper()} method")
    print(f"  {line}")
    if args.output:
        print(f"wrote {args.output}")
    return 0
