"""How far a renderer's thin-lens camera is from the real lens (trust review, issue 24 item 5).

The review measured the Zuiko 18 mm at f/4 against a thin-lens render: field of view -3.95 %, bokeh
+61 to +77 % at 0.3 m. Every thin-lens output (Blender --builtin, RIB, Mitsuba, USD) must say so.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import warnings

import pytest

from physcam.onset.thin_lens_gap import thin_lens_gap
from physcam.lens.library import load_lens
from physcam.onset.report import solve_lens_report
from physcam.optics.sensors import find_sensor

S35 = find_sensor("Super 35")


def _report(name, mark, n):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return solve_lens_report(focal_length_mm=None, lens=load_lens(name), sensor=S35, fstop=n, focus_mm=mark)


def test_the_thin_lens_blur_is_the_renderers_formula():
    """A |1/d - 1/s| f_pin with d, s from the entrance pupil (Blender manual, "Depth of Field"; RenderMan's
    PxrCamera): worked from the report's numbers for dgauss_50mm at 2 m, f/2.8 and a light 1 m from the film."""
    r = _report("dgauss_50mm", 2000.0, 2.8)
    gap = thin_lens_gap(r)
    light, thin, real, pct = gap.bokeh[0]
    assert light == 1000.0
    p = r.entrance_pupil_from_film_mm
    a = r.focal_length_mm / r.f_number_at_focus
    assert thin == pytest.approx(a * r.pinhole[0] * abs(1 / (1000.0 - p) - 1 / (2000.0 - p)), rel=1e-12)
    assert pct == pytest.approx((thin - real) / real * 100.0, rel=1e-12)


def test_a_well_corrected_lens_stopped_down_is_close_to_its_thin_lens():
    """dgauss_50mm at f/8: small aberrations, little distortion, so the thin lens is within a few percent."""
    gap = thin_lens_gap(_report("dgauss_50mm", 2000.0, 8.0))
    assert abs(gap.hfov_difference_pct) < 1.0
    assert len(gap.bokeh) == 2 and all(abs(row[3]) < 4.0 for row in gap.bokeh)


def test_the_wide_angle_at_close_focus_is_far_from_its_thin_lens():
    """The review's case: Zuiko 18 mm at f/4, 0.45 m. The thin lens frames narrower (distortion) and its blur
    is wrong by tens of percent (aberrations at a working aperture)."""
    gap = thin_lens_gap(_report("zuiko_18mm_f3_5", 450.0, 4.0))
    assert gap.hfov_difference_pct < -3.0
    assert max(abs(row[3]) for row in gap.bokeh) > 30.0
    assert "not Zuiko 18mm f/3.5 at f/4" in gap.summary()


def _physcam(*args, cwd):
    return subprocess.run([sys.executable, "-m", "physcam", *args], capture_output=True, text=True, cwd=cwd)


@pytest.mark.slow
def test_every_thin_lens_output_says_how_far_it_is_from_the_lens(tmp_path):
    lens = ["--lens", "zuiko_18mm_f3_5", "--fstop", "4", "--focus", "0.45m"]
    words = "a thin-lens camera is not Zuiko 18mm f/3.5 at f/4"
    rib = _physcam("export", "rib", "-o", "cam.rib", *lens, cwd=tmp_path)
    assert rib.returncode == 0 and words in (tmp_path / "cam.rib").read_text() and words in rib.stdout
    mi = _physcam("export", "mitsuba", "-o", "mi", *lens, "--json", cwd=tmp_path)
    assert json.loads(mi.stdout)["thin_lens_gap"]["hfov_difference_pct"] < -3.0
    bl = _physcam("export", "blender", "zuiko_18mm_f3_5", "--focus", "0.45m", "--fstop", "4", "--builtin", "-o", "bl",
                  cwd=tmp_path)
    assert bl.returncode == 0 and words in (tmp_path / "bl" / "builtin_zuiko_18mm_f3_5.py").read_text()
    usd = _physcam("usd", "write", "cam.usda", *lens, "--json", cwd=tmp_path)
    assert json.loads(usd.stdout)["thin_lens_gap"]["bokeh"]
    from pxr import Usd

    stage = Usd.Stage.Open(str(tmp_path / "cam.usda"))
    gap = stage.GetPrimAtPath("/Cameras/Camera/Camera").GetCustomDataByKey("physcam:thinLensGap")
    assert gap["hfov_difference_pct"] < -3.0 and math.isfinite(gap["bokeh"]["0"]["difference_pct"])
