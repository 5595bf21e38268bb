"""One iris for one lens (trust review, issue 24 item 2).

The f-stop sizes the iris once, with the lens focused at infinity (EFL over entrance-pupil diameter,
ISO 517), and the iris keeps that size at every focus. Before the fix an internal-focus lens got its
stop from two lens states: zuiko_18mm_f3_5 at 0.45 m, f/4 wrote 8.205 mm into pbrt and 8.280 mm into the
Blender OSL camera (9.8 % apart on navarro_anamorphic_2x at close focus).
"""

from __future__ import annotations

import dataclasses
import math
from contextlib import nullcontext

import pytest

from physcam.errors import PhysCamWarning
from physcam.lens.library import load_lens
from physcam.onset.report import solve_lens_report
from physcam.optics.sensors import find_sensor
from physcam.optics.state import camera_state
from physcam.optics import focusing, paraxial

CASES = [("zuiko_18mm_f3_5", 450.0), ("navarro_anamorphic_2x", 1250.0), ("dgauss_50mm", 600.0)]
N = 4.0


def _with_stop(p, semi):
    s = list(p.surfaces)
    s[p.stop_index] = dataclasses.replace(s[p.stop_index], semi_diameter=semi)
    return p.with_surfaces(s)


@pytest.mark.parametrize("name, mark", CASES)
def test_the_iris_makes_the_lens_f_n_at_infinity_and_keeps_its_size_when_it_focuses(name, mark):
    lens = load_lens(name)
    iris = focusing.iris_semi_diameter(lens, N)
    at_inf = focusing.focus(lens, math.inf).prescription
    # the definition, checked through the Gaussian engine of the stopped lens: EFL / EPD = N at infinity
    assert paraxial.gaussian(_with_stop(at_inf, iris)).f_number == pytest.approx(N, rel=1e-12)
    # the same iris whichever focused state of the lens it is asked of
    assert focusing.iris_semi_diameter(focusing.focus(lens, mark).prescription, N) == pytest.approx(iris, rel=1e-12)


@pytest.mark.parametrize("name, mark", CASES)
def test_every_consumer_writes_the_same_iris(name, mark):
    from physcam.analysis.image_quality._pupil import setup
    from physcam.export.blender import bake_camera
    from physcam.export.pbrt import pbrt_camera_values

    lens = load_lens(name)
    sensor = find_sensor("Super 35")
    iris = 2.0 * focusing.iris_semi_diameter(lens, N)
    # the Zuiko 18 mm's strong distortion: the report says its render camera is no pinhole (PhysCamWarning)
    strong = pytest.warns(PhysCamWarning, match="is not a pinhole") if name == "zuiko_18mm_f3_5" else nullcontext()
    with strong:
        report = solve_lens_report(focal_length_mm=None, lens=lens, sensor=sensor, fstop=N, focus_mm=mark)
    baked = bake_camera(camera_state(lens, focus_mm=mark, fstop=N, sensor_mm=(sensor.width_mm, sensor.height_mm)))
    written = {
        "Blender OSL": 2.0 * baked.lens.surfaces[baked.lens.stop_index].semi_diameter,
        "analyses (MTF, PSF)": 2.0 * setup(camera_state(lens, fstop=N, focus_mm=mark)).stop_semi_diameter,
    }
    if not lens.is_anamorphic:  # pbrt's realistic camera takes spherical lenses only
        written["pbrt realistic"] = pbrt_camera_values(report, lens, cameras=("realistic",))["realistic"]["aperturediameter"]
    for who, d in written.items():
        assert d == pytest.approx(iris, rel=1e-12), who
    # the report's entrance pupil at this focus is that iris seen through the focused lens's front group
    st = focusing.focus(lens, mark)
    g = paraxial.gaussian(_with_stop(st.prescription, iris / 2.0), object_z=st.object_z, film_z=st.film_z)
    assert report.aperture_diameter_mm == pytest.approx(g.entrance_pupil_diameter, rel=1e-9)
    assert report.f_number_at_focus == pytest.approx(g.efl / g.entrance_pupil_diameter, rel=1e-9)


def test_unit_focusing_keeps_the_f_number():
    """A lens that moves whole keeps its EFL and pupils: the f-number at any focus is the f-stop."""
    lens = load_lens("dgauss_50mm")
    assert focusing.f_number_ratio(lens, 600.0) == pytest.approx(1.0, abs=1e-12)
    r = solve_lens_report(focal_length_mm=None, lens=lens, sensor=find_sensor("Super 35"), fstop=N, focus_mm=600.0)
    assert r.fstop_at_focus is None and r.f_number_at_focus == N


def test_the_usd_iris_round_trips(tmp_path):
    """The PhysicalCamera's lens iris is the entrance pupil at the focus; reading it back keeps the f-number
    at the focus, so the depth of field read from the file is the one written."""
    from physcam.usd.author import author_camera, new_stage, spec_from_report
    from physcam.usd.read import open_stage, read_camera

    lens = load_lens("navarro_anamorphic_2x")
    r = solve_lens_report(focal_length_mm=None, lens=lens, sensor=find_sensor("Super 35"), fstop=N, focus_mm=1250.0)
    assert r.f_number_at_focus < 0.95 * N  # this lens's close focus changes its f-number by about 10 %
    stage = new_stage()
    author_camera(stage, "/Cam", spec_from_report(r), report=r)
    path = tmp_path / "cam.usda"
    stage.GetRootLayer().Export(str(path))
    back = read_camera(open_stage(path), "/Cam").report()
    assert back.f_number_at_focus == pytest.approx(r.f_number_at_focus, rel=1e-5)
    assert back.dof.near_from_film_mm == pytest.approx(r.dof.near_from_film_mm, rel=1e-4)
