"""Issue 33, render proof of ``physcam calibrate``: a checkerboard photographed through physcam's own
OSL real-lens camera of ``zeiss_distagon_35mm_f4`` (Blender Cycles, traced through the prescription)
at two focus marks, calibrated by ``physcam calibrate --lens``, agrees with physcam's prediction from
the prescription: the pinhole focal length and the distortion field within the stated uncertainty,
and the breathing between the marks within 0.2 %.

The two sides are independent: Cycles renders through the OSL shader's float32 ray trace (film to
scene, the chart a textured emissive plane), the chart is found by OpenCV and fitted by OpenCV's
calibration; the prediction is physcam's numpy tracer's paraxial pinhole at the mark and its real
chief rays (:func:`physcam.analysis.distortion.stmap.distortion_field`).

The far mark's chart is the near one scaled by the ratio of the marks (a bigger board, so that it
fills the frame as well): a chart's size enters only the poses OpenCV fits, never the pinhole or the
distortion, so one ``--square`` serves both marks.

What makes the 0.2 % affordable (docs/calibrate.md, "How well it measures", has the numbers): the
breathing's error is Cycles' sampling noise in the corners (no model error: 0.005 %), so the test
buys corner precision per second of rendering. (1) Adaptive sampling (at most 48 samples, threshold
0.01, at least 8): a textured emissive plane's flat pixels converge at once, the edges get the
samples. (2) A 1 px pixel filter instead of Cycles' 1.5 px: sharper edges, 28 % less corner noise per
sample. (3) A checkerboard of 14 x 9 inner corners instead of a 10 x 7 ChArUco board: 126 corners a
view instead of ~48, every one refined in a window scaled to its squares (a ChArUco corner's window
stops at the markers); a checkerboard must be seen whole, so the board is small (16 mm squares at
600 mm, about 17 px) and pushed toward the frame's corners, so that the distortion field is measured
out to them (a 20 mm board pushed less missed the corners, and the field there by up to 2.4 px).
Per render the corners then scatter by 0.065 px RMS (two seeds' difference over sqrt 2) in 2.7 s a
view, where 8 plain samples of the ChArUco board gave 0.29 px in 1.3 s and 128 plain samples 0.065-0.074
px in 6.5-10 minutes for the 16 views.

Measured (2 shared CPU cores, load 1.7-1.9; 16 renders of 640 x 427 px; ``PHYSCAM_CALIBRATE_RENDER_SEED``
0-4, five draws of the render noise): the test 52-60 s (rendering 43-47 s); breathing +0.076, +0.118,
-0.096, +0.138, +0.118 % from the predicted 2.488 % (stated uncertainty 0.13-0.20 %): all within
0.2 %; pinholes within 0.1 % of the prediction (+-0.03 mm at 600 mm, +-0.03-0.07 mm at 1500 mm);
distortion field 0.02-0.14 px RMS from the prediction, all within the stated uncertainty. At 96
samples (test 71-75 s; corners 0.044 px per render) the breathing is no better (+0.032, +0.123, -0.003,
+0.163, +0.086 %): what is left, about +0.08 % on average, is not sampling noise. Checked on
these 16 views (docs/calibrate.md, "How well it measures"): the model is not it
(corners placed by the prediction: -0.0006 %); the chart's depth is +0.013 % (each corner where its
real chief ray lands, the tilted chart 540-670 mm and 1350-1680 mm from the film); and the 1 px
pixel filter's pixel locking (the corners found are pushed 0.05 px x sin(2 pi x their fraction of a
pixel) toward the pixel edges, the same in every seed) about +0.02 % (Cycles' 1.5 px filter: 0.033 px
of locking, breathing +0.034, +0.100, -0.137, +0.145, +0.103 % for seeds 0-4, 0.022 % less on
average, giving up the 1 px filter's 28 % less corner noise). The rest (0.03 px per corner
that every seed shares besides) is not identified. Under heavy load (load 4.5 from other jobs) the
test takes about twice as long.

Each view is rendered only in a render border about the chart (:func:`_border`; black outside it,
``use_crop_to_border`` off): the black world around a small chart took two thirds of the frame's
samples (8 a pixel at least, adaptive sampling's floor) and none of its information. Cycles seeds a
pixel's samples by its place in the frame, so the pictures are the full frame's bit for bit (all 16
views checked against a full-frame run, 2026-11-28), and so are the measured figures (seed 0:
breathing +0.076 % of 0.2 %, pinholes -0.016 and +0.011 mm with uncertainties 0.040 and 0.029 mm,
distortion fields 0.022 and 0.113 px RMS against 2 x 0.124 and 2 x 0.075 px). The pytest run of this
file took 114.6 s CPU with full frames and 70.6 s with the border (``/usr/bin/time``, side by side, load
10-16).

The 16 renders keep Cycles' scene from one to the next (``use_persistent_data``): every picture's pixels the
same (all 16 views, twice, 2026-11-30), Blender's CPU 61.8, 64.7 s -> 59.0, 59.5 s (two pairs, load 9-10).
"""

from __future__ import annotations

import csv
import json
import os
import time

import numpy as np
import pytest

from _blender import DARK_SCENE_CAMERA_AT_FILM, run_blender
from physcam.export.blender import blender_setup_script, osl_camera_shader
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state

cv2 = pytest.importorskip("cv2")
pytestmark = pytest.mark.slow

LENS = "zeiss_distagon_35mm_f4"
MARKS_MM = (600.0, 1500.0)  # focus marks, mm from the film
FSTOP = 11.0  # depth of field for the tilted chart: blur <= 0.7 px over +-100 mm at 600 mm
SIZE = (640, 427)
SENSOR_MM = (36.0, 36.0 * SIZE[1] / SIZE[0])  # square photosites, 56.25 um
SQUARES, SQUARE_MM = (15, 10), 16.0  # a checkerboard of 14 x 9 inner corners (240 x 160 mm at 600 mm)
MARGIN = 0.5  # white border around the squares, in squares (the detector needs the outer squares' edges)
POSES = 8  # per mark
PUSH = (0.20, 0.12)  # the views' push toward the frame's corners, over the distance (the board stays whole)
#: Cycles' most samples per pixel, adaptive sampling on (module notes)
SAMPLES = int(os.environ.get("PHYSCAM_CALIBRATE_RENDER_SAMPLES", "48"))
ADAPTIVE_THRESHOLD, ADAPTIVE_MIN_SAMPLES = 0.01, 8
FILTER_PX = 1.0  # Cycles' Blackman-Harris pixel filter width (default 1.5): sharper edges, less corner noise
#: Cycles' sampling seed (PHYSCAM_CALIBRATE_RENDER_SEED: another draw of the render noise)
SEED = int(os.environ.get("PHYSCAM_CALIBRATE_RENDER_SEED", "0"))
#: The render border about the chart (module notes): the chart seen through a pinhole at the lens's entrance
#: pupil (physcam's report at the marks: 61.8 and 60.3 mm in front of the film, pinholes 36.6 and 35.7 mm),
#: and a margin (the rendered chart's edges lie within 1.3 px of that pinhole's outline). 6 px, not the 24 it was:
#: the black ring between them is adaptive sampling's 8 samples a pixel of nothing, 13 % of the renders' CPU; the
#: pictures are the same bit for bit (six views rendered with both, 2026-11-30: Blender 25.4, 24.7 s -> 22.4, 21.0 s)
BORDER_PUPIL_MM, BORDER_FOCAL_MM, BORDER_PAD_PX = 61.0, 36.6, 6
#: From this many samples the corners are good to <= 0.06 px RMS and the breathing is asserted within 0.2 %
PROOF_SAMPLES = 48

#: Renders one textured emissive plane per job through each mark's physcam setup script into PNG.
SCENE = '''
import json, runpy, sys
jobs = json.loads(open(sys.argv[1]).read())
''' + DARK_SCENE_CAMERA_AT_FILM + '''mat = bpy.data.materials.new("chart"); mat.use_nodes = True
nt = mat.node_tree; nt.nodes.clear()
tex = nt.nodes.new("ShaderNodeTexImage"); tex.image = bpy.data.images.load(jobs["board"])
tex.interpolation = "Linear"; tex.extension = "CLIP"
em = nt.nodes.new("ShaderNodeEmission"); em.inputs["Strength"].default_value = 1.0
nt.links.new(tex.outputs["Color"], em.inputs["Color"])
nt.links.new(em.outputs[0], nt.nodes.new("ShaderNodeOutputMaterial").inputs[0])
setup = None
scene.render.use_persistent_data = True  # Cycles keeps its scene from one view to the next (module notes)
for job in jobs["renders"]:
    if job["setup"] != setup:
        runpy.run_path(job["setup"], run_name="physcam_setup")["apply"](scene)
        setup = job["setup"]
    scene.cycles.use_denoising = False
    scene.render.threads_mode = "FIXED"
    scene.render.threads = 2
    scene.view_settings.view_transform = "Standard"
    scene.cycles.max_bounces = 0
    scene.cycles.samples = jobs["samples"]
    scene.cycles.use_adaptive_sampling = True  # flat pixels stop early: the edges get the samples
    scene.cycles.adaptive_threshold = jobs["adaptive_threshold"]
    scene.cycles.adaptive_min_samples = jobs["adaptive_min_samples"]
    scene.cycles.seed = jobs["seed"]
    scene.cycles.filter_width = jobs["filter_px"]
    for o in list(bpy.data.objects):
        if o.type == "MESH":
            bpy.data.objects.remove(o)
    me = bpy.data.meshes.new("chart")
    me.from_pydata(job["corners"], [], [(0, 1, 2, 3)])
    uv = me.uv_layers.new()
    for li, loop in enumerate(me.loops):
        uv.data[li].uv = job["uv"][loop.vertex_index]
    ob = bpy.data.objects.new("chart", me); scene.collection.objects.link(ob)
    me.materials.append(mat)
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "BW"
    scene.render.use_border = True; scene.render.use_crop_to_border = False  # black outside the chart's border
    (scene.render.border_min_x, scene.render.border_max_x, scene.render.border_min_y,
     scene.render.border_max_y) = job["border"]
    scene.render.filepath = job["out"]
    bpy.ops.render.render(write_still=True)
print(json.dumps({"rendered": len(jobs["renders"])}))
'''


def _poses(mark, n, seed):
    """``n`` chart poses (R, t) in OpenCV's camera frame (mm), the chart about ``mark`` from the film,
    tilted up to 30 degrees, pushed toward every corner of the frame in turn (:data:`PUSH`), whole."""
    rng = np.random.default_rng(seed)
    scale = mark / MARKS_MM[0]
    centre = scale * SQUARE_MM * np.array([SQUARES[0] / 2, SQUARES[1] / 2, 0.0])
    out = []
    for i in range(n):
        ax, ay = np.radians(rng.uniform(-30, 30, 2))
        az = np.radians(rng.uniform(-10, 10))
        R = cv2.Rodrigues(np.array([ax, 0, 0]))[0] @ cv2.Rodrigues(np.array([0, ay, 0]))[0] @ \
            cv2.Rodrigues(np.array([0, 0, az]))[0]
        z = mark * rng.uniform(0.97, 1.03)
        corner = np.array([(-1) ** i, (-1) ** (i // 2)]) * (PUSH if i < n - 2 else [0.0, 0.0])
        shift = (corner + rng.uniform(-0.03, 0.03, 2)) * z
        out.append((R, np.array([shift[0], shift[1], z]) - R @ centre, scale))
    return out


def _board(px_per_square=64):
    """The checkerboard's picture, with its white margin (uint8)."""
    j, i = np.mgrid[0:SQUARES[1] * px_per_square, 0:SQUARES[0] * px_per_square] // px_per_square
    img = np.where((i + j) % 2 == 0, 0, 255).astype(np.uint8)
    return np.pad(img, int(MARGIN * px_per_square), constant_values=255)


def _job(R, t, scale, out):
    """The chart's four corners (margin included) in Blender's camera frame (m; OpenCV's y and z negated)
    and their UVs."""
    w, h = SQUARES[0] * SQUARE_MM * scale, SQUARES[1] * SQUARE_MM * scale
    m = MARGIN * SQUARE_MM * scale
    chart = np.array([[-m, -m, 0], [w + m, -m, 0], [w + m, h + m, 0], [-m, h + m, 0]], float)
    cam = (chart @ R.T + t) * [1.0, -1.0, -1.0] / 1000.0
    return {"corners": cam.tolist(), "uv": [[0, 1], [1, 1], [1, 0], [0, 0]], "out": str(out), "border": _border(chart @ R.T + t)}


def _border(points_mm):
    """Cycles' render border about the chart (fractions of the frame, y up): its corners (OpenCV's camera
    frame, mm from the film centre) through a pinhole of :data:`BORDER_FOCAL_MM` at :data:`BORDER_PUPIL_MM`,
    :data:`BORDER_PAD_PX` more each way."""
    pitch = SENSOR_MM[0] / SIZE[0]
    z = points_mm[:, 2] - BORDER_PUPIL_MM
    u = SIZE[0] / 2 + BORDER_FOCAL_MM * points_mm[:, 0] / z / pitch
    v = SIZE[1] / 2 + BORDER_FOCAL_MM * points_mm[:, 1] / z / pitch  # down
    x0, x1 = np.clip([u.min() - BORDER_PAD_PX, u.max() + BORDER_PAD_PX], 0, SIZE[0]) / SIZE[0]
    y0, y1 = np.clip([v.min() - BORDER_PAD_PX, v.max() + BORDER_PAD_PX], 0, SIZE[1]) / SIZE[1]
    return [float(x0), float(x1), float(1 - y1), float(1 - y0)]


@pytest.fixture(scope="module")
def photographs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("calibrate_render")
    lens = load_lens(LENS)
    cv2.imwrite(str(tmp / "board.png"), _board())
    renders, rows = [], []
    for k, mark in enumerate(MARKS_MM):
        src = osl_camera_shader(camera_state(lens, focus_mm=mark, fstop=FSTOP, sensor_mm=SENSOR_MM))
        setup = tmp / f"mark{k}.py"
        setup.write_text(blender_setup_script(src, sensor_width_mm=SENSOR_MM[0], sensor_height_mm=SENSOR_MM[1],
                                              resolution=SIZE, text_name=f"mark{k}.osl"))
        for i, (R, t, scale) in enumerate(_poses(mark, POSES, seed=k + 1)):
            out = tmp / f"m{k}_{i:02d}.png"
            renders.append(dict(_job(R, t, scale, out), setup=str(setup)))
            rows.append([out.name, f"{mark:g}mm"])
    jobs = tmp / "jobs.json"
    jobs.write_text(json.dumps({"board": str(tmp / "board.png"), "samples": SAMPLES, "seed": SEED, "renders": renders,
                                "adaptive_threshold": ADAPTIVE_THRESHOLD, "filter_px": FILTER_PX,
                                "adaptive_min_samples": ADAPTIVE_MIN_SAMPLES}))
    with (tmp / "marks.csv").open("w", newline="") as f:
        csv.writer(f).writerows([["image", "mark"], *rows])
    t0 = time.perf_counter()
    run_blender(SCENE, str(jobs), timeout=max(600, 6 * SAMPLES * POSES))
    return tmp, time.perf_counter() - t0


def test_the_rendered_lens_measures_as_its_prescription(photographs, tmp_path, capsys):
    from physcam.cli import main

    tmp, seconds = photographs
    images = sorted(str(p) for p in tmp.glob("m*_*.png"))
    rc = main(["calibrate", *images, "--marks", str(tmp / "marks.csv"), "--sensor-width", f"{SENSOR_MM[0]}",
               "--sensor-height", f"{SENSOR_MM[1]}", "--chart", "checkerboard",
               "--corners", f"{SQUARES[0] - 1}x{SQUARES[1] - 1}", "--square", f"{SQUARE_MM}mm",
               "--lens", LENS, "--bootstrap", "20", "-o", str(tmp_path / "calib"), "--json"])
    assert rc == 0, capsys.readouterr().err
    doc = json.loads(capsys.readouterr().out)
    rows = {r["figure"]: r for r in doc["comparison"]["rows"]}
    print(f"rendered in {seconds:.0f} s;", json.dumps(rows, indent=1))
    for mark in MARKS_MM:
        f = rows[f"pinhole focal length at {mark:g} mm"]
        assert f["agrees"], f  # within 2 standard uncertainties of the paraxial pinhole at the mark
        d = rows[f"distortion field at {mark:g} mm (RMS difference)"]
        assert d["agrees"], d
    b = rows[f"breathing {MARKS_MM[0]:g} mm against {MARKS_MM[1]:g} mm"]
    assert b["agrees"], b  # within 2 stated standard uncertainties (percent)
    if SAMPLES >= PROOF_SAMPLES:  # render noise low enough for the 0.2 % (module notes)
        assert abs(b["difference"]) <= 0.2, b
    else:  # fewer samples: more render noise in the corners (as 1/sqrt(samples)), so the 0.2 % is not
        # shown; assert the uncertainty is stated
        assert 0.02 < b["std"] < 1.5, b
    # the corners sit on the fitted camera to the render's noise (the verdict may still reject USD's
    # lensDistortion at 600 mm: it misses this Distagon's field by ~0.8 px, a limit of that model)
    assert all(m["residual_px"]["rms"] < 0.5 for m in doc["marks"]), [m["residual_px"]["rms"] for m in doc["marks"]]
