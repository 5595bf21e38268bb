"""OpenCV pinhole fits checked against OpenCV itself (cv2.projectPoints as an independent oracle),
a hand-worked distortion-free lens, and the Omniverse schema's documented attribute names."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import InputError, WrongTypeError
from physcam.export.opencv_distortion import OMNI_API_SCHEMA, fit_opencv_pinhole
from physcam.lens.library import load_lens
from physcam.lens.prescription import LensMetadata, Medium, Prescription, Surface

cv2 = pytest.importorskip("cv2")

W_MM, H_MM, W_PX, H_PX = 36.0, 24.0, 4096, 2731


def _pixels(film_xy, w=W_MM, h=H_MM, W=W_PX, H=H_PX):
    # the upright image of the inverted real image: film x (right) -> pixel u leftward, film y (up) -> v downward
    return np.stack([W / 2 - film_xy[:, 0] * W / w, H / 2 + film_xy[:, 1] * H / h], axis=1)


def _project(cam, obj_cv):
    img, _ = cv2.projectPoints(np.ascontiguousarray(obj_cv, dtype=np.float64).reshape(-1, 1, 3), np.zeros(3),
                               np.zeros(3), cam.camera_matrix(), cam.distortion_coefficients())
    return img.reshape(-1, 2)


def _directions_over_sensor(f, n=60, seed=3):
    rng = np.random.default_rng(seed)
    h = rng.uniform([-0.49 * W_MM, -0.49 * H_MM], [0.49 * W_MM, 0.49 * H_MM], size=(n, 2))
    d = np.column_stack([h[:, 0] / f, h[:, 1] / f, np.ones(n)])
    return d / np.linalg.norm(d, axis=1)[:, None]


@pytest.fixture(scope="module")
def dgauss():
    return load_lens("dgauss_50mm")


@pytest.mark.parametrize("terms", ["k1k2k3", "rational"])
def test_opencv_lands_where_real_rays_land_at_infinity(dgauss, terms):
    from physcam.analysis._chief import aim_from_infinity
    from physcam.optics.focusing import focus
    from physcam.trace import RayBatch, trace_through

    cam = fit_opencv_pinhole(dgauss, W_MM, H_MM, W_PX, H_PX, terms=terms)
    assert cam.max_residual_px < 0.1
    assert cam.p1 == cam.p2 == 0.0
    # forward chief rays of collimated beams (not the backward rays the fit used), traced to the film
    wl = dgauss.wavelength_nm
    d = _directions_over_sensor(50.0)
    aimed = aim_from_infinity(dgauss, d, wavelength_nm=wl)
    film_z = focus(dgauss, math.inf).film_z
    out = trace_through(dgauss, RayBatch.from_arrays(aimed.start, aimed.direction, wl), end_z=film_z)
    assert (aimed.ok & out.ok).all()
    real_px = _pixels(np.column_stack([out.x, out.y]))
    # the scene point of a beam travelling along d lies at -d; OpenCV's frame is x right, y down, z forward
    obj = np.column_stack([-d[:, 0], d[:, 1], d[:, 2]])
    err = np.hypot(*(_project(cam, obj) - real_px).T)
    assert err.max() < 0.1
    assert err.max() < cam.max_residual_px + 0.01


def test_opencv_lands_on_real_rays_at_a_finite_focus(dgauss):
    from physcam.analysis._chief import aim_from_film
    from physcam.optics import paraxial
    from physcam.optics.focusing import focus
    from physcam.trace import RayBatch, trace_through

    mark = 1500.0
    cam = fit_opencv_pinhole(dgauss, W_MM, H_MM, W_PX, H_PX, focus_mm=mark)
    assert cam.max_residual_px < 0.1
    # fx is physcam's best-match pinhole: 52.048 mm at 1.5 m (GaussianData's documented figure)
    assert cam.fx * W_MM / W_PX == pytest.approx(52.048, abs=1e-3)
    s = focus(dgauss, mark)
    q, wl = s.prescription, dgauss.wavelength_nm
    rng = np.random.default_rng(7)
    film = rng.uniform([-0.49 * W_MM, -0.49 * H_MM], [0.49 * W_MM, 0.49 * H_MM], size=(40, 2))
    aimed = aim_from_film(q, film, s.film_z, wavelength_nm=wl)
    out = trace_through(q, RayBatch.from_arrays(aimed.start, aimed.direction, wl), reverse=True)
    assert (aimed.ok & out.ok).all()
    t = (s.object_z - out.z) / out.N
    p = np.column_stack([out.x + t * out.L, out.y + t * out.M, out.z + t * out.N])  # on the plane of sharp focus
    z_ep = paraxial.gaussian(q, object_z=s.object_z, film_z=s.film_z).z_entrance_pupil
    assert mark - (s.film_z - z_ep) == pytest.approx(-s.object_z + z_ep, abs=1e-6)
    obj = np.column_stack([p[:, 0], -p[:, 1], -(p[:, 2] - z_ep)])  # seen from the entrance pupil
    err = np.hypot(*(_project(cam, obj) - _pixels(film)).T)
    assert err.max() < 0.1


def _concentric(radius=50.0, n=1.5):
    """A sphere of glass (n behind it) with the stop at its centre: every chief ray meets the surface
    normally and goes straight through the centre, so h = L tan(theta) exactly with L the centre-to-film
    distance; the entrance pupil is the centre (the stop seen through a surface centred on it), so the
    best-match pinhole is L and the OpenCV k's vanish. Paraxially L = n R / (n - 1) - R = R / (n - 1) = 100 mm."""
    g = Medium(n, 0.0)
    return Prescription((Surface(radius, radius, g, 45.0), Surface(0.0, 2.0 * radius, g, 1.0, kind="stop")),
                        LensMetadata(name="concentric sphere")).validate()


@pytest.mark.parametrize("terms", ["k1k2k3", "rational"])
def test_a_distortion_free_lens_gives_zero_coefficients(terms):
    cam = fit_opencv_pinhole(_concentric(), 24.0, 16.0, 1200, 800, terms=terms)
    assert cam.fx == pytest.approx(100.0 * 1200 / 24.0, rel=1e-9)  # hand-worked L = 100 mm
    assert cam.fy == pytest.approx(100.0 * 800 / 16.0, rel=1e-9)
    for k in (cam.k1, cam.k2, cam.k3, cam.k4, cam.k5, cam.k6, cam.p1, cam.p2):
        assert abs(k) < 1e-8
    assert cam.max_residual_px < 1e-5
    assert (cam.cx, cam.cy) == (600.0, 400.0)


@settings(max_examples=4)
@given(st.sampled_from([(1024, 683), (2048, 1365), (8192, 5461)]))
def test_coefficients_do_not_depend_on_the_pixel_count(size):
    """Normalised coordinates: the k's are a property of the lens, fx scales with the pixels."""
    lens = load_lens("dgauss_50mm")
    a = fit_opencv_pinhole(lens, W_MM, H_MM, W_PX, H_PX)
    b = fit_opencv_pinhole(lens, W_MM, H_MM, *size)
    assert b.fx / size[0] == pytest.approx(a.fx / W_PX, rel=1e-12)
    for k in ("k1", "k2", "k3"):
        assert getattr(b, k) == pytest.approx(getattr(a, k), rel=1e-3, abs=1e-6)


def test_anamorphic_gives_fx_and_fy_from_each_meridian():
    from physcam.optics.focusing import breathing_table
    from physcam.optics.paraxial import gaussian_xy

    lens = load_lens("navarro_anamorphic_2x")
    cam = fit_opencv_pinhole(lens, 12.0, 10.0, 1200, 1000)
    # the film sits where Y (the spherical meridian) focuses; the framing focal length of X there comes
    # from the paraxial field angle to the sensor edge (breathing table), of Y at infinity from its EFL
    (row,) = breathing_table(lens, [math.inf], sensor_width_mm=12.0)
    assert cam.fx == pytest.approx(row.breathing_focal_length_mm * 100.0, rel=1e-9)
    assert cam.fy == pytest.approx(gaussian_xy(lens)["y"].efl * 100.0, rel=1e-9)
    assert cam.fy / cam.fx == pytest.approx(lens.squeeze, rel=0.05)
    assert any("anamorphic" in n for n in cam.notes)


# Omniverse's OmniLensDistortionOpenCvPinholeAPI, as its schema reference lists it
# (https://nvidia-omniverse.github.io/ovrtx/0.7.0/sensors/reference/schemas_lens_distortion.html and the
# example in https://nvidia-omniverse.github.io/ovrtx/sensors/cameras/lens_calibration.html)
OMNI_FLOATS = ["cx", "cy", "fx", "fy", "k1", "k2", "k3", "k4", "k5", "k6", "p1", "p2", "s1", "s2", "s3", "s4"]


def test_usd_attributes_are_omniverses_names_and_types(dgauss):
    cam = fit_opencv_pinhole(dgauss, W_MM, H_MM, W_PX, H_PX)
    a = cam.usd_attributes()
    assert OMNI_API_SCHEMA == "OmniLensDistortionOpenCvPinholeAPI"
    expected = {"omni:lensdistortion:model"} | {f"omni:lensdistortion:opencvPinhole:{k}" for k in OMNI_FLOATS + ["imageSize"]}
    assert set(a) == expected
    assert a["omni:lensdistortion:model"] == "opencvPinhole"
    assert a["omni:lensdistortion:opencvPinhole:imageSize"] == (4096, 2731)
    assert all(type(v) is int for v in a["omni:lensdistortion:opencvPinhole:imageSize"])
    for k in OMNI_FLOATS:
        assert type(a[f"omni:lensdistortion:opencvPinhole:{k}"]) is float
    assert a["omni:lensdistortion:opencvPinhole:fx"] == cam.fx
    d = cam.to_dict()
    assert d["omniverse"]["apiSchemas"] == ["OmniLensDistortionOpenCvPinholeAPI"]
    assert d["focus_from_film_mm"] is None and d["dist_coeffs_opencv_order"][4] == cam.k3


@pytest.mark.parametrize("kwargs", [dict(image_width_px=0), dict(image_width_px=True), dict(image_width_px=4096.0),
                                    dict(image_height_px=10**6), dict(sensor_width_mm=0.0),
                                    dict(sensor_height_mm=float("nan")), dict(terms="k9"),
                                    dict(focus_mm=-1.0)])
def test_bad_values_are_input_errors(dgauss, kwargs):
    args = dict(sensor_width_mm=W_MM, sensor_height_mm=H_MM, image_width_px=W_PX, image_height_px=H_PX)
    args.update(kwargs)
    with pytest.raises(InputError):
        fit_opencv_pinhole(dgauss, **args)


def test_wrong_lens_type():
    with pytest.raises(WrongTypeError):
        fit_opencv_pinhole("dgauss_50mm", W_MM, H_MM, W_PX, H_PX)
