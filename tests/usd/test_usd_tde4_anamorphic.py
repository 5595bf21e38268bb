"""3DE4 Anamorphic - Standard, Degree 4 and 6 on a USD camera (issue 49 item 2).

USD's lensDistortion has no anamorphic model, so ``physcam usd write`` of an anamorphic lens puts 3DE's own
model on the companion camera (``physcam:tde4AnamorphicDegree<d>:*``). Oracles: the model's published
form (Science-D-Visions' Lens Distortion Plugin Kit, "tde4_ldm_standard.pdf": diagonally normalised
coordinates of the desqueezed filmback, the pixel aspect undone, x (1 + sum Cx_ij r^j cos(i phi)),
y (1 + sum Cy_ij r^j cos(i phi)), the aspect redone) evaluated here from the stored attributes alone;
the per-meridian framing focal lengths of the hand y-u trace (tests/_anamorphic_yu.py) for the focal
length and pixel aspect; the traced chief rays for the residual.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from physcam.cli import main

from _anamorphic_yu import hand_framing_focal_lengths

pxr = pytest.importorskip("pxr")
from pxr import Usd  # noqa: E402

from physcam.usd.validate import validation_errors  # noqa: E402

W, H = 18.0, 13.5  # mm: a frame Neil's front 2x covers (docs/anamorphic.md)
SLUG = "neil_front_anamorphic_2x"


def _published_undistort(attrs, degree, p_mm):
    """Distorted -> undistorted picture mm on the physical (squeezed) film by the published form, from USD alone."""
    a = attrs["pixelAspect"]
    w_fb, h_fb = attrs["filmback"]
    r_fb = math.hypot(w_fb, h_fb) / 2.0  # half the desqueezed filmback's diagonal
    c = dict(zip(attrs["parameterNames"], attrs["parameters"]))
    p = np.stack([a * p_mm[:, 0], p_mm[:, 1]], axis=1) / r_fb  # desqueezed, diagonally normalised
    q = np.stack([p[:, 0] / a, p[:, 1]], axis=1)  # the pixel aspect undone
    r, phi = np.hypot(q[:, 0], q[:, 1]), np.arctan2(q[:, 1], q[:, 0])
    fx, fy = np.ones(len(q)), np.ones(len(q))
    for j in range(2, degree + 1, 2):
        for i in range(0, j + 1, 2):
            fx += c[f"Cx{i}{j} - Degree {j}"] * r ** j * np.cos(i * phi)
            fy += c[f"Cy{i}{j} - Degree {j}"] * r ** j * np.cos(i * phi)
    pu = np.stack([a * q[:, 0] * fx, q[:, 1] * fy], axis=1)  # the aspect redone
    return np.stack([pu[:, 0] / a, pu[:, 1]], axis=1) * r_fb  # back to the squeezed film, mm


@pytest.fixture(scope="module")
def stage(tmp_path_factory):
    out = tmp_path_factory.mktemp("tde4") / "neil.usda"
    assert main(["usd", "write", str(out), "--lens", SLUG, "--focus", "3m", "--sensor-width", str(W),
                 "--sensor-height", str(H)]) == 0
    return Usd.Stage.Open(str(out))


def _attrs(prim, degree):
    p = f"physcam:tde4AnamorphicDegree{degree}:"
    names = ("model", "focalLength", "filmback", "pixelAspect", "parameterNames", "parameters", "rmsResidualPx",
             "maxResidualPx", "plateSizePx")
    return {n: prim.GetAttribute(p + n).Get() for n in names}


@pytest.mark.parametrize("degree, max_px", [(4, 0.5), (6, 0.1)])
def test_the_stored_model_reproduces_the_traced_field(stage, degree, max_px):
    from physcam.analysis.distortion.models import samples_from_field
    from physcam.analysis.distortion.stmap import distortion_field
    from physcam.optics.state import camera_state
    from physcam.lens.library import load_lens

    assert validation_errors(stage) == []
    attrs = _attrs(stage.GetPrimAtPath("/Cameras/Camera/Camera"), degree)
    assert attrs["model"] == f"3DE4 Anamorphic - Standard, Degree {degree}"
    assert len(attrs["parameters"]) == {4: 10, 6: 18}[degree]
    fx, fy = hand_framing_focal_lengths(SLUG, 3000.0)
    assert attrs["focalLength"] == pytest.approx(fy, rel=1e-5)
    assert attrs["pixelAspect"] == pytest.approx(fy / fx, rel=1e-5)  # 2.0 at 3 m, the desqueezed pinhole round
    assert tuple(attrs["filmback"]) == pytest.approx((W * fy / fx, H), rel=1e-5)
    # the traced chief rays, on a 4096-pixel-wide plate of the same frame
    cam = camera_state(load_lens(SLUG), focus_mm=3000.0, sensor_mm=(W, H))
    s = samples_from_field(distortion_field(cam, width_px=512, height_px=384, maps=False))
    got = _published_undistort(attrs, degree, s.distorted_mm)
    err_px = np.hypot(*((got - s.undistorted_mm) * (4096 / W)).T)
    assert err_px.max() < max_px
    assert attrs["maxResidualPx"] * 4096 / attrs["plateSizePx"][0] < max_px


def test_a_spherical_lens_has_no_anamorphic_model(tmp_path):
    out = tmp_path / "dg.usda"
    assert main(["usd", "write", str(out), "--lens", "dgauss_50mm", "--focus", "3m", "--sensor", "S35"]) == 0
    stage = Usd.Stage.Open(str(out))
    prim = stage.GetPrimAtPath("/Cameras/Camera/Camera")
    assert prim.GetAttribute("lensDistortion:k1").HasAuthoredValue()
    assert not [p for p in prim.GetAuthoredPropertyNames() if p.startswith("physcam:tde4Anamorphic")]


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_a_shots_companion_gets_the_model_and_loses_it_with_a_spherical_lens(tmp_path):
    from physcam.lens.library import load_lens
    from physcam.usd.author import CameraSpec
    from physcam.usd.kit import refresh_shot, write_body_file, write_shot, write_vendor_lens

    lens_f = write_vendor_lens(tmp_path / "lens.usda", load_lens(SLUG), focus_mm=3000.0, fstop=2.8)
    body_f = write_body_file(tmp_path / "body.usda", CameraSpec.of(sensor_width_mm=W, sensor_height_mm=H))
    shot = write_shot(tmp_path / "shot.usda", body_f, lens_f)
    stage = Usd.Stage.Open(str(shot))
    assert validation_errors(stage) == []
    attrs = _attrs(stage.GetPrimAtPath("/Cameras/Shot/Camera"), 4)
    fx, fy = hand_framing_focal_lengths(SLUG, 3000.0)
    assert attrs["pixelAspect"] == pytest.approx(fy / fx, rel=1e-5) and len(attrs["parameters"]) == 10
    del attrs, stage
    write_vendor_lens(lens_f, load_lens("dgauss_50mm"), focus_mm=3000.0, fstop=2.8, force=True)
    refresh_shot(shot)
    stage = Usd.Stage.Open(str(shot))
    prim = stage.GetPrimAtPath("/Cameras/Shot/Camera")
    assert prim.GetAttribute("lensDistortion:k1").HasAuthoredValue()
    assert not [p for p in prim.GetAuthoredPropertyNames() if p.startswith("physcam:tde4Anamorphic")]
