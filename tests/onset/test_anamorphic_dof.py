"""Anamorphic depth of field (trust review, issue 24 item 1).

A defocused point is ``dof_aspect`` as wide as tall in the desqueezed picture (the entrance
pupil's X over Y diameter), so the horizontal limits are where the vertical blur reaches
c / dof_aspect: deeper than the vertical for a front anamorphic (pupil narrowed in X), the same
for a rear anamorphic (round pupil). Before the fix the horizontal limits took c / squeeze and
were shallower for every anamorphic.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from physcam.lens.library import load_lens
from physcam.onset.report import solve_lens_report
from physcam.optics.sensors import find_sensor
from physcam.optics import focusing

ALEXA35 = find_sensor("ALEXA 35")


def _thin_lens_limits(f, n, c, s):
    """Exact thin-lens DOF limits from H1 (Ray, *Applied Photographic Optics*, 3rd ed., 6.4), by hand."""
    h = f * f / (n * c)
    near = s * h / (h + (s - f))
    far = s * h / (h - (s - f)) if h > s - f else math.inf
    return near, far


def test_thin_lens_with_a_squeeze_is_a_front_anamorphic_whose_horizontal_dof_is_deeper():
    f, n, c, sq = 50.0, 2.8, 0.025, 2.0
    r = solve_lens_report(focal_length_mm=f, sensor=ALEXA35, fstop=n, focus_mm=3048.0, squeeze=sq, coc=c)
    assert r.dof_aspect == pytest.approx(1.0 / sq)
    assert r.dof_horizontal.coc_mm == pytest.approx(c * sq)  # c / (1 / squeeze)
    near, far = _thin_lens_limits(f, n, c * sq, r.object_distance_mm)
    assert r.dof_horizontal.near_mm == pytest.approx(near, rel=1e-9)
    assert r.dof_horizontal.far_mm == pytest.approx(far, rel=1e-9)
    assert r.dof_horizontal.total_mm > 1.9 * r.dof.total_mm  # the review's case: was 224 mm against 450 mm


def test_the_cli_and_its_json_say_the_same():
    out = subprocess.run([sys.executable, "-m", "physcam", "report", "--focal", "50", "--fstop", "2.8", "--focus",
                          "10ft", "--sensor", "ALEXA 35", "--squeeze", "2", "--json"],
                         capture_output=True, text=True, check=True).stdout
    d = json.loads(out)
    assert d["dof_horizontal"]["total_mm"] > d["dof"]["total_mm"]


def _blur_widths(lens, mark, fstop, light_mm):
    """(width, height) of a point light's blur on the film, 4 sqrt(second moment) per axis (the full
    width of a uniform ellipse), traced through the real lens with the iris at ``fstop``."""
    from physcam.analysis.defocus.bokeh import bokeh_image
    from physcam.optics.state import camera_state

    st = focusing.focus(lens, mark)
    cam = camera_state(st.prescription, film_z=st.film_z, stop_semi_diameter=focusing.iris_semi_diameter(lens, fstop))
    img = bokeh_image(cam, light_mm, rays=100_000, pixels=192, fresnel=False)
    a = img.image.sum(axis=2)
    x0, x1, y0, y1 = img.extent_mm
    ys, xs = np.indices(a.shape)
    X = x0 + (xs + 0.5) * (x1 - x0) / a.shape[1]
    Y = y0 + (ys + 0.5) * (y1 - y0) / a.shape[0]
    t = a.sum()
    cx, cy = (a * X).sum() / t, (a * Y).sum() / t
    return 4 * math.sqrt((a * (X - cx) ** 2).sum() / t), 4 * math.sqrt((a * (Y - cy) ** 2).sum() / t)


@pytest.mark.slow
@pytest.mark.parametrize("name, aspect", [("neil_front_anamorphic_2x", 0.5), ("navarro_anamorphic_2x", 1.0)])
def test_real_anamorphic_blur_aspect_matches_the_traced_bokeh(name, aspect):
    """The report's blur aspect against the desqueezed width over height of a strongly defocused point
    traced through the prescription (near and far of the focus), within 10 %."""
    lens = load_lens(name)
    with pytest.warns(Warning):  # the ALEXA 35 open gate's corners lie outside these lenses' image circles
        r = solve_lens_report(focal_length_mm=None, lens=lens, sensor=ALEXA35, fstop=4.0, focus_mm=3000.0)
    assert r.dof_aspect == pytest.approx(aspect, abs=0.01)
    for light in (1200.0, 20000.0):
        w, h = _blur_widths(lens, 3000.0, 4.0, light)
        assert w * r.squeeze / h == pytest.approx(r.dof_aspect, rel=0.10)
    dh, dv = r.dof_horizontal, r.dof
    if aspect < 1:
        assert dh.near_from_film_mm < dv.near_from_film_mm and dh.far_from_film_mm > dv.far_from_film_mm
    else:  # a rear anamorphic's blur is round: the horizontal limits are the vertical ones
        assert dh.near_from_film_mm == pytest.approx(dv.near_from_film_mm, rel=1e-3)
        assert dh.far_from_film_mm == pytest.approx(dv.far_from_film_mm, rel=1e-3)
