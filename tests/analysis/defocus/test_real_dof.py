"""Depth of field from real rays (issue 27 item 4) against independent computations."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from physcam.analysis.defocus.bokeh import bokeh_image
from physcam.analysis.defocus.real_dof import blur_diameter_mm, real_depth_of_field
from physcam.lens.library import load_lens
from physcam.onset.report import solve_lens_report
from physcam.optics.sensors import find_sensor
from physcam.optics import focusing
from physcam.optics.state import camera_state

from _image_quality import perfect_lens

S35 = find_sensor("Super 35")


def _brute_force_blur(lens, mark, fstop, light_mm, fraction=None, film_shift=0.0):
    """The blur of an on-axis light from physcam's bokeh tracer (Owen-scrambled Sobol rays over the front
    element, a histogram on the film; nothing shared with the real-DOF code but the tracer): the
    second-moment diameter sqrt(8 E[r^2]), or the diameter holding ``fraction`` of the light."""
    st = focusing.focus(lens, mark)
    cam = camera_state(st.prescription, film_z=st.film_z + film_shift,
                       stop_semi_diameter=focusing.iris_semi_diameter(lens, fstop))
    img = bokeh_image(cam, light_mm, rays=400_000, pixels=512, fresnel=False)
    a = img.image.sum(axis=2)
    x0, x1, y0, y1 = img.extent_mm
    ys, xs = np.indices(a.shape)
    X = x0 + (xs + 0.5) * (x1 - x0) / a.shape[1]
    Y = y0 + (ys + 0.5) * (y1 - y0) / a.shape[0]
    t = a.sum()
    cx, cy = (a * X).sum() / t, (a * Y).sum() / t
    r = np.hypot(X - cx, Y - cy).ravel()
    if fraction is None:
        return math.sqrt(8.0 * (a.ravel() * r * r).sum() / t)
    order = np.argsort(r)
    cum = np.cumsum(a.ravel()[order]) / t
    return 2.0 * float(r[order][np.searchsorted(cum, fraction)])


@pytest.mark.slow
@pytest.mark.parametrize("measure, fraction", [("moment", None), ("energy", 0.8)])
def test_at_the_real_limits_the_traced_blur_is_the_coc(measure, fraction):
    """dgauss_50mm at f/2.8 focused at 3 m: at the near and far limits found, an independent trace of the
    light's blur measures the CoC (within 3 %: the histogram's pixels and the two samplers)."""
    lens = load_lens("dgauss_50mm")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = solve_lens_report(focal_length_mm=None, lens=lens, sensor=S35, fstop=2.8, focus_mm=3000.0)
    d = real_depth_of_field(camera_state(lens, focus_mm=3000.0, fstop=2.8), coc_mm=r.coc_mm, measure=measure,
                            energy_fraction=fraction or 0.8)
    assert d.near_from_film_mm < d.sharpest_from_film_mm < d.far_from_film_mm
    for limit in (d.near_from_film_mm, d.far_from_film_mm):  # the film where the collimated lens has it
        assert _brute_force_blur(lens, 3000.0, 2.8, limit, fraction, d.film_shift_mm) == pytest.approx(r.coc_mm,
                                                                                                      rel=0.03)
    # the blur at the sharpest distance is below the CoC, and the same by both computations
    assert d.sharpest_blur_mm < r.coc_mm
    assert blur_diameter_mm(camera_state(lens, focus_mm=3000.0, fstop=2.8), d.near_from_film_mm, measure=measure,
                            energy_fraction=fraction or 0.8, film_shift_mm=d.film_shift_mm,
                            grid=d.pupil_grid) == pytest.approx(r.coc_mm, rel=1e-3)


def test_a_nearly_perfect_slow_lens_has_the_models_depth_of_field():
    """The stigmatic singlet at f/22 focused at 2 m: its blur is the thin lens's disk, so its real limits
    (second-moment diameter, which is c for a uniform disk of diameter c) are the model's within 1 %."""
    lens = perfect_lens()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = solve_lens_report(focal_length_mm=None, lens=lens, sensor=find_sensor("FF"), fstop=22.0, focus_mm=2000.0,
                              coc=0.03)
    d = real_depth_of_field(camera_state(lens, focus_mm=2000.0, fstop=22.0), coc_mm=0.03, measure="moment")
    assert d.near_from_film_mm == pytest.approx(r.dof.near_from_film_mm, rel=0.01)
    assert d.far_from_film_mm == pytest.approx(r.dof.far_from_film_mm, rel=0.01)


def test_a_blur_larger_than_the_coc_everywhere_is_said_plainly():
    from physcam.errors import OpticsError

    with pytest.raises(OpticsError, match="no depth of field"):
        real_depth_of_field(camera_state(load_lens("dgauss_50mm"), focus_mm=3000.0, fstop=2.8), coc_mm=0.001)
