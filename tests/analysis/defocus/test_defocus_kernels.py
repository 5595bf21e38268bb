"""The kernels of physcam defocus (issues 42 item 5, 47): interpolated in depth and field, cached on
disk as stacks written whole and checked when read.

Oracles: kernels traced directly at a position and depth (DefocusCamera.kernels: their own fan,
not interpolated) against the interpolated ones (second moments, the part of a kernel a picture
shows); Gaussian optics (a ray's landing offset is linear in inverse depth: interpolating across
32 depth nodes moves it by under 0.02 px); and a damaged cache (NaN, truncated, another camera's)
against a fresh trace (the same pixels, never NaN)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from physcam.analysis.defocus import trace as dt
from physcam.analysis.defocus.render import defocus, inverse_depth
from physcam.analysis.defocus.cache import STACK_GLOB
from physcam.analysis.defocus.kernels import KernelCache, defocus_camera
from physcam.errors import PhysCamWarning
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state
from physcam.data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM

SENSOR_MM = (36.0, DEFAULT_SENSOR_HEIGHT_MM)  # 36 mm wide imaged on the width; the height is not used

W, H = 160, 90


@pytest.fixture(scope="module")
def cam():
    return defocus_camera(camera_state(load_lens("dgauss_50mm"), focus_mm=2000.0, fstop=2.8, sensor_mm=SENSOR_MM),
                          width=W, height=H, tile=32)


def _moments(k):
    """Second-moment widths (px) of a kernel's middle channel about its centroid: (sx, sy)."""
    m = k[..., k.shape[2] // 2].astype(float)
    ys, xs = np.indices(m.shape)
    t = m.sum()
    cx, cy = (m * xs).sum() / t, (m * ys).sum() / t
    return math.sqrt((m * (xs - cx) ** 2).sum() / t), math.sqrt((m * (ys - cy) ** 2).sum() / t)


def test_ray_offsets_are_linear_in_inverse_depth(cam):
    """Gaussian optics: a ray's landing offset from the pinhole image is its pupil point times
    f_pin (u - u_focus) / p, linear in u. Interpolated between two ladder nodes (8 and 16, the middle
    at 12), the rays that pass at all three land within 0.02 px of where they are traced, at the axis
    and in the corner of a frame whose corner is 29 deg off the axis; and the interpolated light
    (the passing rays' solid angle, not linear in u: kernels are normalised, and T has its own
    table) is the traced one within 2 %."""
    assert cam.ladder(12) == (8, 16)
    for field in [(W / 2, H / 2), (W - 1.0, 1.0)]:
        us = [float(cam.node_u(n)) for n in (8, 12, 16)]
        box = dt.pupil_boxes(cam, [field], us)[0]
        a, m, b = dt.trace_fans(cam, [(field, u, box, 1 << 13) for u in us])
        mid = dt.interpolate_fan(a, b, m.u)
        ok = (a.w > 0) & (m.w > 0) & (b.w > 0)
        assert ok.sum() > 2000
        assert np.hypot(mid.ox[ok] - m.ox[ok], mid.oy[ok] - m.oy[ok]).max() < 0.02
        assert mid.w.sum() == pytest.approx(m.w.sum(), rel=0.02)


def test_kernels_between_ladder_nodes_are_the_traced_ones(cam):
    """A node kernel interpolated between ladder nodes has the second moments of the kernel traced
    directly at that depth and field node, within 2 % (and both have the thin-lens size)."""
    cache = KernelCache(cam)
    cols, rows = cache.grid
    n = 12  # between ladder nodes 8 and 16
    assert cam.ladder(n) == (8, 16)
    for c, r in [(len(cols) // 2, len(rows) // 2), (len(cols) - 1, 0)]:
        got = cache.node_kernel(c, r, n)
        want = cam.kernels([(float(cols[c]), float(rows[r]), 1.0 / float(cam.node_u(n)))])[0].image
        for g, w in zip(_moments(got), _moments(want)):
            assert g == pytest.approx(w, rel=0.02)


def test_kernels_between_field_nodes_are_close_to_the_traced_ones(cam):
    """Between field nodes a kernel is the blend of its four nodes': at the middle of a cell near the
    corner (where the cat's eye changes fastest) its second moments are those of a kernel traced
    there within 5 % (the bisection's tolerance: 3 % along the diagonal)."""
    cache = KernelCache(cam)
    cols, rows = cache.grid
    x, y = 0.5 * (cols[-1] + cols[-2]), 0.5 * (rows[0] + rows[1])
    n = 20
    got = cache.tile_kernel(x, y, n)
    want = cam.kernels([(x, y, 1.0 / float(cam.node_u(n)))])[0].image
    for g, w in zip(_moments(got), _moments(want)):
        assert g == pytest.approx(w, rel=0.05)


def _scene(cam):
    rng = np.random.default_rng(5)
    img = rng.uniform(0, 1, (H, W, 3)).astype(np.float32)
    z = np.full((H, W), 3.0)
    z[20:60, 30:90] = 0.6
    z[:, 130:] = 1e10
    return img, inverse_depth(z, cam)


def test_the_disk_cache_is_read_back_and_written_as_one_stack(cam, tmp_path):
    """A frame traces its kernels and writes them as one stack file (one sync, issue 47); a second
    cache on the same folder (another frame, another worker) reads them, traces none, and gives the
    same picture."""
    img, u = _scene(cam)
    first = KernelCache(cam, tmp_path)
    a = defocus(img, u, first)
    assert first.traced > 0 and first.loaded == 0
    assert len(list(first.folder.glob(STACK_GLOB))) == 1
    second = KernelCache(cam, tmp_path)
    b = defocus(img, u, second)
    assert second.traced == 0 and second.loaded == first.traced
    np.testing.assert_allclose(b, a, rtol=1e-6, atol=1e-7)
    assert len(list(first.folder.glob(STACK_GLOB))) == 1  # nothing new to write


@pytest.fixture(scope="module")
def traced_stacks(cam, tmp_path_factory):
    """The scene's picture from a cache without a folder, and a folder holding two stacks: one
    node's, then the rest of the frame's (its name returned); each damage test gets a copy."""
    img, u = _scene(cam)
    fresh = defocus(img, u, KernelCache(cam))
    folder = tmp_path_factory.mktemp("stacks")
    KernelCache(cam, folder).prepare([(0, 0, 0)])
    before = set((folder / cam.key()).glob(STACK_GLOB))
    defocus(img, u, KernelCache(cam, folder))
    (path,) = set((folder / cam.key()).glob(STACK_GLOB)) - before  # the frame's own stack
    return fresh, folder, path.name


@pytest.mark.parametrize("damage", ["nan", "truncated", "garbage", "other camera"])
def test_a_damaged_cache_is_traced_again_never_nan(cam, tmp_path, damage, traced_stacks):
    """Issue 42 item 5: a NaN kernel gave NaN pixels in a file reported as written; a truncated one
    a traceback on every later run. A damaged stack file is set aside with one warning naming it,
    its kernels are traced again, and the picture is the fresh one. (The stacks are traced once for
    the four damages, round 14: traced_stacks.)"""
    import shutil

    img, u = _scene(cam)
    fresh, stacks, name = traced_stacks
    shutil.copytree(stacks / cam.key(), tmp_path / cam.key())
    path = tmp_path / cam.key() / name
    data = path.read_bytes()
    if damage == "nan":
        with np.load(path) as z:
            arrays = {k: z[k] for k in z.files}
        name = max(("data", "direct_data"), key=lambda k: len(arrays[k]))  # node or tile-corner kernels
        arrays[name][len(arrays[name]) // 2] = np.nan
        with open(path, "wb") as fh:
            np.savez(fh, **arrays)
    elif damage == "truncated":
        path.write_bytes(data[: len(data) // 2])
    elif damage == "garbage":
        path.write_bytes(b"not a stack" * 100)
    else:
        with np.load(path) as z:
            arrays = {k: z[k] for k in z.files}
        arrays["key"] = np.array("0123456789abcdef")
        with open(path, "wb") as fh:
            np.savez(fh, **arrays)
    cache = KernelCache(cam, tmp_path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = defocus(img, u, cache)
    said = [str(w.message) for w in caught if issubclass(w.category, PhysCamWarning)]
    assert len(said) == 1 and path.name in said[0] and "traced again" in said[0]
    assert np.isfinite(out).all() and cache.traced > 0
    np.testing.assert_allclose(out, fresh, rtol=1e-5, atol=1e-6)


def test_transmission_is_one_on_the_axis_and_falls_off(cam):
    """T is 1 on the axis at every depth (its definition) and falls toward the corners."""
    cache = KernelCache(cam)
    for n in (cam.node_far(), 0, 16):
        t = cache.transmission(np.array([W / 2, W - 1.0]), np.array([H / 2, 1.0]), n)[:, 0]
        assert t[0] == pytest.approx(1.0, abs=1e-6) and 0.2 < t[1] < 0.95


def test_infinity_kernel_stays_inside_the_thin_lens_blur(cam):
    """The farthest depth node stands for infinity: its kernel's light lies within the pupil's blur
    circle there, D_ep f_pin / s (s the focus distance from the pupil), plus 2 px for aberrations
    and the pixel grid. (Traced from 1e9 mm the rays lost precision and half the light fell in a halo.)"""
    cache = KernelCache(cam)
    k = cache.node_kernel(len(cache.grid[0]) // 2, len(cache.grid[1]) // 2, cam.node_far())[..., 0]
    blur = cam.pupil_diameter_mm * cam.pinhole_mm / (cam.focus_mm - cam.pupil_from_film_mm) / cam.pitch_mm
    r = k.shape[0] // 2
    ys, xs = np.indices(k.shape)
    assert k[np.hypot(xs - r, ys - r) <= blur / 2 + 2].sum() >= 0.99 * k.sum()


class _TracedAtCorners(KernelCache):
    """The oracle of issue 47's interpolation bound (as ``benchmarks/defocus.py
    --interpolation-check``): every tile corner's kernel traced at its own place and its depth
    node's own depth (DefocusCamera.kernels), no field or depth-ladder blend.

    With ``spot`` (x, y) (round 14), the picture is black farther than 96 px from it: a corner
    there takes a 1-pixel kernel instead of a traced one (two tiles away, its tiles hold no light:
    the picture is the same to the bit, checked on both blurs of the test, 5 s -> 0.8 s). It never
    traces field-node or direct kernels, which its own tile kernels replace (the library's
    :meth:`prepare` traced them for nothing); a read of one would raise KeyError, not pass."""

    FAR_PX = 96.0

    def __init__(self, camera, spot=None):
        super().__init__(camera)
        self.spot = spot

    def _trace(self, missing, progress):
        return {}

    def trace_direct(self, points):
        return {}

    def tile_kernel(self, x, y, n):
        key = (round(float(x), 3), round(float(y), 3), int(n))
        if self.spot is not None and math.hypot(x - self.spot[0], y - self.spot[1]) > self.FAR_PX:
            return np.ones((1, 1, 1), np.float32)
        if key not in self._tiles:
            v = float(self.camera.node_u(n))
            k = self.camera.kernels([(x, y, 1.0 / max(v, 1e-7))])[0].image
            self._tiles[key] = (k / k.sum(axis=(0, 1), keepdims=True)).astype(np.float32)
        return self._tiles[key]


@pytest.mark.parametrize("blur_px", [-3.0, 1.0])
def test_bright_spot_near_focus_matches_kernels_traced_at_its_corners(blur_px):
    """Issue 47: where kernels are interpolated the picture differs from one made with kernels traced
    where they are used by under 0.5 % of its peak. A bright spot (one pixel of 100 on black, at the
    depth of a blur of ``blur_px``: negative nearer than focus) off the axis between field nodes, where a
    small aberrated kernel turns with the azimuth: before the fix its blend of four field nodes'
    kernels missed the traced one by 10-30 % of the peak (measured: 16.5 % at 2K in the benchmark)."""
    w, h = 512, 270
    cam = defocus_camera(camera_state(load_lens("dgauss_50mm"), focus_mm=2000.0, fstop=2.8, sensor_mm=SENSOR_MM),
                         width=w, height=h, tile=32)
    img = np.zeros((h, w, 1), np.float32)
    x, y = int(0.62 * w), int(0.3 * h)
    img[y, x] = 100.0
    u = np.full((h, w), cam.focus_u + blur_px / cam.blur_per_u)
    out = defocus(img, u, KernelCache(cam))
    ref = defocus(img, u, _TracedAtCorners(cam, spot=(x, y)))
    assert ref.max() > 2.0  # a concentrated spot: the case the blend got wrong
    ys, xs = np.indices((h, w))  # the light stays near the spot, away from the corners not traced
    assert not ref[np.hypot(xs - x, ys - y) > _TracedAtCorners.FAR_PX - 32 * math.sqrt(2)].any()
    assert np.abs(out - ref).max() <= 0.005 * ref.max()


def test_a_bladed_iris_blurs_as_the_round_iris_of_its_f_number():
    """One f-number convention with blades (docs/conventions.md, issue 41 item 5): a 6-blade iris at f/2.8
    has the round f/2.8 iris's area, so its corners lie sqrt(pi / (3 sin 60 deg)) = 1.0996 round radii out
    (closed form of a regular hexagon's area), as in physcam's Blender camera. A uniform hexagon of the
    disk's area has a polar second moment 20 sqrt(3) pi^2 / 216 / (pi / 2) = 1.0077 times the disk's, so
    an on-axis point's blur has an RMS radius within 2 % of the round iris's (the hexagon inscribed in the
    round pupil, the old convention, gave 0.913 of it)."""
    from physcam.trace.aperture import Aperture

    lens = load_lens("dgauss_50mm")
    kw = dict(width=320, height=180, tile=32)
    state = camera_state(lens, focus_mm=2000.0, fstop=2.8, sensor_mm=SENSOR_MM)
    rnd = defocus_camera(state, **kw)
    hexa = defocus_camera(state, aperture=Aperture(6), **kw)
    assert hexa.stop_semi / rnd.stop_semi == pytest.approx(math.sqrt(math.pi / (3 * math.sin(math.pi / 3))), rel=1e-6)
    point = [(160.0, 90.0, 500.0)]  # on the axis, 0.5 m from the pupil: a blur about 12 px across
    radii = []
    for c in (rnd, hexa):
        sx, sy = _moments(c.kernels(point)[0].image)
        radii.append(math.hypot(sx, sy))
    assert radii[1] / radii[0] == pytest.approx(1.0077 ** 0.5, abs=0.02)


@pytest.mark.parametrize("dispersion", [False, True])
def test_direct_kernels_binned_together_are_the_node_kernels_binned_one_by_one(dispersion):
    """field.direct_kernels bins a frame's many small fans in one bincount (trace.bin_fans): the same
    sums in the same order as node_kernel fan by fan, so the same kernels to the bit (both here, in
    one process, no BLAS); with fans of two sample counts, three wavelengths, a fan without light."""
    from physcam.analysis.defocus.field import box_depths, direct_kernels, node_kernel

    c = defocus_camera(camera_state(load_lens("dgauss_50mm"), focus_mm=2000.0, fstop=2.8, sensor_mm=SENSOR_MM),
                       width=W, height=H, tile=32, dispersion=dispersion)
    pts = [(3.0, 5.0), (80.0, 45.0), (150.0, 12.5)]
    boxes = dt.pupil_boxes(c, pts, box_depths(c))
    unwarps = np.linalg.inv(dt.distortion_jacobians(c, pts))
    jobs = [(p, u, b, k) for (p, b) in zip(pts, boxes) for u, k in ((1 / 900.0, 4096), (1 / 6000.0, 8192))]
    fans = dt.trace_fans(c, jobs)
    f = fans[0]
    fans.append(dt.Fan(f.field_px, f.u, np.zeros_like(f.ox), np.zeros_like(f.oy), np.zeros_like(f.w), f.ch, f.ex, f.ey))
    uw = [unwarps[i // 2] for i in range(len(jobs))] + [unwarps[0]]
    got = direct_kernels(c, fans, uw)
    want = [node_kernel(c, fan, fan, 0, None, u)[0] for fan, u in zip(fans, uw)]
    assert all(a.shape == b.shape and np.array_equal(a, b) for a, b in zip(got, want))
    assert got[-1].shape == (1, 1, len(c.wavelengths_nm)) and max(k.shape[0] for k in got) >= 3  # a unit kernel; blurs


@pytest.mark.parametrize("field", [(W / 2, H / 2), (W - 1.0, 1.0)])
def test_fans_in_single_precision_land_where_double_precision_rays_from_the_object_land(cam, field):
    """The fans are traced in float32 from a plane before the front element (trace.py, ``_trace_batch``).
    The oracle: the same rays in float64 from their object points, at 0.6 m, the focus and infinity (FAR_MM,
    10 km, where float32's step is 1 mm: rays started there landed 4.5 um off). The rays that pass in both
    land within 0.5 um of each other (measured: 0.3 um at infinity, 0.003 um nearer; 0.03 px on a 2K frame
    of this film), at most one in a thousand passes in one only (a ray on a rim; none here), and their
    weights (cos^3 of the ray's angle, float64 in both) are the same."""
    us = [1.0 / 600.0, cam.focus_u, 0.0]
    box = dt.pupil_boxes(cam, [field], us)[0]
    fans = dt.trace_fans(cam, [(field, u, box, 1 << 12) for u in us])
    wls = np.asarray(cam.wavelengths_nm, dtype=float)
    sx0, sy0 = cam.film_point(*field)
    z_ep = cam.film_z - cam.pupil_from_film_mm
    bw, bh = box[1] - box[0], box[3] - box[2]
    for fan, u in zip(fans, us):
        px, py, pz, _ = dt._object_point(cam, field, u)
        n = fan.ox.shape[0]
        rays, cos = dt._rays(np.full(n, px), np.full(n, py), np.full(n, pz), fan.ex, fan.ey, z_ep, wls[fan.ch])
        assert rays.dtype == np.float64
        w = cos ** 3 * (bw * bh / n)  # before the trace, which turns the directions in place
        x, y, ok, _ = dt._trace(cam, rays)
        ox, oy = (x + sx0) / -cam.pitch_mm, (y + sy0) / cam.pitch_mm
        both = ok & (fan.w > 0)
        assert ok.sum() > 1000
        assert (ok != (fan.w > 0)).sum() <= n // 1000
        assert np.hypot(fan.ox[both] - ox[both], fan.oy[both] - oy[both]).max() * cam.pitch_mm < 5e-4
        np.testing.assert_allclose(fan.w[both], w[both], rtol=1e-12)


def test_field_positions_without_light_are_said_not_left_black_in_silence():
    """At f/1000 on dgauss_50mm the kernels' pupil search found no light toward the frame's corners (its
    entrance pupil is 0.05 mm there), and `physcam defocus` wrote black corners with only numpy's RuntimeWarning
    (a review found it: at f/22 to f/300 the corner keeps about cos^4 of the centre's light). Such positions are
    now said in a PhysCamWarning; at f/22 nothing is said and no position is dark."""
    import warnings

    from physcam.analysis.defocus.field import field_table
    from physcam.analysis.defocus.kernels import defocus_camera
    from physcam.errors import PhysCamWarning
    from physcam.lens.library import load_lens
    from physcam.optics.state import camera_state

    for fstop, dark in ((1000.0, True), (22.0, False)):
        cam = defocus_camera(camera_state(load_lens("dgauss_50mm"), focus_mm=600.0, fstop=fstop, sensor="S35"),
                             width=96, height=64)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            table = field_table(cam, None, {cam.node_far()})
        said = [w for w in caught if issubclass(w.category, PhysCamWarning) and "no light reached" in str(w.message)]
        assert not [w for w in caught if issubclass(w.category, RuntimeWarning)]
        assert bool(said) == dark, [str(w.message) for w in caught]
        t = table.transmission[cam.node_far()]
        assert (t.max(axis=1) <= 0).any() == dark and t[0].max() == pytest.approx(1.0)
