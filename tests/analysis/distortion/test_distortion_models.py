"""Fitted distortion models (physcam.analysis.distortion.models) against hand-worked numbers,
OpenCV (a test-only oracle for the Brown-Conrady U-D formula) and forward-traced chief rays."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.analysis.distortion.models import (
    TDE4_PARAMETERS, BrownConrady, DistortionSamples, TDE4RadialStandard, fit_brown_conrady, fit_models,
    fit_tde4_radial, fit_usd_standard, samples_from_field,
)
from physcam.analysis.distortion.stmap import distortion_field
from physcam.errors import ExportError, PhysCamError
from physcam.lens.library import load_lens
from physcam.optics.state import as_designed, camera_state

from _forward_chief import ideal_grid_and_real

W_PX, H_PX = 2048, 1366
SENSOR = (36.0, 24.0)
FOCUS = 2000.0


def _brown(coeffs, direction="U-D", f=50.0):
    c = dict(k1=0.0, k2=0.0, k3=0.0, p1=0.0, p2=0.0, fx_mm=f, fy_mm=f) | coeffs
    return BrownConrady("Brown-Conrady " + direction, direction, c, 0.0, 0.0, 1.0, (W_PX, H_PX), SENSOR, FOCUS)


def _tde4(coeffs, sensor=SENSOR):
    c = {n: 0.0 for n in TDE4_PARAMETERS} | dict(focal_length_mm=50.0, pixel_aspect=1.0) | coeffs
    return TDE4RadialStandard("3DE4 Radial - Standard, Degree 4", "D-U", c, 0.0, 0.0, 1.0, (W_PX, H_PX), sensor,
                              FOCUS)


def test_brown_conrady_formula_worked_by_hand():
    # k1 0.1, k2 0.01, p1 0.001, p2 0.002 at normalised (0.3, 0.2): r^2 = 0.13,
    # radial 1 + 0.013 + 0.000169 = 1.013169
    # x' = 0.3 * 1.013169 + 2 * 0.001 * 0.06 + 0.002 * (0.13 + 0.18) = 0.3046907
    # y' = 0.2 * 1.013169 + 0.001 * (0.13 + 0.08) + 2 * 0.002 * 0.06 = 0.2030838
    m = _brown(dict(k1=0.1, k2=0.01, p1=0.001, p2=0.002))
    out = m.formula(np.array([[0.3 * 50.0, 0.2 * 50.0]])) / 50.0
    assert out[0] == pytest.approx([0.3046907, 0.2030838], abs=1e-12)
    # U-D: the formula distorts; undistort inverts it
    assert m.undistort_mm(m.formula(np.array([[15.0, 10.0]])))[0] == pytest.approx([15.0, 10.0], abs=1e-10)


def test_brown_conrady_u_d_is_opencvs_projection():
    cv2 = pytest.importorskip("cv2")
    rng = np.random.default_rng(3)
    k1, k2, p1, p2, k3 = -0.21, 0.07, 0.0013, -0.0021, 0.011
    f, cx, cy = 1000.0, 1024.0, 683.0
    pts = rng.uniform(-0.6, 0.6, size=(50, 2))
    obj = np.column_stack([pts, np.ones(50)])
    img, _ = cv2.projectPoints(obj, np.zeros(3), np.zeros(3), np.array([[f, 0, cx], [0, f, cy], [0, 0, 1.0]]),
                               np.array([k1, k2, p1, p2, k3]))
    m = _brown(dict(k1=k1, k2=k2, k3=k3, p1=p1, p2=p2), f=f)
    mine = m.formula(pts * f) + [cx, cy]
    assert np.abs(mine - img[:, 0, :]).max() < 1e-8


def test_tde4_radial_standard_worked_by_hand():
    # c2 0.1, u1 0.01, v1 -0.02, c4 0.02 at diagonally normalised (0.5, -0.3): r^2 = 0.34, r^4 = 0.1156
    # radial 1 + 0.034 + 0.002312 = 1.036312
    # x' = 0.5 * 1.036312 + (0.34 + 0.5) * 0.01 + 2 * 0.5 * -0.3 * -0.02 = 0.532556
    # y' = -0.3 * 1.036312 + (0.34 + 0.18) * -0.02 + 2 * 0.5 * -0.3 * 0.01 = -0.3242936
    # cylindric phi 30 deg, b 0.1: q = sqrt(1.1), c = cos 30, s = 0.5
    q, c, s = math.sqrt(1.1), math.cos(math.radians(30.0)), 0.5
    mxx, mxy, myy = c * c * q + s * s / q, (q - 1 / q) * c * s, c * c / q + s * s * q
    assert (mxx, mxy, myy) == pytest.approx((1.0249722, 0.0412861, 0.9772991), abs=1e-7)
    x1, y1 = 0.532556, -0.3242936
    expect = [mxx * x1 + mxy * y1, mxy * x1 + myy * y1]
    m = _tde4({"Distortion - Degree 2": 0.1, "U - Degree 2": 0.01, "V - Degree 2": -0.02,
               "Quartic Distortion - Degree 4": 0.02, "Phi - Cylindric Direction": 30.0,
               "B - Cylindric Bending": 0.1})
    r_fb = 0.5 * math.hypot(*SENSOR)
    out = m.formula(np.array([[0.5 * r_fb, -0.3 * r_fb]]))[0] / r_fb
    assert out == pytest.approx(expect, abs=1e-12)


def test_tde4_undistorted_bounding_box_worked_by_hand():
    """The box of the undistorted frame, 36 x 24 mm, "Distortion - Degree 2" -0.05 (undistort shrinks).

    r_fb^2 = 18^2 + 12^2 = 468 mm^2. Along the right edge, x_u = x (1 + c2 (x^2 + y^2) / r_fb^2) is largest
    at y = 0: 18 (1 - 0.05 * 324 / 468) = 17.376923 mm; along the top edge, at x = 0:
    12 (1 - 0.05 * 144 / 468) = 11.815385 mm. In 3DE's unit coordinates (0 to 1 over the filmback):
    x from 0.5 - 17.376923 / 36 = 0.017308 to 0.982692, y from 0.5 - 11.815385 / 24 = 0.007692 to 0.992308.
    """
    m = _tde4({"Distortion - Degree 2": -0.05})
    t = np.linspace(-1.0, 1.0, 2001)
    edge = np.concatenate([np.column_stack([np.full_like(t, 18.0), 12.0 * t]),
                           np.column_stack([18.0 * t, np.full_like(t, 12.0)]),
                           np.column_stack([np.full_like(t, -18.0), 12.0 * t]),
                           np.column_stack([18.0 * t, np.full_like(t, -12.0)])])
    u = m.undistort_mm(edge)
    box_unit = [u[:, 0].min() / 36 + 0.5, u[:, 0].max() / 36 + 0.5, u[:, 1].min() / 24 + 0.5, u[:, 1].max() / 24 + 0.5]
    assert box_unit == pytest.approx([0.017308, 0.982692, 0.007692, 0.992308], abs=1e-6)


@settings(max_examples=25, deadline=None)
@given(k1=st.floats(-0.2, 0.2), k2=st.floats(-0.05, 0.05), k3=st.floats(-0.01, 0.01),
       p1=st.floats(-1e-3, 1e-3), p2=st.floats(-1e-3, 1e-3), direction=st.sampled_from(["D-U", "U-D"]))
def test_fitting_recovers_a_known_brown_conrady_model(k1, k2, k3, p1, p2, direction):
    truth = _brown(dict(k1=k1, k2=k2, k3=k3, p1=p1, p2=p2), direction=direction, f=35.0)
    X, Y = np.meshgrid(np.linspace(-18, 18, 15), np.linspace(-12, 12, 11))
    src = np.column_stack([X.ravel(), Y.ravel()])
    dst = truth.formula(src)
    d, u = (src, dst) if direction == "D-U" else (dst, src)
    s = DistortionSamples("synthetic", FOCUS, d, u, SENSOR, (W_PX, H_PX), (35.0, 35.0))
    fit = fit_brown_conrady(s, direction)
    got = [fit.coefficients[n] for n in ("k1", "k2", "k3", "p1", "p2")]
    assert got == pytest.approx([k1, k2, k3, p1, p2], abs=1e-9)
    assert fit.max_residual_px < 1e-6 and fit.acceptable


@pytest.fixture(scope="module")
def distagon():
    lens = load_lens("zeiss_distagon_35mm_f4")
    res = distortion_field(camera_state(lens, focus_mm=FOCUS, sensor_mm=SENSOR), width_px=W_PX, height_px=H_PX,
                           maps=False)
    return lens, res, fit_models(samples_from_field(res), ("brown", "3de4", "usd"))


def test_fits_land_forward_traced_points_within_their_stated_residual(distagon):
    """Ideal pinhole pixels, distorted by each model, against the real rays traced forward (the oracle)."""
    lens, res, fits = distagon
    ideal, real = ideal_grid_and_real(lens, FOCUS, SENSOR, (W_PX, H_PX))
    scale = np.array([W_PX / SENSOR[0], H_PX / SENSOR[1]])
    centre = np.array([W_PX / 2, H_PX / 2])
    for fit in fits:
        predicted = fit.distort_mm((ideal - centre) / scale) * scale + centre
        err = np.hypot(*(predicted - real).T)
        assert err.max() <= fit.max_residual_px + 0.01, (fit.model, err.max(), fit.max_residual_px)
        if isinstance(fit, BrownConrady):  # degree 6 radial: well inside half a pixel here
            assert fit.acceptable and fit.max_residual_px < 0.1, fit.model
    # and the lens distorts visibly, so the models are doing work
    assert np.hypot(*(real - ideal).T).max() > 5.0


def test_usd_fit_agrees_with_the_radial_fit_of_the_field_angle_table():
    """At infinity the 2-D USD fit and the 1-D radial fit of real_distortion (another code path, from
    infinity to the paraxial focus) describe the same lens: their predictions agree to 0.1 px."""
    from physcam.analysis.distortion.field import real_distortion

    lens = load_lens("dgauss_50mm")
    res = distortion_field(as_designed(lens, sensor_mm=(36, 24)), width_px=W_PX, height_px=H_PX, maps=False)
    usd = fit_usd_standard(samples_from_field(res))
    radial = real_distortion(lens, sensor_width_mm=36.0, sensor_height_mm=24.0).fit
    r = np.linspace(0.5, 21.6, 40)
    a = r * usd.coefficients["k1"] * (r / 18) ** 2 + r * usd.coefficients["k2"] * (r / 18) ** 4
    b = r * radial.distortion_pct(r) / 100.0
    assert np.abs(a - b).max() * W_PX / 36.0 < 0.1


def test_a_wide_lens_is_not_called_a_good_fit_and_is_not_exported(tmp_path):
    from physcam.cli import main
    from physcam.export.tde4 import tde4_lens_text

    lens = load_lens("zuiko_18mm_f3_5")
    res = distortion_field(camera_state(lens, focus_mm=FOCUS, sensor_mm=(36, 24)), width_px=W_PX,
                           height_px=H_PX, maps=False)
    fit = fit_tde4_radial(samples_from_field(res))
    assert not fit.acceptable and fit.max_residual_px > 0.5
    with pytest.raises(ExportError, match="px"):
        tde4_lens_text(fit)
    out = tmp_path / "maps"
    assert main(["distortion", "zuiko_18mm_f3_5", "--focus", "2m", "--resolution", "2048x1366", "--stmap", str(out),
                 "--fit", "3de4"]) == 2
    assert not out.exists()  # nothing written half
    # a larger allowance is the user's explicit choice
    assert main(["distortion", "zuiko_18mm_f3_5", "--focus", "2m", "--resolution", "2048x1366", "--stmap", str(out),
                 "--fit", "3de4", "--max-residual", "5"]) == 0
    assert (out / "3de4_radial_standard_degree_4.txt").exists()


def _read_3de4_lens(text):
    """Read a lens file line by line as 3DE4's own *Import Lens...* script does."""
    lines = iter(text.splitlines())
    name = next(lines).strip()
    w, h, fl, aspect, cx, cy, pa = (float(v) for v in next(lines).split())
    mode = next(lines).strip()
    model = next(lines).strip()
    params = {}
    while True:
        para = next(lines).strip()
        if para == "<end_of_file>":
            break
        params[para] = float(next(lines).strip())
        for _ in range(int(next(lines))):
            next(lines)
    return dict(name=name, w=w, h=h, fl=fl, aspect=aspect, cx=cx, cy=cy, pa=pa, mode=mode, model=model, params=params)


def test_3de4_lens_file_reads_back_as_3de_reads_it():
    from physcam.export.tde4 import tde4_lens_text

    lens = load_lens("dgauss_50mm")
    res = distortion_field(camera_state(lens, focus_mm=FOCUS, sensor_mm=(36, 24)), width_px=W_PX,
                           height_px=H_PX, maps=False)
    fit = fit_tde4_radial(samples_from_field(res))
    assert fit.acceptable
    got = _read_3de4_lens(tde4_lens_text(fit, lens.name))
    assert got["model"] == "3DE4 Radial - Standard, Degree 4" and got["mode"] == "DISTORTION_STATIC"
    assert (got["w"], got["h"]) == pytest.approx((3.6, 2.4))  # cm
    assert got["fl"] == pytest.approx(res.pinhole_focal_length_mm[1] / 10.0)
    assert got["pa"] == 1.0 and (got["cx"], got["cy"]) == (0.0, 0.0)
    assert list(got["params"]) == list(TDE4_PARAMETERS)
    assert got["params"]["Distortion - Degree 2"] == fit.coefficients["Distortion - Degree 2"]
    assert got["params"]["B - Cylindric Bending"] == 0.0


def test_nuke_script_feeds_the_image_to_src_and_the_map_to_stmap(tmp_path):
    from physcam.export.nuke import nuke_stmap_script

    text = nuke_stmap_script(tmp_path / "u.exr", tmp_path / "d.exr", plate="p.####.exr", plate_size=(2048, 1366),
                             undistorted_size=(2100, 1400))
    # a .nk node with `inputs N` pops N nodes, the top of the stack as input 0
    stack, wiring = [], {}
    for block in text.split("}\n"):
        if "{" not in block:
            continue
        kind, body = block.strip().split("{", 1)
        knobs = dict(line.strip().split(" ", 1) for line in body.strip().splitlines())
        n = int(knobs.get("inputs", "1"))
        ins = [stack.pop() for _ in range(n)]
        stack.append(knobs.get("name", kind.strip()))
        wiring[stack[-1]] = (kind.strip(), ins, knobs)
    kind, ins, knobs = wiring["physcam_undistort"]
    assert kind == "STMap" and ins == ["physcam_plate", "physcam_undistortion_map"] and knobs["uv"] == "rgb"
    assert wiring["physcam_undistortion_map"][2]["raw"] == "true"
    # the maps carry their own frames (EXR display window = the plate, data window = the overscan):
    # a format knob on their Reads would override them
    assert "format" not in wiring["physcam_undistortion_map"][2]
    assert "format" not in wiring["physcam_distortion_map"][2]
    assert "bounding box 2100 x 1400 (26, 17 px of overscan" in text
    assert wiring["physcam_redistort"][1] == ["physcam_undistorted_render", "physcam_distortion_map"]
    with pytest.raises(PhysCamError):
        nuke_stmap_script('bad"name.exr', "d.exr")


def test_anamorphic_lens_gets_maps_and_a_3de4_cylindric_fit():
    """Navarro 2x: maps checked against forward-traced rays in both meridians; the 3DE4 fit with its
    cylindric terms, its residual stated (and judged)."""
    from physcam.analysis.distortion.stmap import apply_stmap

    lens = load_lens("navarro_anamorphic_2x")
    sensor, size, focus_mm = (24.9, 18.7), (1536, 1152), 3000.0
    res = distortion_field(camera_state(lens, focus_mm=focus_mm, sensor_mm=sensor), width_px=size[0], height_px=size[1])
    fx, fy = res.pinhole_focal_length_mm
    assert fy / fx == pytest.approx(1.96, abs=0.05)  # the squeeze, per meridian
    ideal, real = ideal_grid_and_real(lens, focus_mm, sensor, size, margin=(30, 25))
    ox, oy = res.overscan_px
    W2, H2 = size[0] + 2 * ox, size[1] + 2 * oy
    probe = np.zeros((1, ideal.shape[0], 3))
    probe[0, :, 0] = (ideal[:, 0] + ox) / W2
    probe[0, :, 1] = (ideal[:, 1] + oy) / H2
    src = apply_stmap(res.undistortion_stmap, probe)[0, :, :2] * size
    assert np.hypot(*(src - real).T).max() < 0.1
    fit = fit_tde4_radial(samples_from_field(res))
    assert fit.coefficients["pixel_aspect"] == pytest.approx(fy / fx)
    assert fit.coefficients["B - Cylindric Bending"] != 0.0
    assert math.isfinite(fit.max_residual_px) and fit.rms_residual_px <= fit.max_residual_px
    no_cyl = fit_tde4_radial(samples_from_field(res), cylindric=False)
    assert fit.rms_residual_px <= no_cyl.rms_residual_px + 1e-9  # the cylindric terms help, never hurt


def test_bad_fit_inputs_are_clear_errors(distagon):
    _, res, _ = distagon
    s = samples_from_field(res)
    with pytest.raises(PhysCamError):
        fit_brown_conrady(s, "sideways")
    with pytest.raises(PhysCamError):
        fit_models(s, ["zemax"])
    with pytest.raises(PhysCamError):
        fit_tde4_radial(s, max_residual_px=-1.0)
    with pytest.raises(PhysCamError):
        samples_from_field("not a field")


def test_a_fisheye_on_a_large_sensor_is_refused_not_mapped():
    """The Nikkor 16 mm fisheye covers 180 degrees on 36 x 24: a pinhole cannot hold the frame's corners."""
    with pytest.raises(PhysCamError, match="fisheye"):
        distortion_field(camera_state(load_lens("nikkor_fisheye_16mm_f2_8"), focus_mm=FOCUS, sensor_mm=(36, 24)),
                         width_px=512, height_px=342, maps=False)


def test_opentrackio_entry_is_the_same_map_in_millimetres_y_down():
    """OpenLensIO's reading (mm on the sensor, y down, for the pinhole F) of the U-D entry moves points
    where the fitted model (normalised, y up) does."""
    m = _brown(dict(k1=-0.12, k2=0.03, k3=-0.004, p1=0.002, p2=-0.001), direction="U-D", f=35.0)
    e = m.opentrackio()
    assert e["model"] == "Brown-Conrady U-D"
    up = np.array([[6.0, 4.0], [-10.0, 7.5], [3.0, -9.0]])  # picture mm, y up
    expect = m.formula(up)
    x, y = up[:, 0], -up[:, 1]  # y down
    r2 = x * x + y * y
    k1, _, k2, _, k3, _ = e["radial"]  # OpenLensIO's order: l1, l3, l5 the numerator's r^2, r^4, r^6
    p1, p2 = e["tangential"]
    radial = 1 + k1 * r2 + k2 * r2 ** 2 + k3 * r2 ** 3
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    assert np.column_stack([xd, -yd]) == pytest.approx(expect, abs=1e-12)


@pytest.mark.parametrize("reader", ["camdkit", "unreal"])
def test_distortions_opentrackio_block_reads_right_in_camdkit_and_unreal(reader):
    """`physcam distortion`'s OpenTrackIO block (brown_conrady.json) is the entry `physcam live` sends:
    six radial terms in OpenLensIO's order, which camdkit's note and Unreal's receiver
    (tests/_opentrackio_readers.py) both read back to the fitted map at the 4K corners within 0.1 px."""
    from _opentrackio_readers import READERS, opencv_rational

    from physcam.analysis.distortion.models import samples_from_field
    from physcam.cli.distortion import brown_conrady_document
    from physcam.live.lens_data import distortion_for_sample

    lens = load_lens("dgauss_50mm")
    w, h, W = 24.89, 18.66, 4096
    field = distortion_field(camera_state(lens, focus_mm=2000.0, sensor_mm=(w, h)), width_px=W,
                             height_px=round(W * h / w), maps=False)
    fits = [fit_brown_conrady(samples_from_field(field), d, max_residual_px=math.inf) for d in ("D-U", "U-D")]
    block = brown_conrady_document("dgauss_50mm", fits)["opentrackio_lens_distortion"]
    assert [e["model"] for e in block] == ["Brown-Conrady D-U", "Brown-Conrady U-D"]
    assert all(len(e["radial"]) == 6 for e in block)
    ud, f = block[1], fits[1].coefficients["fy_mm"]
    live, f_live = distortion_for_sample(lens, w, h, 2000.0)
    assert ud == live and f == f_live  # one conversion: what live sends
    corners = np.array([[w / 2, h / 2], [-w / 2, h / 2], [w / 2, -h / 2], [-w / 2, -h / 2]])
    px = W / w
    own = fits[1].formula(corners) * px
    theirs = opencv_rational(corners / f, READERS[reader](ud, f)) * f * px
    assert np.abs(own - corners * px).max() > 2.0  # the corners move (a reader that reads nothing fails)
    assert np.abs(theirs - own).max() < 0.1
