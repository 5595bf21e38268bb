"""``physcam characterize --lens LENS ...``: characterize lenses over a grid on Dask (docs/characterize.md).

Examples::

  physcam characterize --lens dgauss_50mm --lens zeiss_distagon_35mm_f4 --focus 0.5m:inf:8 --fstop 2.8,4 --fields 5 -o library/
  physcam characterize --lens dgauss_50mm --focus 1m,2m,inf --fstop 2.8 -o library/ --scheduler tcp://10.0.0.5:8786
  physcam characterize --lens dgauss_50mm --focus 0.5m:inf:8 --fstop 2,2.8,4 -o library/ --dry-run --json
"""

from __future__ import annotations

from ._common import add_lens_argument, whole

from ._output import add_output_options, document, emit_json


def _whole(name: str, lo: int, hi: int):
    """A bounded whole number (:func:`physcam.cli._common.whole`)."""
    return whole(name, lo=lo, hi=hi)


def register(sub) -> None:
    from .analyze import _resolution, _sensor
    from ._common import add_lenient

    p = sub.add_parser("characterize", help="characterize lenses over a grid of focus, f-stop, field and wavelength "
                                            "on Dask: PSF kernels, ST-maps and fitted distortion, breathing, "
                                            "illumination; a Parquet index and USD variants")
    add_lens_argument(p, many=True, metavar="LENS", help="bundled lens names (see `physcam lenses`) or lens files")
    add_lenient(p)
    p.add_argument("--focus", required=True, metavar="MARKS",
                   help="focus marks from the film plane: NEAR:FAR:N = N marks evenly in 1/distance "
                        "(0.5m:inf:8 = 0.5, 0.583, 0.7, 0.875, 1.17, 1.75, 3.5 m, inf), or a list 1m,2m,inf")
    p.add_argument("--zoom", default=None, metavar="Z,Z",
                   help="zoom positions of zoom lenses, comma-separated: focal lengths (70mm,135mm) or encoder "
                        "values 0..1; each lens is characterized at each position, as lens SLUG_zoom_<EFL>mm "
                        "(zoom x focus x iris; docs/zoom.md)")
    p.add_argument("--fstop", default="2.8", metavar="N,N",
                   help="f-numbers, comma-separated (default 2.8)")
    p.add_argument("--fields", type=_whole("fields", 1, 64), default=5, metavar="K",
                   help="field positions from the frame centre to its corner along the diagonal (default 5)")
    p.add_argument("--wavelengths", default=None, metavar="NM,NM",
                   help="wavelengths in nm, comma-separated (default: each lens's design wavelength)")
    p.add_argument("--kinds", default="lens,distortion,illumination,psf", metavar="K,K",
                   help="cell kinds to make: lens (breathing, pupils), distortion (ST-maps, fits), illumination, "
                        "psf (default all)")
    _sensor(p)
    p.add_argument("--resolution", type=_resolution, default=None, metavar="WxH",
                   help="ST-map frame size in pixels (default 2048 wide with square pixels on the sensor: "
                        "2048x1535 on Super 35)")
    p.add_argument("--rays", type=_whole("rays", 1000, 10**9), default=200_000, metavar="N",
                   help="rays per PSF kernel (default 200000)")
    p.add_argument("--psf-pixels", type=_whole("PSF pixels", 8, 1024), default=64, metavar="PX",
                   help="PSF kernel size in pixels per side (default 64)")
    p.add_argument("--grid", type=_whole("illumination grid", 16, 2000), default=100, metavar="N",
                   help="rays per side of the relative-illumination sampling grid (default 100)")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="the library folder (created if missing)")
    p.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                   help="run on an existing Dask cluster (default: a local cluster on this machine)")
    p.add_argument("--workers", type=_whole("workers", 1, 256), default=None, metavar="N",
                   help="worker processes of the local cluster (default: one per core)")
    p.add_argument("--connect-timeout", type=_whole("connect timeout", 1, 600), default=10, metavar="S",
                   help="seconds to wait for --scheduler (default 10)")
    p.add_argument("--retries", type=_whole("retries", 0, 10), default=2, metavar="N",
                   help="times a failed task is retried (default 2; a dead worker's tasks are rescheduled anyway)")
    p.add_argument("--limit", type=_whole("limit", 0, 10**9), default=None, metavar="N",
                   help="compute at most N cells in this run (the next run resumes)")
    p.add_argument("--force-large", action="store_true",
                   help="allow a grid of more than 2000 cells or 2e10 traced rays")
    p.add_argument("--dry-run", action="store_true",
                   help="validate and print the plan (cells to make, cells already done); start no cluster, write "
                        "nothing")
    p.add_argument("--no-usd", action="store_true", help="do not add a characterization variant to the lens USD files")
    add_output_options(p, what="the run's summary")
    p.set_defaults(handler=run_characterize)


def _grid(args):
    from ..characterize.grid import (MAX_FSTOPS, MAX_WAVELENGTHS, Grid, parse_focus_marks, parse_numbers)
    from .analyze import _resolve_sensor

    _resolve_sensor(args)
    return Grid(focus_mm=parse_focus_marks(args.focus),
                fstops=parse_numbers(args.fstop, "f-stops", lo=0.5, hi=128.0, most=MAX_FSTOPS),
                fields=args.fields,
                wavelengths_nm=None if args.wavelengths is None else parse_numbers(
                    args.wavelengths, "wavelengths (nm)", lo=300.0, hi=1100.0, most=MAX_WAVELENGTHS),
                sensor_mm=(args.sensor_width, args.sensor_height), resolution=None if args.resolution is None else tuple(args.resolution),
                psf_rays=args.rays, psf_pixels=args.psf_pixels, illumination_grid=args.grid,
                kinds=tuple(k.strip() for k in str(args.kinds).split(",") if k.strip())).checked()


def characterize_lenses(ns) -> dict:
    """{slug: Prescription} of a characterize command's lenses; with ``--zoom`` each (zoom) lens once per
    zoom position, the prescription there, slug ``<lens>_zoom_<EFL>mm`` and named with its position."""
    from pathlib import Path
    from types import SimpleNamespace

    from ..characterize.grid import lens_slug
    from ..errors import InputError
    from ._zoom import at_zoom_named
    from .lens import load_lens_arg

    zooms = None if getattr(ns, "zoom", None) is None else [z.strip() for z in str(ns.zoom).split(",") if z.strip()]
    if zooms is not None and not zooms:
        raise InputError("--zoom: give zoom positions, e.g. 70mm,135mm,200mm or 0,0.5,1")
    lenses = {}
    for name in ns.lens:
        base = lens_slug(Path(name).stem if ("/" in name or "\\" in name) else name)
        lens = load_lens_arg(name, ns.lenient)
        for z in [None] if zooms is None else zooms:
            at = SimpleNamespace(zoom=z, wavelength=None)
            rx = at_zoom_named(lens, at)
            slug = base if z is None else lens_slug(f"{base}_zoom_{at.zoom_block['efl_mm']:.1f}mm")
            if slug in lenses:
                raise InputError(f"lens {name!r} is given twice" if z is None else
                                 f"zoom {z!r} of {name!r} is a position already given ({slug})")
            lenses[slug] = rx
    return lenses


def run_characterize(args) -> int:
    import sys

    from ..characterize import characterize

    grid = _grid(args)  # every check that needs no lens first: a bad grid costs nothing
    lenses = characterize_lenses(args)
    show = not args.json

    def started(summary):
        if show or sys.stderr.isatty():
            where = summary.scheduler or "?"
            dash = summary.dashboard or "not served (the scheduler has no bokeh)"
            print(f"physcam: {summary.cells - summary.skipped - summary.not_run} of {summary.cells} cells on "
                  f"{summary.workers} workers at {where}; dashboard: {dash}", file=sys.stderr)

    from ._common import progress_bar

    with progress_bar("characterize") as bar:
        summary = characterize(lenses, grid, args.output, scheduler=args.scheduler, workers=args.workers,
                               limit=args.limit, force_large=args.force_large, dry_run=args.dry_run,
                               retries=args.retries, connect_timeout=float(args.connect_timeout),
                               usd=not args.no_usd, progress=bar, on_start=started)
    d = summary.to_dict()
    if args.json:
        emit_json(document("characterize", d))
    else:
        _print(summary, d)
    if summary.failed:
        from ..errors import OpticsError

        f = summary.failed[0]
        raise OpticsError(f"{len(summary.failed)} of {summary.cells} cells failed (first: {f['lens']} {f['kind']} "
                          f"{f['cell']}: {f['error']}); the others are in {summary.output}")
    return 0


def _print(summary, d) -> None:
    kinds = ", ".join(f"{v} {k}" for k, v in summary.cells_by_kind.items())
    lead = "plan" if summary.dry_run else "run " + summary.run_id
    print(f"{lead}: {summary.cells} cells ({kinds}) for {', '.join(summary.lenses)} into {summary.output}")
    if summary.dry_run:
        print(f"  already done: {summary.skipped}; to compute: {summary.not_run}; about "
              f"{summary.estimated_rays:.3g} rays traced")
        return
    print(f"  computed {summary.computed}, already done {summary.skipped}, done by another run {summary.present}, "
          f"failed {len(summary.failed)}, left for a later run {summary.not_run}")
    if summary.computed:
        ov = d["overhead"]
        print(f"  {summary.workers} workers, cluster up in {summary.cluster_start_s:.1f} s, cells in "
              f"{summary.wall_s:.1f} s (compute {summary.compute_s:.1f} s"
              + (f", scheduling and idle {100 * ov:.1f} %" if ov is not None else "") + ")")
    for u in summary.usd:
        print(f"  {u['file']}: variant {u['variant']} (now current; {len(u['variants'])} in the file)")
