"""No NaN or inf leaves any analysis (issue 8): every analysis, over the bundled lenses, with
random field angles, sensors, focus marks, film planes and wavelengths (extreme ones included),
either raises a PhysCamError with a sentence or returns a result whose every number is finite or
an explicit None ("undefined", "not covered")."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import PhysCamError
from physcam.lens.library import list_lenses, load_lens
from physcam.optics.state import as_designed, camera_state

SLUGS = [r.slug for r in list_lenses()]
pytestmark = pytest.mark.slow


def _all_finite(obj, where="result"):
    """Walk a result's to_dict() (and arrays): every number finite, None allowed."""
    if obj is None or isinstance(obj, (str, bool)):
        return
    if isinstance(obj, dict):
        for k, v in obj.items():
            _all_finite(v, f"{where}.{k}")
    elif isinstance(obj, (list, tuple)):
        for i, v in enumerate(obj):
            _all_finite(v, f"{where}[{i}]")
    elif isinstance(obj, np.ndarray):
        assert np.isfinite(obj).all(), f"{where}: non-finite array values"
    elif isinstance(obj, (int, float, np.floating, np.integer)):
        assert math.isfinite(float(obj)), f"{where} = {obj}"


def _check(fn):
    try:
        res = fn()
    except PhysCamError as exc:
        assert str(exc), "an error without a sentence"
        return
    d = res.to_dict() if hasattr(res, "to_dict") else res
    _all_finite(d)
    json.dumps(d, allow_nan=False, default=lambda o: None)
    for name in ("image", "x_mm", "y_mm"):
        arr = getattr(res, name, None)
        if isinstance(arr, np.ndarray):
            _all_finite(arr, name)


FIELDS = st.one_of(st.floats(-89.0, 89.0), st.sampled_from([0.0, 1e-12, 45.0, 75.0, 88.99, -60.0]))
SIZES = st.one_of(st.floats(0.5, 80.0), st.sampled_from([0.5, 36.0, 1000.0]))
MARKS = st.one_of(st.floats(50.0, 1e7), st.sampled_from([math.inf, 1e9, 100.0]))
WAVES = st.one_of(st.none(), st.floats(380.0, 780.0), st.sampled_from([300.0, 1100.0]))


@settings(max_examples=40, database=None)
@given(slug=st.sampled_from(SLUGS), field=FIELDS, wl=WAVES, clip=st.booleans(),
       film_dz=st.one_of(st.none(), st.floats(-20.0, 20.0)))
def test_spot_and_field_limit(slug, field, wl, clip, film_dz):
    from physcam.analysis.image_quality.spot import spot_diagram
    from physcam.trace import paraxial_image_z

    lens = load_lens(slug)
    film_z = None
    if film_dz is not None:
        try:
            film_z = paraxial_image_z(lens) + film_dz
        except PhysCamError:
            return
    _check(lambda: spot_diagram(as_designed(lens) if film_z is None else camera_state(lens, film_z=film_z), [field],
                                wavelength_nm=wl, rings=8, refine=2, clip=clip))


@settings(max_examples=30, database=None)
@given(slug=st.sampled_from(SLUGS), w=SIZES, h=SIZES, mark=MARKS)
def test_field_of_view_and_breathing(slug, w, h, mark):
    from physcam.analysis.framing.breathing_real import real_breathing
    from physcam.analysis.framing.field_of_view import real_field_of_view

    lens = load_lens(slug)
    _check(lambda: real_field_of_view(lens, w, h, focus_mm=mark))
    _check(lambda: real_breathing(lens, [mark], sensor_width_mm=w, sensor_height_mm=h))


@settings(max_examples=25, database=None)
@given(slug=st.sampled_from(SLUGS), w=SIZES, h=SIZES, top=st.one_of(st.none(), st.floats(0.1, 88.9)))
def test_distortion_illumination_colour(slug, w, h, top):
    from physcam.analysis.image_quality.colour import chromatic_aberration
    from physcam.analysis.distortion.field import real_distortion
    from physcam.analysis.image_quality.illumination import relative_illumination

    lens = load_lens(slug)
    _check(lambda: real_distortion(lens, sensor_width_mm=w, sensor_height_mm=h, n_fields=5))
    _check(lambda: relative_illumination(as_designed(lens, sensor_mm=(w, h)), max_field_deg=top, n_fields=3, grid=24))
    _check(lambda: chromatic_aberration(as_designed(lens, sensor_mm=(w, h)), max_field_deg=top, n_fields=3))


@settings(max_examples=15, database=None)
@given(slug=st.sampled_from(SLUGS), depth=st.one_of(st.floats(10.0, 1e6), st.sampled_from([1e9, 1.0])),
       x=st.floats(-50.0, 50.0), spectral=st.booleans(), field=FIELDS)
def test_bokeh_and_ghosts(slug, depth, x, spectral, field):
    from physcam.analysis.defocus.bokeh import bokeh_image
    from physcam.analysis.image_quality.ghosts import ghost_analysis

    lens = load_lens(slug)
    _check(lambda: bokeh_image(lens, depth, x, 0.0, rays=2000, pixels=16, chunk=1000, spectral=spectral))
    _check(lambda: ghost_analysis(lens, field, rank_rays=200, image_rays=0))
