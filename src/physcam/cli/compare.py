"""``physcam compare blender``: the same point light through physcam's tracer and through Cycles."""

from __future__ import annotations

from ._common import distance, number, print_json

EPILOG = """\
example:
  physcam compare blender dgauss_50mm --focus 2m --fstop 2.8 --light 0.7m --blades 6 -o cmp/
Writes cmp/compare.png (the two images side by side) and cmp/compare.json (the measured table).
Needs a Python with Blender's bpy: `make blender` builds .venv-blender (or --blender-python PATH).
"""


def register(sub) -> None:
    import argparse

    p = sub.add_parser("compare", help="side by side: physcam's own tracer against a renderer (Blender)",
                       description="Render one point light through physcam's OSL camera in Blender and trace it "
                                   "with physcam; measure both (docs/blender.md).", epilog=EPILOG,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    s = p.add_subparsers(dest="compare_command", metavar="RENDERER")
    b = s.add_parser("blender", help="Cycles through physcam's OSL lens camera", epilog=EPILOG,
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    b.add_argument("lens", metavar="NAME_OR_FILE", help="bundled lens name (see `physcam lenses`) or a lens file")
    b.add_argument("--focus", type=distance("focus distance"), required=True, metavar="D",
                   help="focus mark from the film plane (e.g. 2m)")
    b.add_argument("--fstop", type=number("f-number", positive=True), required=True, metavar="N", help="f-number")
    b.add_argument("--light", type=distance("light distance"), required=True, metavar="D",
                   help="the point light's distance from the film plane, on the axis (e.g. 0.7m)")
    b.add_argument("--blades", type=int, default=0, metavar="N", help="iris blades (0: round; 3 or more: a polygon)")
    b.add_argument("--blade-angle", type=number("blade angle"), default=0.0, metavar="DEG",
                   help="angle of the first iris corner, degrees")
    b.add_argument("--crop", type=distance("crop"), default=3.0, metavar="MM",
                   help="width of the film crop around the axis that both images cover (default 3 mm)")
    b.add_argument("--pixels", type=int, default=128, help="image width and height in pixels (32 to 1024)")
    b.add_argument("--samples", type=int, default=512, help="Cycles samples per pixel (default 512)")
    b.add_argument("--blender-python", metavar="PATH",
                   help="a Python with Blender's bpy (default: $PHYSCAM_BLENDER_PYTHON or ./.venv-blender)")
    b.add_argument("--lenient", action="store_true", help="load a lens file that is not buildable as written, repaired")
    b.add_argument("-o", "--output", required=True, metavar="DIR", help="folder for compare.png and compare.json")
    b.add_argument("--force", action="store_true", help="overwrite existing files")
    b.add_argument("--json", action="store_true", help="print the measured table as JSON")
    b.set_defaults(handler=run_blender)
    p.set_defaults(handler=lambda args: (p.print_help(), 0)[1])


def run_blender(args) -> int:
    import json
    from pathlib import Path

    from ..errors import InputError
    from ..export.blender_compare import compare_bokeh
    from ..io import atomic_write, check_writable
    from ..lens.library import load_lens
    from ..trace.aperture import Aperture

    out = Path(args.output)
    png, js = out / "compare.png", out / "compare.json"
    for f in (png, js):
        check_writable(f, force=args.force)
    if not (args.blades == 0 or 3 <= args.blades <= 64):
        raise InputError(f"--blades must be 0 (round) or 3 to 64, got {args.blades}")
    aperture = Aperture(args.blades, args.blade_angle) if args.blades else None
    lens = load_lens(args.lens, lenient=args.lenient)
    res = compare_bokeh(lens, focus_mm=args.focus, fstop=args.fstop, light_mm=args.light, aperture=aperture,
                        crop_mm=args.crop, pixels=args.pixels, samples=args.samples,
                        blender_python=args.blender_python)
    table = {k: v for k, v in res.items() if k != "images"}
    atomic_write(js, json.dumps(table, indent=2, allow_nan=False) + "\n", force=args.force)
    _figure(res, png, force=args.force)
    if args.json:
        print_json(dict(table, files=[str(png), str(js)]))
        return 0
    m = table["measured"]
    d = m["equivalent_diameter_mm"]
    print(f"{res['lens']}: light {res['light_from_film_mm'] / 1000:g} m from the film, focus "
          f"{res['focus_from_film_mm'] / 1000:g} m, f/{res['fstop']:g}")
    print(f"  bokeh diameter: Cycles {d['cycles']:.4f} mm, physcam {d['physcam']:.4f} mm, ratio {d['ratio']:.4f}")
    if "corners" in m:
        print(f"  iris corners: Cycles {m['corners']['cycles']}, physcam {m['corners']['physcam']}")
    print(f"wrote {png} and {js}")
    return 0


def _figure(res, path, *, force):
    import numpy as np

    from ..figures import pyplot, save_figure

    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(7.4, 3.8))
    h = res["crop_mm"] / 2
    for ax, key, title in zip(axes, ("physcam", "cycles"), ("physcam (numba tracer)", "Cycles (OSL camera)")):
        img = res["images"][key]
        top = float(np.percentile(img[img > 0], 90)) if (img > 0).any() else 1.0  # render noise: not the max
        ax.imshow(np.clip(img / top, 0, 1), origin="lower", extent=(-h, h, -h, h), cmap="magma")
        d = res["measured"]["equivalent_diameter_mm"][key]
        ax.set_title(f"{title}\nequivalent diameter {d:.4f} mm", fontsize=9)
        ax.set_xlabel("film x (mm)")
    axes[0].set_ylabel("film y (mm)")
    fig.suptitle(f"{res['lens']}: light {res['light_from_film_mm'] / 1000:g} m, focus "
                 f"{res['focus_from_film_mm'] / 1000:g} m, f/{res['fstop']:g}", fontsize=10)
    return save_figure(fig, path, force=force)
