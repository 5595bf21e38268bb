"""``physcam defocus IMAGE.exr``: the lens's own depth of field on a pinhole render with depth;
``physcam defocus-kernels``: its PSF stack for other compositors (docs/defocus.md)."""

from __future__ import annotations

from ._common import add_lens_argument, add_sensor_options, focus, number, whole
from ._output import add_output_options, document, emit_json

EPILOG = """\
examples:
  physcam defocus render.exr --depth ViewLayer.Depth.Z --lens dgauss_50mm --focus 2m --fstop 2.8 -o dof.exr
  physcam defocus plate.exr --depth plate_depth.exr --depth-kind inverse --lens dgauss_50mm --focus 3m --fstop 4 -o dof.exr
  physcam defocus shot/render.####.exr --lens dgauss_50mm --focus 2m --fstop 2.8 -o dof/dof.####.exr --workers 4

A sequence (one run of # in IMAGE and OUT) runs frame-parallel on Dask (a local cluster, or
--scheduler), the kernels shared in --kernel-cache (default OUT's folder/kernels); frames whose
output exists are skipped unless --force.

The render must be a pinhole at the lens's entrance pupil with the lens's best-match pinhole focal
length at this focus (physcam report --lens L --focus F --json: pinhole) on the same sensor width.
"""


def register(sub) -> None:
    import argparse

    p = sub.add_parser("defocus", help="apply the lens's own depth of field to a pinhole render with depth (EXR)",
                       description="Scatter each pixel with the lens's traced point spread for its depth and place "
                                   "(field- and depth-dependent: size, cat's eye, iris, vignetting), depth layers "
                                   "composited back to front for occlusion, in linear light.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("image", metavar="IMAGE.exr", help="the pinhole render (linear light), or a sequence IN.####.exr")
    p.add_argument("--depth", metavar="CHANNEL|DEPTH.exr", default=None,
                   help="the depth channel of IMAGE (default: its one Z / *.Depth.Z / depth.Z channel) or an EXR file")
    p.add_argument("--depth-channel", metavar="NAME", default=None,
                   help="the channel of the --depth file holding the depth (default: its one depth channel; a pass "
                        "Blender 5 wrote through the compositor, R = G = B, is read from R)")
    p.add_argument("--depth-kind", choices=("planar", "ray", "inverse"), default=None,
                   help="planar: along the axis from the entrance pupil's plane (Blender's Z); ray: along the pixel's "
                        "ray; inverse: 1/planar (Nuke's depth.Z). Default: inverse for a depth.Z channel, else planar")
    p.add_argument("--depth-unit", choices=("mm", "cm", "m", "in", "ft"), default="m",
                   help="the depth pass's unit (default m, Blender's scene unit)")
    _camera_options(p)
    p.add_argument("-o", "--output", metavar="OUT.exr", required=True,
                   help="the defocused EXR (OUT.####.exr for a sequence)")
    p.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                   help="a sequence: run on an existing Dask cluster (default: a local cluster on this machine)")
    p.add_argument("--workers", type=whole("workers", lo=1, hi=256), default=None, metavar="N",
                   help="a sequence: worker processes of the local cluster (default: one per core)")
    p.add_argument("--edge-px", type=whole("edge px", lo=0, hi=8), default=1, metavar="N",
                   help="give pixels within N of a nearer one its depth (default 1): a render's antialiased edge "
                        "pixels hold foreground light under the background's depth; 0 keeps the depth as given")
    p.add_argument("--kernel-cache", metavar="DIR", default=None,
                   help="keep traced kernels in DIR, shared by later frames of the shot")
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    add_output_options(p, what="a summary")
    p.set_defaults(handler=run)

    k = sub.add_parser("defocus-kernels", help="write the lens's PSF stack (field x depth) as EXR images + index.json",
                       description="The kernels physcam defocus scatters with, for a Nuke or Resolve convolution.",
                       epilog="example:\n  physcam defocus-kernels --lens dgauss_50mm --focus 2m --fstop 2.8 "
                              "--resolution 640x360 --depths 1m,4m -o /tmp/physcam-psf-doc --force\n",
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    _camera_options(k)
    k.add_argument("--resolution", type=_resolution, default=(2048, 1080), metavar="WxH",
                   help="the picture's size in pixels (default 2048x1080)")
    k.add_argument("--field-grid", type=_resolution, default=(5, 3), metavar="NXxNY",
                   help="picture positions, corner to corner (default 5x3)")
    k.add_argument("--depths", default="0.5m,1m,2m,4m,inf", metavar="D1,D2,...",
                   help="planar depths from the entrance pupil (default 0.5m,1m,2m,4m,inf)")
    k.add_argument("-o", "--output", metavar="DIR", required=True, help="folder for the EXR kernels and index.json")
    k.add_argument("--force", action="store_true",
                   help="replace an existing stack (a folder physcam wrote, whole; never a folder of other files)")
    add_output_options(k, what="the index")
    k.set_defaults(handler=run_kernels)


def _camera_options(p) -> None:
    add_lens_argument(p)
    p.add_argument("--focus", type=focus("focus distance"), required=True, metavar="MARK",
                   help="focus mark from the film plane (e.g. 2m, inf, hyperfocal)")
    p.add_argument("--fstop", type=number("f-stop", positive=True), required=True, help="the iris's f-stop")
    p.add_argument("--blades", type=whole("blades", lo=0), default=0, metavar="N", help="iris blades (default 0: round)")
    p.add_argument("--dispersion", action="store_true", help="trace R, G, B at 620, 550, 460 nm (colour fringes)")
    p.add_argument("--tile", type=whole("tile", lo=0), default=64, metavar="PX", help="pixels between field nodes (default 64)")
    p.add_argument("--depth-step", type=number("depth step", positive=True), default=1.0, metavar="PX",
                   help="blur-diameter step between depth nodes near focus (default 1 px)")
    p.add_argument("--depth-step-rel", type=number("relative depth step", lo=0, hi=0.5), default=0.05, metavar="F",
                   help="the step grows by F times the blur diameter (default 0.05: 4 px at 60 px of blur; 0: uniform)")
    add_sensor_options(p)


def _resolution(text):
    import argparse

    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"give WxH in whole numbers, e.g. 2048x1080; got {text!r}") from None
    if not (1 <= w <= 65536 and 1 <= h <= 65536):
        raise argparse.ArgumentTypeError(f"each side must be 1 to 65536, got {text!r}")
    return w, h


def _aperture(args):
    from ..errors import InputError
    from ..trace.aperture import Aperture

    if args.blades == 0:
        return None
    if not 3 <= args.blades <= 32:
        raise InputError(f"--blades must be 0 (round) or 3 to 32, got {args.blades}")
    return Aperture(args.blades)


def run(args) -> int:
    from ..analysis.defocus.exr import defocus_file
    from ..lens.library import load_lens
    from ._common import resolve_focus, resolve_sensor

    lens = load_lens(args.lens)
    sensor = resolve_sensor(args)
    args.focus = resolve_focus(args.focus, lens=lens, fstop=args.fstop, sensor=sensor, args=args)
    cam = _camera(args, lens, sensor)
    opts = dict(depth=args.depth, depth_channel=args.depth_channel, depth_kind=args.depth_kind, depth_unit=args.depth_unit,
                dispersion=args.dispersion, tile=args.tile, step_px=args.depth_step, step_rel=args.depth_step_rel,
                edge_px=args.edge_px)
    if "#" in args.image:
        return _run_sequence(args, cam, opts)
    res = defocus_file(args.image, args.output, cam, kernel_folder=args.kernel_cache, force=args.force,
                       progress=_progress(args), **opts)
    if args.json:
        emit_json(document("defocus", res, units={"length": "mm", "time": "s"}))
        return 0
    pin = f"{res['pinhole_focal_length_mm']:.3f} mm"
    if abs(res["pinhole_focal_length_x_mm"] - res["pinhole_focal_length_mm"]) > 1e-9:
        pin += f" (X {res['pinhole_focal_length_x_mm']:.3f} mm: pixel aspect " \
               f"{res['pinhole_focal_length_mm'] / res['pinhole_focal_length_x_mm']:.4f})"
    print(f"{res['lens']}: {res['pixels'][0]} x {res['pixels'][1]} px defocused at f/{res['fstop']:g} "
          f"({res['kernels_traced']} kernels traced, {res['kernels_loaded']} read, {res['seconds']:.1f} s); pinhole {pin} "
          f"at the entrance pupil, {res['entrance_pupil_from_film_mm']:.3f} mm in front of the film")
    if res["kept_channels"]:
        print(f"kept as read: {', '.join(res['kept_channels'][:8])}{' ...' if len(res['kept_channels']) > 8 else ''}")
    print(f"wrote {res['output']}")
    return 0


def _progress(args):
    """A progress bar on stderr for people (none with --json or when stderr is not a terminal)."""
    import sys

    if getattr(args, "json", False) or not sys.stderr.isatty():
        return None

    def show(done, total):
        sys.stderr.write(f"\rdefocus: depth layer {done}/{total}" + ("\n" if done == total else ""))
        sys.stderr.flush()

    return show


def _camera(args, lens, sensor):
    """The one camera state of a defocus command: the lens at the mark, its iris at the f-stop and of
    its blades, on the sensor."""
    from ..optics.state import camera_state

    return camera_state(lens, focus_mm=args.focus, fstop=args.fstop, sensor_mm=(sensor.width_mm, sensor.height_mm),
                        aperture=_aperture(args))


def _run_sequence(args, cam, opts) -> int:
    from ..extras import require_extra

    require_extra("dask", "a sequence on Dask (physcam defocus IN.####.exr)")
    from ..characterize.defocus_shot import defocus_sequence

    lens = cam.lens
    s = defocus_sequence(args.image, args.output, cam, kernel_folder=args.kernel_cache, scheduler=args.scheduler,
                         workers=args.workers, force=args.force, **opts)
    res = {"images": args.image, "outputs": args.output, "lens": lens.name, "frames_done": s.done,
           "frames_skipped": s.skipped, "kernel_cache": s.kernel_folder, "dashboard": s.dashboard}
    if args.json:
        emit_json(document("defocus_sequence", res, units={"length": "mm"}))
        return 0
    print(f"{lens.name}: {len(s.done)} frame(s) defocused, {len(s.skipped)} skipped (output there; --force redoes "
          f"them); kernels in {s.kernel_folder}")
    return 0


def run_kernels(args) -> int:
    import math

    from ..analysis.defocus.exr import write_kernel_stack
    from ..analysis.defocus.kernels import defocus_camera
    from ..lens.library import load_lens
    from ..units import parse_distance
    from ..extras import require_extra
    from ._common import list_items, resolve_focus, resolve_sensor

    require_extra("exr", "the PSF stack as EXR (physcam defocus-kernels)")
    lens = load_lens(args.lens)
    sensor = resolve_sensor(args)
    args.focus = resolve_focus(args.focus, lens=lens, fstop=args.fstop, sensor=sensor, args=args)
    depths = [parse_distance(t, name="depth", allow_inf=True) for t in list_items(args.depths, "the depths", "1m,4m,inf")]
    cam = defocus_camera(_camera(args, lens, sensor), width=args.resolution[0], height=args.resolution[1],
                         dispersion=args.dispersion, tile=args.tile, step_px=args.depth_step,
                         step_rel=args.depth_step_rel)
    from pathlib import Path

    lens_file = args.lens if Path(str(args.lens)).is_file() else None
    index = write_kernel_stack(args.output, cam, field_grid=args.field_grid, depths_mm=depths, force=args.force,
                               inputs=[lens_file])
    if args.json:
        emit_json(document("defocus_kernels", index, units={"length": "mm"}))
        return 0
    n = len(index["kernels"])
    print(f"{index['lens']}: {n} kernels ({args.field_grid[0]} x {args.field_grid[1]} field x {len(depths)} depths, "
          f"{'inf' if math.isinf(max(depths)) else max(depths)} mm farthest) in {args.output}/ with index.json")
    return 0
