"""``physcam demo``: the main job on the bundled default lens and sensor.

The default setup is the bundled ``dgauss_50mm`` (pbrt's double Gauss, US 2,673,491) on an
ARRI ALEXA 35 open gate at f/2.8, focused 3 m from the film plane. The demo writes a folder,
whole (``physcam.io.staged_folder``: a killed run leaves no half of one; ``--force`` replaces a demo
folder physcam wrote), and prints the report:

- ``report.json`` / ``report.txt``: the lens report, technical model filled from the lens
  itself, with its UsdGeomCamera and RenderMan blocks; ``dof.png``: the depth-of-field chart (near
  and far against focus, a band per stop);
- ``lens.json``: the lens's Gaussian data at that focus; ``lens_diagram.png``: elements, stop,
  rays and cardinal points; ``breathing.png``: field of view against focus distance;
- ``camera.usda``: the PhysicalCamera and its companion UsdGeomCamera;
- ``spot.png`` and ``bokeh.png``: real-ray spot diagram and bokeh of a point light;
  ``bokeh_photo.exr`` / ``.png``: that bokeh as a photograph (linear, and tone-mapped with a scale
  bar in the sensor's pixels);
- ``lens_card.pdf``: the lens's one-page card (section, MTF, distortion, illumination, breathing,
  bokeh, key numbers; docs/lens-card.md);
- ``distortion/``: ST-maps (EXR, with PNG previews) of the lens at that focus on that sensor, its
  fitted Brown-Conrady (OpenTrackIO) and 3DE4 models, and a Nuke script applying the maps
  (docs/distortion.md);
- ``blender/``: the real-lens OSL camera shader and its set-up script for Blender Cycles, and a
  script matching Blender's built-in camera to the report, and the physcam Blender extension
  (``physcam-<version>.zip`` with the default lens only, to keep the demo quick; ``make
  blender-extension`` ships every bundled lens; docs/blender.md).
"""

from __future__ import annotations

DEFAULTS = {
    "lens": "dgauss_50mm",
    "fstop": 2.8,
    "focus": 3000.0,
    "sensor": "ALEXA 35",
}


def register(sub) -> None:
    p = sub.add_parser("demo", help="run the main job on the default lens and sensor, writing a folder of outputs")
    from ._common import FOLDER_FORCE_HELP, hidden_alias
    from ._output import add_output_options

    p.add_argument("-o", "--output", dest="out", default="demo-output", metavar="DIR",
                   help="folder to write (default demo-output)")
    hidden_alias(p, "--out", "out")
    p.add_argument("--force", action="store_true", help=FOLDER_FORCE_HELP)
    from ._common import add_units_option

    add_units_option(p)
    add_output_options(p, what="the list of written files")
    p.set_defaults(handler=run, output_folders=("out",))


def _args():
    from argparse import Namespace

    return Namespace(
        lens=DEFAULTS["lens"], focal=None, fstop=DEFAULTS["fstop"], tstop=None, focus=DEFAULTS["focus"],
        sensor=DEFAULTS["sensor"], sensor_width=None, sensor_height=None, squeeze=1.0, coc=None,
        near=None, far=None, model="technical", h1=None, h2=None, pupil=None, reference="film", flange=None,
        sensor_front=None, lens_length=None, pupil_fraction=None, meters_per_unit=0.01, shutter_angle=180.0,
    )


def _steps():
    """(name, function(out_dir, context, force) -> list of written paths), in order."""
    return [
        ("lens report", _report_step),
        ("Gaussian data and diagram", _lens_step),
        ("USD camera", _usd_step),
        ("a clip's recorded metadata as a USD camera", _metadata_step),
        ("spot diagram and bokeh", _trace_step),
        ("lens card", _card_step),
        ("distortion maps and models", _distortion_step),
        ("Blender cameras", _blender_step),
    ]


def report_text(report, units: str = "m"):
    """(the Table, the note lines) that `physcam report` prints: report.txt holds the table's plain
    text, every cell whole (a rich table captured at 80 columns drew a box and folded the cells)."""
    from ..onset.table import report_rows, report_title
    from ._output import Table

    table = Table(report_title(report), ("quantity", "value", "measured from"))
    for r in report_rows(report, units, notes=False):
        table.add_row(*r)
    return table, "".join(f"note: {n}\n" for n in report.notes)


def _report_step(out, ctx, force):
    import json

    from ..io import atomic_write
    from ..onset.dof_plot import plot_dof_chart
    from .report import camera_blocks, dof_chart_solver, solve_from_args

    ns = _args()
    report = solve_from_args(ns)
    ctx["report"] = report
    d = report.to_dict()
    d["cameras"] = camera_blocks(report, ns)
    ctx["table"], ctx["notes"] = report_text(report, ctx.get("units", "m"))
    table = ctx["table"]
    return [
        atomic_write(out / "report.json", json.dumps(d, indent=2, allow_nan=False) + "\n", force=force),
        atomic_write(out / "report.txt", table.plain() + ctx["notes"], force=force),
        plot_dof_chart(report, dof_chart_solver(ns, report), out / "dof.png", force=force,
                       units=ctx.get("units", "m")),
    ]


def _lens_step(out, ctx, force):
    import json
    import math

    from ..analysis.framing.breathing_plot import save_breathing_plot
    from ..analysis.lens_cards.diagram import save_lens_diagram
    from ..io import atomic_write
    from ..lens.library import load_lens
    from ..optics import focusing
    from ..optics.state import camera_state

    lens = load_lens(DEFAULTS["lens"])
    ctx["lens"] = lens
    st = focusing.focus(lens, DEFAULTS["focus"])
    g = focusing.gaussian_at_focus(lens, DEFAULTS["focus"], fstop=DEFAULTS["fstop"])
    data = {"lens": lens.name, "focus_from_film_mm": DEFAULTS["focus"], "fstop": DEFAULTS["fstop"],
            "back_focus_mm": st.back_focus_mm, "gaussian": g.to_dict()}
    text = json.dumps(data, indent=2, allow_nan=False, default=lambda v: None if isinstance(v, float)
                      and not math.isfinite(v) else str(v))
    sensor = ctx["report"].sensor
    rows = focusing.breathing_table(lens, [600.0, 1000.0, 2000.0, 5000.0, math.inf], sensor_width_mm=sensor.width_mm)
    return [
        atomic_write(out / "lens.json", text + "\n", force=force),
        save_lens_diagram(camera_state(lens, fstop=DEFAULTS["fstop"]), out / "lens_diagram.png", force=force,
                          units=ctx.get("units", "m")),
        save_breathing_plot(rows, out / "breathing.png", force=force, title=f"focus breathing: {lens.name}",
                            sensor_width_mm=sensor.width_mm, units=ctx.get("units", "m")),
    ]


def _usd_step(out, ctx, force):
    from ..usd.author import author_from_report, new_stage, save_stage

    stage = new_stage(0.01)
    author_from_report(stage, "/Camera", ctx["report"])
    return [save_stage(stage, out / "camera.usda", force=force)]


def _metadata_step(out, ctx, force):
    """The camera metadata a cinema camera recorded (a 48-frame excerpt of an ARRI ALEXA LF clip, bundled;
    docs/camera-metadata.md) as one animated USD camera: its focus, iris and focal length per frame."""
    from importlib import resources

    from ..metadata import load
    from ..metadata.convert import solve, write_usd

    clip = resources.files("physcam.data").joinpath("samples/arri_alexa_lf_B001C001_first48.csv")
    with resources.as_file(clip) as path:
        record = load(path)
    return [write_usd(out / "clip_camera.usda", record, solve(record), force=force)]


def _trace_step(out, ctx, force):
    from ..analysis.defocus.bokeh import bokeh_image
    from ..analysis.image_quality.spot import spot_diagram
    from ..optics.state import as_designed, camera_state
    from ..trace.aperture import Aperture

    lens = ctx["lens"]
    spot = spot_diagram(as_designed(lens), (0.0, 5.0, 10.0))  # the lens as designed: infinity, wide open
    # a point light 1.2 m from the film, off axis, with the lens focused at 3 m and stopped to
    # f/2.8 by a 7-blade iris: the defocus blur shows the iris and cat's-eye vignetting
    s = ctx["report"].sensor
    state = camera_state(lens, focus_mm=DEFAULTS["focus"], fstop=DEFAULTS["fstop"], sensor_mm=(s.width_mm, s.height_mm),
                         aperture=Aperture(nsides=7, roundness=0.2))
    bokeh = bokeh_image(state, 1200.0, 250.0, 150.0, rays=400_000, pixels=160, spectral=True)
    from ..analysis.defocus.bokeh import write_bokeh_photo

    photo = write_bokeh_photo(bokeh, out / "bokeh_photo", pixel_pitch_um=s.pitch_um or s.width_mm * 1000.0 / 4096,
                              sensor_name=s.name, force=force)
    return [spot.plot(out / "spot.png", force=force), bokeh.plot(out / "bokeh.png", force=force), *photo]


def _card_step(out, ctx, force):
    """The default lens's one-page card (A4) on the demo's sensor, focused at infinity."""
    from ..analysis.lens_cards.card import lens_card, save_lens_card

    s = ctx["report"].sensor
    card = lens_card(ctx["lens"], sensor_width_mm=s.width_mm, sensor_height_mm=s.height_mm, sensor_name=s.name)
    return [save_lens_card(card, out / "lens_card.pdf", force=force, units=ctx.get("units", "m"))]


def _distortion_step(out, ctx, force):
    """ST-maps at the demo's focus and sensor, the fitted models' files and the Nuke script."""
    import json

    from .. import __version__
    from ..analysis.distortion.models import fit_brown_conrady, fit_tde4_radial, samples_from_field
    from ..analysis.distortion.stmap import distortion_field, write_stmaps
    from ..export.nuke import nuke_stmap_script
    from ..export.tde4 import tde4_lens_text
    from ..optics.state import camera_state
    from ..io import atomic_write

    s = ctx["report"].sensor
    w = 1920
    h = max(16, round(w * s.height_mm / s.width_mm))
    camera = camera_state(ctx["lens"], focus_mm=DEFAULTS["focus"], sensor_mm=(s.width_mm, s.height_mm))  # chief rays
    res = distortion_field(camera, width_px=w, height_px=h)
    d = out / "distortion"
    paths = write_stmaps(res, d, force=force)
    smp = samples_from_field(res)
    brown = [fit_brown_conrady(smp, "D-U"), fit_brown_conrady(smp, "U-D")]
    tde4 = fit_tde4_radial(smp)
    from .distortion import brown_conrady_document

    doc = brown_conrady_document(res.lens_name, brown)
    ox, oy = res.overscan_px
    final = ctx.get("final", out) / "distortion"  # where the maps will be once the demo folder is published
    nk = nuke_stmap_script(final.resolve() / "undistortion.exr", final.resolve() / "distortion.exr", plate_size=(w, h),
                           undistorted_size=(w + 2 * ox, h + 2 * oy), version=__version__)
    paths += [atomic_write(d / "brown_conrady.json", json.dumps(doc, indent=2) + "\n", force=force),
              atomic_write(d / "3de4_radial_standard_degree_4.txt", tde4_lens_text(tde4, res.lens_name), force=force),
              atomic_write(d / "physcam_stmap.nk", nk, force=force)]
    return paths


def _blender_step(out, ctx, force):
    """The real-lens OSL camera and its set-up script, and Blender's built-in camera matched to the report."""
    from ..export.blender import write_blender_camera
    from ..export.blender_camera import blender_camera_script, blender_camera_values
    from ..io import atomic_write
    from ..optics.state import camera_state
    from ..trace.aperture import Aperture

    report = ctx["report"]
    s = report.sensor
    width = 1920
    height = max(1, round(width * s.height_mm / s.width_mm))
    camera = camera_state(ctx["lens"], focus_mm=DEFAULTS["focus"], fstop=DEFAULTS["fstop"],
                          sensor_mm=(s.width_mm, s.height_mm), aperture=Aperture(nsides=7, roundness=0.2))
    osl, setup = write_blender_camera(camera, out / "blender", resolution=(width, height), name=DEFAULTS["lens"],
                                      force=force)
    values = blender_camera_values(report, resolution_x=width, blades=7)
    builtin = atomic_write(out / "blender" / f"builtin_{DEFAULTS['lens']}.py", blender_camera_script(values),
                           force=force)
    from ..export.blender_extension import build_extension

    # the default lens only (one lens's focus table is ~10 s; every lens is `make blender-extension`)
    return [osl, setup, builtin, build_extension(out / "blender", lenses=[DEFAULTS["lens"]], force=force)]


def run(args) -> int:
    from pathlib import Path

    from ._common import console, output_folder, relocated, units_of
    from ._output import document, emit_json, print_table

    from ..extras import require_extra

    require_extra("usd", "the demo's USD cameras (physcam demo)")  # before any file is written
    out = Path(args.out)
    ctx: dict = {"units": units_of(args), "final": out}  # scene distances on the plots: --units, else the config's
    written = []
    err = console(stderr=True)
    with output_folder(out, force=args.force, command="demo") as tmp:  # the folder is written whole, at the end
        for name, step in _steps():
            paths = relocated(step(tmp, ctx, False), tmp, out)
            written.extend(paths)
            if not args.json:
                err.print(f"{name}: " + ", ".join(str(p) for p in paths))
    if args.json:
        emit_json(document("demo", {"out": str(out), "files": [str(p) for p in written]}))
        return 0
    print_table(ctx["table"])
    print(ctx["notes"], end="")
    return 0
