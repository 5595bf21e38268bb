"""physcam.export.blender without Blender: what the OSL camera bakes in, and its errors; the CLI."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from physcam.cli import main
from physcam.errors import ExportError, InputError, OpticsError
from physcam.export.blender import blender_setup_script, osl_camera_shader, write_blender_camera
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state
from physcam.optics.focusing import focus
from physcam.optics.paraxial import stop_semi_diameter_for_fstop
from physcam.trace.surfaces import surface_table


def _array(src: str, name: str) -> np.ndarray:
    m = re.search(rf"\b(?:float|int) {name}\[\w+\] = \{{([^}}]*)\}};", src)
    assert m, name
    return np.array([float(v) for v in m.group(1).split(",")])


def _scalar(src: str, name: str) -> float:
    return float(re.search(rf"\bfloat {name} = ([^;]+);", src).group(1))


@pytest.mark.parametrize("slug, focus_mm, fstop", [("navarro_anamorphic_2x", 4000.0, 4.0),
                                                    ("canon_rf_85mm_f1_2", 1500.0, None),
                                                    ("zeiss_distagon_35mm_f4", math.inf, 8.0)])
def test_arrays_are_physcams_surface_table_of_the_focused_lens(slug, focus_mm, fstop):
    """The emitted rows are physcam's surface_table (film side first) of the lens focused by
    physcam's focus solution (internal focusing for the Canon and the Navarro, unit focusing for
    the Distagon), with the stop at the f-number's semi-diameter, and FILM_Z is its film plane."""
    lens = load_lens(slug)
    src = osl_camera_shader(camera_state(lens, focus_mm=focus_mm, fstop=fstop, sensor_mm=(24.0, 18.0)), dispersion=True)
    st = focus(lens, focus_mm)
    q = st.prescription
    semi = None if fstop is None else stop_semi_diameter_for_fstop(lens, fstop)
    t = surface_table(q, reverse=True, stop_semi_diameter=semi)
    assert re.search(rf"#define N_SURF {len(lens.surfaces)}\b", src)
    # the tracer's kinds, a sphere (a spherical surface, or an aspheric one with no terms, of conic 0)
    # marked 4: the shader's shortcut (physcam.export.osl.SPHERE_KIND)
    sphere = [s.kind in ("spherical", "aspheric") and s.conic == 0.0 and s.radius != 0.0
              and not any(s.aspheric) for s in reversed(q.surfaces)]
    assert _array(src, "KIND").tolist() == [4 if sp else k for k, sp in zip(t.kind.tolist(), sphere)]
    assert 4 in _array(src, "KIND").tolist()
    for name, col in (("VZ", t.vertex_z), ("AX", t.ax), ("AY", t.ay), ("AZ", t.az), ("CV", t.curvature),
                      ("CK", t.conic), ("SEMI", t.semi_diameter), ("DB", t.disp_before), ("DA", t.disp_after)):
        assert np.array_equal(_array(src, name), col.ravel()), name
    if t.aspheric.any():
        assert np.array_equal(_array(src, "ASPH"), t.aspheric.ravel())
    assert _scalar(src, "FILM_Z") == st.film_z
    assert _scalar(src, "REAR_Z") == q.vertex_z[-1]
    if st.method == "internal":  # the focus groups really moved
        assert not np.array_equal(_array(src, "VZ"), surface_table(lens, reverse=True).vertex_z)
    if lens.is_anamorphic:
        assert (_array(src, "AX") != _array(src, "AY")).any()  # cylinders


def test_monochrome_indices_are_physcams_at_the_design_wavelength():
    lens = load_lens("dgauss_50mm")
    src = osl_camera_shader(camera_state(lens, focus_mm=2000.0, sensor_mm=(36.0, 24.0)), fresnel=True)
    q = focus(lens, 2000.0).prescription
    t = surface_table(q, reverse=True)
    np.testing.assert_allclose(_array(src, "N1"), t.index_before(lens.wavelength_nm), rtol=1e-15)
    np.testing.assert_allclose(_array(src, "N2"), t.index_after(lens.wavelength_nm), rtol=1e-15)
    assert np.array_equal(_array(src, "RSC"), t.r_scale)
    # dispersion off: no per-ray wavelength or index (hashnoise also draws the iris's repeated aims)
    assert "DB[" not in src and "u_wl" not in src and "lam " not in src
    assert "Ts *=" in src


def test_aperture_and_features_are_emitted():
    lens = load_lens("dgauss_50mm")
    iris = dict(nsides=6, angle_deg=30.0, roundness=0.25, density=-0.5)
    src = osl_camera_shader(camera_state(lens, focus_mm=3000.0, sensor_mm=(36.0, 24.0)), aperture=iris)
    # the iris's numbers in the data block (the template's code reads them by name)
    assert f"#define AP_WEDGE {2 * math.pi / 6!r}\n" in src
    assert f"#define AP_ANGLE {math.radians(30.0)!r}\n" in src
    assert "#define AP_ROUNDNESS 0.25\n" in src and "#define AP_DENSITY -0.5\n" in src
    assert "AP_ROUNDNESS * (1.0 - pg)" in src and "AP_DENSITY * (2.0 * sr - 1.0)" in src
    plain = osl_camera_shader(camera_state(lens, focus_mm=3000.0, sensor_mm=(36.0, 24.0)))
    assert "AP_WEDGE" not in plain and "Ts *=" not in plain


def test_bad_input_is_a_clear_error(tmp_path):
    lens = load_lens("zeiss_distagon_35mm_f4")
    kw = dict(sensor_mm=(36.0, 24.0))
    with pytest.raises(OpticsError, match="closest real focus"):
        osl_camera_shader(camera_state(lens, focus_mm=50.0, **kw))
    with pytest.raises(OpticsError, match="faster than this lens opens"):
        osl_camera_shader(camera_state(lens, focus_mm=3000.0, fstop=1.0, **kw))
    for bad in (0.0, -5.0, float("nan"), "three metres", True):  # ("3m" reads as 3000 mm, as camera_state reads it)
        with pytest.raises(InputError):
            osl_camera_shader(camera_state(lens, focus_mm=bad, **kw))
    with pytest.raises(InputError, match="sensor width"):
        osl_camera_shader(camera_state(lens, focus_mm=3000.0, sensor_mm=(-1.0, 24.0)))
    with pytest.raises(InputError, match="aperture"):
        osl_camera_shader(camera_state(lens, focus_mm=3000.0, **kw), aperture="hexagon")
    with pytest.raises(InputError, match="roundness"):
        osl_camera_shader(camera_state(lens, focus_mm=3000.0, **kw), aperture=(6, 0.0, 2.0, 0.0))
    with pytest.raises(InputError):
        osl_camera_shader(camera_state(lens, focus_mm=3000.0, **kw), dispersion="yes")
    with pytest.raises(TypeError):
        osl_camera_shader("zeiss_distagon_35mm_f4", focus_mm=3000.0, **kw)
    with pytest.raises(InputError, match="aspect"):
        blender_setup_script("cam.osl", sensor_width_mm=36.0, sensor_height_mm=24.0, resolution=(1920, 1080))
    with pytest.raises(InputError, match="OSL source"):
        blender_setup_script("not\na shader", sensor_width_mm=36.0, sensor_height_mm=24.0)


def test_setup_script_embeds_the_shader_and_sets_the_camera():
    src = "shader cam(output point position = 0) {}\n"
    py = blender_setup_script(src, sensor_width_mm=24.89, sensor_height_mm=18.66, resolution=(2048, 1536))
    ns: dict = {}
    compile(py, "setup.py", "exec")  # valid Python
    body = py.replace("import bpy", "bpy = None")
    exec(body, ns)
    assert ns["SHADER_SOURCE"] == src and ns["SHADER_PATH"] is None
    assert ns["RESOLUTION"] == (2048, 1536) and ns["SENSOR_WIDTH_MM"] == 24.89
    assert callable(ns["apply"]) and 'cam.type = "CUSTOM"' in py and "shading_system = True" in py
    by_path = blender_setup_script("lens.osl", sensor_width_mm=36.0, sensor_height_mm=24.0)
    ns = {}
    exec(by_path.replace("import bpy", "bpy = None"), ns)
    assert ns["SHADER_PATH"] == "lens.osl" and ns["RESOLUTION"] == (1920, 1280)


def test_write_blender_camera_does_not_clobber(tmp_path):
    lens = load_lens("cooke_triplet_50mm_f4_5")
    camera = camera_state(lens, focus_mm=5000.0, sensor_mm=(36.0, 24.0))
    osl, setup = write_blender_camera(camera, tmp_path, name="cooke")
    assert osl.name == "cooke.osl" and setup.name == "setup_cooke.py"
    assert osl.read_text() == osl_camera_shader(camera)
    assert repr(osl.read_text()) in setup.read_text()
    with pytest.raises(ExportError, match="exists"):
        write_blender_camera(camera, tmp_path, name="cooke")
    write_blender_camera(camera_state(lens, focus_mm=2000.0, sensor_mm=(36.0, 24.0)), tmp_path, name="cooke", force=True)
    assert "focus 2000 mm" in osl.read_text()


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def test_cli_export_blender(capsys, tmp_path):
    rc, out, _ = run(capsys, "export", "blender", "navarro_anamorphic_2x", "--focus", "3m", "--fstop", "4",
                     "--sensor-width", "24.89", "--sensor-height", "18.66", "--blades", "7", "--dispersion",
                     "--fresnel", "-o", str(tmp_path), "--json")
    assert rc == 0
    d = json.loads(out)
    src = (tmp_path / "navarro_anamorphic_2x.osl").read_text()
    assert d["shader"] == str(tmp_path / "navarro_anamorphic_2x.osl") and d["resolution"] == [1920, 1439]
    lens = load_lens("navarro_anamorphic_2x")
    camera = camera_state(lens, focus_mm=3000.0, fstop=4.0, sensor_mm=(24.89, 18.66))
    assert src == osl_camera_shader(camera, aperture=(7, 0.0, 0.0, 0.0), dispersion=True, fresnel=True)
    assert (tmp_path / "setup_navarro_anamorphic_2x.py").is_file()
    rc, _, err = run(capsys, "export", "blender", "navarro_anamorphic_2x", "--focus", "3m", "-o", str(tmp_path))
    assert rc == 2 and "exists" in err and "--force" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("argv, message", [
    (["--focus", "20cm"], "closest focus"),
    (["--focus", "3m", "--fstop", "0.9"], "faster than this lens opens"),
    (["--focus", "3m", "--blades", "5.5"], "whole number"),
])
def test_cli_errors_are_one_line(capsys, tmp_path, argv, message):
    rc, out, err = run(capsys, "export", "blender", "canon_rf_85mm_f1_2", *argv, "-o", str(tmp_path))
    assert rc == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not any(tmp_path.iterdir())



def test_focus_table_of_a_lens_longer_than_its_one_to_one_conjugate():
    """The Laikin zoom at 15 mm is 288 mm long while its 1:1 conjugate (4 f + hiatus) is 250 mm from
    the film: a subject there would be inside the lens. closest_focus, and so the extension's focus
    table (and its panel's closest focus), stops where the subject reaches the front vertex: the mark
    equals the back focus plus the lens's track (subject distance 0), not the 1:1 mark."""
    from physcam.export.blender_focus import focus_table
    from physcam.optics.focusing import closest_focus
    from physcam.optics.paraxial import gaussian

    lens = load_lens("laikin_zoom_15_150mm")
    g = gaussian(lens)
    assert 4 * g.efl + g.z_rear_principal_plane - g.z_front_principal_plane < 260.0 < lens.total_track
    ft = focus_table(lens, n_focus=3)
    st = focus(lens, float(ft.closest_mm))
    assert ft.closest_mm == pytest.approx(closest_focus(lens), rel=2e-6)
    assert st.object_distance_mm == pytest.approx(0.0, abs=0.01)
    assert ft.closest_mm == pytest.approx(st.back_focus_mm + lens.total_track, abs=0.01)
