"""physcam defocus (issue 34): closed forms and properties of the layered scatter, and bad input.

Oracles: radiance invariance (a uniform wall renders its radiance times the relative
transmission, at any depth), energy conservation of a point (its blurred image sums to the
kernel's transmission), the thin-lens blur diameter D_ep f_pin |1/d - 1/s| (Gaussian optics of
the entrance pupil), and occlusion (an opaque foreground wider than its blur hides what is behind).
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from physcam.analysis.defocus.render import defocus, inverse_depth, near_edges
from physcam.analysis.defocus.kernels import KernelCache, defocus_camera
from physcam.errors import InputError
from physcam.lens.library import load_lens

W, H = 128, 72


@pytest.fixture(scope="module")
def cache():
    cam = defocus_camera(load_lens("dgauss_50mm"), focus_mm=2000.0, fstop=2.8, sensor_width_mm=36.0, width=W,
                         height=H, tile=32)
    return KernelCache(cam)


def test_uniform_wall_keeps_its_radiance(cache):
    """A uniform wall 0.6 m from the pupil (blur ~4 px) renders its radiance times cos^4 of the
    field angle of its tile's centre (the kernels are constant over a 32 px tile; no vignetting so
    near the axis at f/2.8): the blur moves light, it does not make or lose it."""
    cam = cache.camera
    img = np.ones((H, W, 3), np.float32)
    u = inverse_depth(np.full((H, W), 0.6), cam)
    out = defocus(img, u, cache)
    sx, sy = cam.film_point(80.0, 48.0)  # the centre of the tile holding pixel (64, 36)
    cos4 = math.cos(math.atan(math.hypot(sx, sy) / cam.pinhole_mm)) ** 4
    assert out[H // 2, W // 2, 1] == pytest.approx(cos4, rel=0.01)
    assert np.isfinite(out).all() and out.min() > 0.3


def test_point_blur_diameter_is_the_thin_lens_one(cache):
    """A single bright pixel at 0.25 m: its image holds the kernel's transmission (about 1 near the
    axis) and its second-moment diameter sqrt(8 E[r^2]) is the pupil's blur D f_pin |1/d - 1/s|
    (a uniform disk; the real lens's aberrations within 6 %)."""
    cam = cache.camera
    img = np.zeros((H, W, 1), np.float32)
    img[H // 2, W // 2] = 1.0
    d = 250.0
    u = inverse_depth(np.full((H, W), d / 1000), cam)
    out = defocus(img, u, cache)[..., 0]
    assert out.sum() == pytest.approx(1.0, abs=0.03)
    ys, xs = np.indices(out.shape)
    t = out.sum()
    cx, cy = (out * xs).sum() / t, (out * ys).sum() / t
    d2 = math.sqrt(8 * (out * ((xs - cx) ** 2 + (ys - cy) ** 2)).sum() / t)
    want = float(cam.blur_px(d))
    assert want > 8
    assert d2 == pytest.approx(want, rel=0.06)


def test_opaque_foreground_hides_the_background(cache):
    """A dark square 0.5 m away, 40 px wide, in front of a bright wall at 3 m: at its centre (more
    than a blur radius from its edges) only the square is seen; outside, its blurred edge darkens
    the wall partly (scatter with occlusion, not a gather that lets the wall through)."""
    cam = cache.camera
    img = np.full((H, W, 1), 10.0, np.float32)
    z = np.full((H, W), 3.0)
    sl = (slice(H // 2 - 20, H // 2 + 20), slice(W // 2 - 20, W // 2 + 20))
    img[sl] = 0.0
    z[sl] = 0.5
    out = defocus(img, inverse_depth(z, cam), cache, edge_px=0)[..., 0]  # an exact depth edge: no widening
    r = cam.blur_px(500.0) / 2
    assert r < 15
    # at most 1 % of the wall leaks through: where two tiles' kernels meet, their distortion
    # offsets differ by a fraction of a pixel and the square's blurred coverage is 0.997, not 1
    assert out[H // 2, W // 2] == pytest.approx(0.0, abs=0.1)
    edge = out[H // 2, W // 2 + 20 + 1]  # just outside the square: partly covered by its blur
    assert 1.0 < edge < 9.0


@pytest.mark.parametrize("bad, words", [
    (np.nan, "NaN"), (-1.0, "negative"), (0.0, "zero"),
])
def test_bad_depths_are_one_sentence(cache, bad, words):
    z = np.full((H, W), 2.0)
    z[3, 4] = bad
    with pytest.raises(InputError, match=words):
        inverse_depth(z, cache.camera)


def test_wrong_size_depth_is_refused(cache):
    with pytest.raises(InputError, match="same size"):
        defocus(np.zeros((H, W, 3)), np.zeros((H, W - 1)), cache)


def _exr(path, planes, size=(W, H)):
    import OpenEXR

    w, h = size
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, {k: np.ascontiguousarray(v, np.float32) for k, v in planes.items()}) as f:
        f.write(str(path))


@pytest.mark.parametrize("case", ["no depth", "nan", "negative", "wrong size"])
def test_cli_bad_input_exits_2_with_one_line(tmp_path, case):
    rgb = {c: np.ones((H, W)) for c in "RGB"}
    z = np.full((H, W), 2.0)
    args = []
    if case == "no depth":
        _exr(tmp_path / "in.exr", rgb)
    elif case == "wrong size":
        _exr(tmp_path / "in.exr", rgb)
        _exr(tmp_path / "z.exr", {"Z": np.full((H - 2, W), 2.0)}, (W, H - 2))
        args = ["--depth", str(tmp_path / "z.exr")]
    else:
        z[5, 5] = np.nan if case == "nan" else -2.0
        _exr(tmp_path / "in.exr", {**rgb, "Z": z})
    p = subprocess.run([sys.executable, "-m", "physcam", "defocus", str(tmp_path / "in.exr"), *args, "--lens",
                        "dgauss_50mm", "--focus", "2m", "--fstop", "2.8", "--sensor-width", "36", "--sensor-height",
                        "20.25", "-o", str(tmp_path / "out.exr")], capture_output=True, text=True, timeout=120)
    assert p.returncode == 2, p.stderr
    lines = [ln for ln in p.stderr.strip().splitlines() if not ln.startswith("note")]
    assert len(lines) == 1 and "Traceback" not in p.stderr
    assert not (tmp_path / "out.exr").exists()


def test_cli_defocus_json_document(tmp_path):
    """A render with a Z channel defocuses through the CLI; the --json document meets its schema and
    the EXR keeps the header's windows and the colour channels."""
    import json

    import jsonschema

    from physcam.analysis.defocus.exr import read_exr
    from physcam.cli._output import schema_file

    _exr(tmp_path / "in.exr", {**{c: np.ones((H, W)) for c in "RGB"}, "Z": np.full((H, W), 1.0)})
    p = subprocess.run([sys.executable, "-m", "physcam", "defocus", str(tmp_path / "in.exr"), "--lens", "dgauss_50mm",
                        "--focus", "2m", "--fstop", "2.8", "--sensor-width", "36", "--sensor-height", "20.25",
                        "--tile", "32", "-o", str(tmp_path / "out.exr"), "--json"], capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    jsonschema.validate(doc, json.loads(schema_file(doc["schema"]).read_text()))
    assert doc["depth_channel"] == "Z" and doc["depth_kind"] == "planar"
    out = read_exr(tmp_path / "out.exr")
    assert set(out.channels) == {"R", "G", "B"} and out.display_size == (W, H)


def test_infinity_kernel_stays_inside_the_thin_lens_blur(cache):
    """The farthest depth node stands for infinity: its kernel's light lies within the pupil's
    blur circle there, diameter D_ep f_pin / s (s the focus distance from the pupil), plus 2 px for
    aberrations and the pixel grid. (It was traced from 1e9 mm, where the rays lost precision and
    half the light fell in a halo 80 px wide.)"""
    cam = cache.camera
    k = cache.get(cache.node_centre(0, 0, (H, W), (0, 0)), cam.node_far())
    blur = cam.pupil_diameter_mm * cam.pinhole_mm / (cam.focus_mm - cam.pupil_from_film_mm) / cam.pitch_mm
    img = k.image[..., 0]
    ys, xs = np.indices(img.shape)
    r = np.hypot(xs - k.radius, ys - k.radius)
    assert img[r <= blur / 2 + 2].sum() >= 0.99 * img.sum()


def test_small_foreground_over_black_keeps_its_light(cache):
    """A bright 3 x 3 px patch at 0.3 m (blur ~10 px) in front of a black background at infinity:
    the blurred patch holds the light it had (times the kernel's transmission, about 1 here), as
    nothing lies behind it to show through. (The background's hole behind the patch was
    renormalised away, C / A with A ~ 9 / blur area, and the patch came out ~16 % too bright.)"""
    cam = cache.camera
    img = np.zeros((H, W, 1), np.float32)
    img[35:38, 63:66] = 10.0
    z = np.full((H, W), 1e10)
    z[35:38, 63:66] = 0.3
    out = defocus(img, inverse_depth(z, cam), cache, edge_px=0)[..., 0]
    assert out.sum() == pytest.approx(90.0, rel=0.03)


def test_near_edges_is_a_max_filter_of_inverse_depth():
    """Hand-worked: one near pixel (u = 2) in a far field (u = 0.5) spreads to its 8 neighbours at
    edge_px = 1 and to a 5 x 5 block at 2; 0 leaves the depth alone."""
    u = np.full((7, 7), 0.5)
    u[3, 3] = 2.0
    one = near_edges(u, 1)
    assert (one[2:5, 2:5] == 2.0).all() and (one == 2.0).sum() == 9
    assert (near_edges(u, 2) == 2.0).sum() == 25
    assert near_edges(u, 0) is u


def test_depth_nodes_step_grows_with_the_blur(cache):
    """Hand-worked node spacing: with b_n = step (e^(rel n) - 1) / rel the blur difference between
    nodes n and n + 1 is (step + rel b_n) (e^rel - 1) / rel, i.e. the step grows by ``rel`` of the
    blur; the thin-lens blur D_ep f_pin |u - u_focus| / p is computed here from the pupil."""
    cam = cache.camera
    k = cam.pupil_diameter_mm * cam.pinhole_mm / cam.pitch_mm
    s, rel = cam.step_px, cam.step_rel
    assert rel == 0.05 and s == 1.0
    n = np.arange(0, 40)
    b = k * (cam.node_u(n) - cam.focus_u)
    np.testing.assert_allclose(np.diff(b), (s + rel * b[:-1]) * math.expm1(rel) / rel, rtol=1e-9)
    np.testing.assert_allclose(cam.node_index(cam.node_u(n)), n, atol=1e-9)
    assert cam.node_u(cam.node_far()) == 0.0 and cam.node_u(cam.node_far() + 1) > 0.0
