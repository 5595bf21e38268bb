"""Issue 13.3: Mitsuba 3's thinlens sensor matched to the lens report, proven by Mitsuba renders.

The closed forms are worked by hand (tests/_thin_lens.py): a thin lens focused at a mark frames like
a pinhole s' from the film and blurs a point at d into a disk c = A s' |1/d - 1/s| (A = f/N;
distances from the lens). Mitsuba renders (``scalar_rgb``) the camera physcam wrote, and the
images are measured: marker centroids at known angles for the field of view, the second moment of
a defocused emissive sphere for the disk.
"""

from __future__ import annotations

import json
import math

import pytest

from physcam.cli import main
from physcam.errors import ExportError, InputError, WrongTypeError
from physcam.export.mitsuba import mitsuba_camera_values, mitsuba_scene_dict, mitsuba_scene_xml
from physcam.lens.library import load_lens
from physcam.onset.report import solve_lens_report
from physcam.optics.sensors import custom_sensor, find_sensor

from _thin_lens import fov_deg, image_distance_at_mark


def _thin(fstop=2.0, mark=1000.0, squeeze=1.0):
    return solve_lens_report(focal_length_mm=50.0, sensor=find_sensor("FF"), fstop=fstop, focus_mm=mark,
                             squeeze=squeeze)


def test_thinlens_values_are_the_focused_lens():
    """fov from s' (not f), aperture radius f/(2N), focus distance from the lens (the pupil), in
    scene units; the film has the sensor's aspect."""
    v = mitsuba_camera_values(_thin(), width_px=600, meters_per_unit=0.001)
    s = v["sensor"]
    si = image_distance_at_mark(50.0, 1000.0)
    assert s["fov"] == pytest.approx(fov_deg(36.0, si), rel=1e-12)
    assert s["fov"] < fov_deg(36.0, 50.0) * 0.96  # the infinity field is 5 % wider at 1 m
    assert s["fov_axis"] == "x"
    assert s["aperture_radius"] == pytest.approx(12.5)
    assert s["focus_distance"] == pytest.approx(1000.0 - si, rel=1e-12)  # s, from the lens
    assert (s["film"]["width"], s["film"]["height"]) == (600, 400)
    assert s["to_world"][2][3] == pytest.approx(-si)  # the camera at the lens, s' in front of the film
    cm = mitsuba_camera_values(_thin(), width_px=600)["sensor"]  # default: centimetres
    assert cm["aperture_radius"] == pytest.approx(1.25) and cm["focus_distance"] == pytest.approx(s["focus_distance"] / 10)


def test_what_mitsuba_cannot_hold_is_refused():
    with pytest.raises(ExportError, match="principal-point offset"):
        mitsuba_camera_values(_thin(), shift_mm=(2.0, 0.0))
    with pytest.raises(ExportError, match="round disk"):  # a thin lens with a squeeze: a front anamorphic
        mitsuba_camera_values(_thin(squeeze=2.0))
    with pytest.raises(InputError):
        mitsuba_camera_values(_thin(), width_px=0)
    with pytest.raises(InputError):
        mitsuba_camera_values(_thin(), spp=2.5)
    with pytest.raises(WrongTypeError):
        mitsuba_camera_values({"fov": 40})
    with pytest.raises(InputError):
        mitsuba_scene_xml({"sensor": {"type": "perspective"}})


def test_cli_writes_xml_and_dict_and_keeps_existing_files(tmp_path, capsys):
    argv = ["export", "mitsuba", "--focal", "50", "--fstop", "2", "--focus", "1m", "--sensor", "FF",
            "--width-px", "300", "--meters-per-unit", "0.001", "-o", str(tmp_path), "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    d = json.loads((tmp_path / "camera.json").read_text())
    assert d["type"] == "scene" and d["sensor"]["fov"] == pytest.approx(out["sensor"]["fov"])
    assert 'type="thinlens"' in (tmp_path / "camera.xml").read_text()
    assert main(argv) == 2  # no clobber
    assert "already exists" in capsys.readouterr().err
    assert main(argv + ["--force"]) == 0
    assert main(argv[:-3] + ["--shift-x", "2", "-o", str(tmp_path / "b")]) == 2
    assert "principal-point offset" in capsys.readouterr().err


# --- renders -------------------------------------------------------------------------------------------
mi = None
def _variant():
    """mitsuba with its scalar_rgb variant, or a skip that says why."""
    global mi
    mi = pytest.importorskip("mitsuba", reason="the Mitsuba renders need the mitsuba package "
                                               "(pip install mitsuba==3.7.1, in the test extra)")
    try:
        mi.set_variant("scalar_rgb")
    except Exception as exc:  # noqa: BLE001 - a wheel without the variant
        pytest.skip(f"mitsuba has no scalar_rgb variant here: {exc}")
    return mi


def _sphere_xml(x, y, z, r, radiance):
    return (f'<shape type="sphere"><point name="center" x="{x!r}" y="{y!r}" z="{z!r}"/>'
            f'<float name="radius" value="{r!r}"/><emitter type="area"><rgb name="radiance" '
            f'value="{radiance!r}"/></emitter></shape>\n')


def _sphere_dict(x, y, z, r, radiance):
    return {"type": "sphere", "center": [x, y, z], "radius": r,
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [radiance] * 3}}}


def _blob(img, x0, x1, y0, y1):
    """Centroid (pixel units, pixel centres at +0.5) and second moment of a window of the image."""
    import numpy as np

    sub = img[y0:y1, x0:x1]
    yy, xx = np.mgrid[y0:y1, x0:x1] + 0.5
    tot = sub.sum()
    cx, cy = (xx * sub).sum() / tot, (yy * sub).sum() / tot
    return cx, cy, (((xx - cx) ** 2 + (yy - cy) ** 2) * sub).sum() / tot


def _measure(img, px_per_mm, f_pin, marker_deg=(15.0, 10.0)):
    """(horizontal fov, vertical fov) from the markers, and the defocus disk diameter (mm on the film)
    from the centre blob's second moment."""
    h, w = img.shape
    lx, _, _ = _blob(img, 0, w // 5, 0, h)
    rx, _, _ = _blob(img, w - w // 5, w, 0, h)
    _, uy, _ = _blob(img, 2 * w // 5, 3 * w // 5, 0, h // 5)
    _, by, _ = _blob(img, 2 * w // 5, 3 * w // 5, h - h // 5, h)
    th, tv = (math.tan(math.radians(a)) for a in marker_deg)
    hfov = 2 * math.degrees(math.atan(th * (w / 2) / ((rx - lx) / 2)))
    vfov = 2 * math.degrees(math.atan(tv * (h / 2) / ((by - uy) / 2)))
    _, _, m2 = _blob(img, w // 2 - w // 6, w // 2 + w // 6, h // 2 - h // 6, h // 2 + h // 6)
    return hfov, vfov, m2


def _scene_positions(values, d_mm, radius_mm, mpu_mm, marker_deg=(15.0, 10.0)):
    """Markers on the focus plane at +-15 deg (horizontal) and +-10 deg (vertical) seen from the
    pupil, and the defocused sphere d_mm in front of the pupil; scene units of mpu_mm mm."""
    s = values["sensor"]
    z0 = s["to_world"][2][3]  # the pupil
    fd = s["focus_distance"]
    th, tv = (math.tan(math.radians(a)) for a in marker_deg)
    rm = 0.004 * fd  # markers: small, sharp
    markers = [(-fd * th, 0.0, z0 - fd, rm), (fd * th, 0.0, z0 - fd, rm), (0.0, fd * tv, z0 - fd, rm),
               (0.0, -fd * tv, z0 - fd, rm)]
    return markers, (0.0, 0.0, z0 - d_mm / mpu_mm, radius_mm / mpu_mm)


def _disk_from_moment(m2, e_px, px_per_mm):
    """A uniform disk of diameter c convolved with the sphere's sharp image (a disk of diameter e) and
    the box pixel filter (variance 1/12 px^2 per axis): E[r^2] = c^2/8 + e^2/8 + 1/6."""
    return math.sqrt(8.0 * m2 - e_px**2 - 8.0 / 6.0) / px_per_mm


@pytest.mark.slow
def test_render_of_the_xml_frames_and_blurs_like_the_thin_lens(tmp_path):
    """50 mm f/2 focused at a 1 m mark on full frame; a sphere 0.35 m from the lens. The render's
    disk matches c = A s' |1/d - 1/s| within 2 % and its field of view the focused lens's within
    0.1 %; the infinity field (fov from f, as Mitsuba users type it) would be 5.4 % off."""
    _variant()
    import numpy as np

    r = _thin(fstop=2.0, mark=1000.0)
    v = mitsuba_camera_values(r, width_px=360, meters_per_unit=0.001, spp=256)
    xml = mitsuba_scene_xml(v)
    d_mm, radius_mm = 350.0, 1.5
    markers, centre = _scene_positions(v, d_mm, radius_mm, 1.0)
    shapes = "".join(_sphere_xml(*m, 1.0) for m in markers) + _sphere_xml(*centre, 1.0)
    shapes += '<integrator type="direct"/>\n'
    # box pixel filter: each pixel integrates its own area (no blur, no bias of centroids)
    xml = xml.replace('<film type="hdrfilm">', '<film type="hdrfilm"><rfilter type="box"/>')
    (tmp_path / "scene.xml").write_text(xml.replace("</scene>", shapes + "</scene>"))
    img = np.array(mi.render(mi.load_file(str(tmp_path / "scene.xml"))))[:, :, 0].astype(float)
    px_per_mm = 360 / 36.0
    si = image_distance_at_mark(50.0, 1000.0)
    s = 1000.0 - si
    hfov, vfov, m2 = _measure(img, px_per_mm, si)
    assert hfov == pytest.approx(fov_deg(36.0, si), rel=1e-3)
    assert vfov == pytest.approx(fov_deg(24.0, si), rel=1e-3)
    assert hfov == pytest.approx(r.hfov_focus_deg, rel=1e-3)
    e_px = 2.0 * si * radius_mm / math.sqrt(d_mm**2 - radius_mm**2) * px_per_mm
    c = 25.0 * si * abs(1.0 / d_mm - 1.0 / s)
    measured = _disk_from_moment(m2, e_px, px_per_mm)
    assert measured == pytest.approx(c, rel=0.02)
    assert measured != pytest.approx(c * 50.0 / si, rel=0.02)  # the infinity-FOV camera's disk


@pytest.mark.slow
def test_render_of_the_dict_matches_a_real_lens_report(tmp_path):
    """dgauss.50mm at f/2.8 focused at a 1.2 m mark on a 24 x 16 mm sensor, loaded with mi.load_dict
    from the JSON physcam writes: the render frames like the report's focused field (markers at 10
    and 6 degrees; within 0.1 %) and
    blurs a point 0.4 m from the pupil into A f_pin |1/d - 1/s| (A the entrance pupil, s and d from
    it) within 2 %."""
    _variant()
    import numpy as np

    lens = load_lens("dgauss_50mm")
    r = solve_lens_report(focal_length_mm=None, sensor=custom_sensor(24.0, 16.0), fstop=2.8, focus_mm=1200.0, lens=lens)
    v = mitsuba_camera_values(r, width_px=360, meters_per_unit=0.001, spp=256)
    d = json.loads(json.dumps(mitsuba_scene_dict(v)))  # what the JSON file holds
    sensor = dict(d["sensor"], to_world=mi.ScalarTransform4f(d["sensor"]["to_world"]))
    sensor["film"] = dict(sensor["film"], rfilter={"type": "box"})
    d_mm, radius_mm = 400.0, 1.5
    markers, centre = _scene_positions(v, d_mm, radius_mm, 1.0, marker_deg=(10.0, 6.0))
    scene = {"type": "scene", "integrator": {"type": "direct"}, "sensor": sensor}
    for i, m in enumerate(markers + [centre]):
        scene[f"s{i}"] = _sphere_dict(*m, 1.0)
    img = np.array(mi.render(mi.load_dict(scene)))[:, :, 0].astype(float)
    px_per_mm = 360 / 24.0
    f_pin = r.pinhole[0]
    hfov, vfov, m2 = _measure(img, px_per_mm, f_pin, marker_deg=(10.0, 6.0))
    assert hfov == pytest.approx(r.hfov_focus_deg, rel=1e-3)
    assert vfov == pytest.approx(r.vfov_focus_deg, rel=1e-3)
    s = r.focus_from_film_mm - r.entrance_pupil_from_film_mm
    e_px = 2.0 * f_pin * radius_mm / math.sqrt(d_mm**2 - radius_mm**2) * px_per_mm
    c = r.aperture_diameter_mm * f_pin * abs(1.0 / d_mm - 1.0 / s)
    assert _disk_from_moment(m2, e_px, px_per_mm) == pytest.approx(c, rel=0.02)
