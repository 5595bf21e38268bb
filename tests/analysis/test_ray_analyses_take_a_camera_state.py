"""The ray analyses (spot, bokeh, relative illumination, colour, ghosts) take a CameraState first
(issue 28): the state gives the same result as the equivalent lens with its focus and stop spelled
out the old way (focusing.focus for the focused lens and film plane, focusing.iris_semi_diameter for
the iris: the functions the state is made of, called here by hand); a state together with a focus,
film plane, stop or sensor of its own is an InputError; anything else first is a WrongTypeError.

Closed form for the finite-focus spot: a small field's centroid lies at the paraxial image of the
object point, y' = m y with m the Gaussian magnification and y = -tan(theta) (z_ep - z_object)
(the object seen under theta from the entrance pupil).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from physcam.analysis.defocus.bokeh import bokeh_image
from physcam.analysis.image_quality.colour import chromatic_aberration
from physcam.analysis.image_quality.ghosts import ghost_analysis, trace_ghost
from physcam.analysis.image_quality.illumination import relative_illumination
from physcam.analysis.image_quality.spot import spot_diagram
from physcam.errors import InputError, WrongTypeError
from physcam.lens.library import load_lens
from physcam.optics import focusing
from physcam.optics.state import camera_state
from physcam.trace.aperture import Aperture

DGAUSS = load_lens("dgauss_50mm")
SONNAR = load_lens("sonnar_50mm_f1_5")  # dispersive glass: colour is not zero
SPOT = dict(rings=12, refine=2)


def _by_hand(lens, mark, fstop):
    """(focused lens, film z, iris semi-diameter) the old way, without a CameraState."""
    st = focusing.focus(lens, mark)
    return st.prescription, st.film_z, focusing.iris_semi_diameter(lens, fstop)


def _old_door():
    """The lens with its keywords, the pre-issue-43 form: it warns until physcam 0.3."""
    return pytest.warns(DeprecationWarning, match=r"is now \w+\((camera_state|as_designed)\(lens, .*physcam 0\.3")


def _rms(res):
    return [f.rms_radius_um for f in res.fields]


def test_spot_from_a_state_is_the_spot_of_its_lens_stop_and_film():
    s = camera_state(DGAUSS, fstop=4.0)
    a = spot_diagram(s, (0.0, 5.0), **SPOT)
    _, film, iris = _by_hand(DGAUSS, math.inf, 4.0)
    with _old_door():
        b = spot_diagram(DGAUSS, (0.0, 5.0), fstop=4.0, film_z=film, **SPOT)
    assert _rms(a) == pytest.approx(_rms(b), rel=1e-9)
    assert s.stop_semi_diameter == iris
    assert a.film_z_mm == pytest.approx(film, abs=1e-9)


def test_a_focused_state_images_its_object_point_where_the_paraxial_optics_put_it():
    s = camera_state(DGAUSS, focus_mm=1000.0, fstop=4.0)
    theta = 1.0
    res = spot_diagram(s, (0.0, theta), **SPOT)
    y_obj = -math.tan(math.radians(theta)) * (s.entrance_pupil_z - s.object_z)
    assert res.fields[1].centroid_y_mm == pytest.approx(s.gaussian.magnification * y_obj, rel=2e-3)
    # in focus: as sharp as the lens at infinity, far sharper than light from infinity on that film
    sharp = spot_diagram(camera_state(DGAUSS, fstop=4.0), (0.0,), **SPOT).fields[0].rms_radius_um
    with _old_door():
        blurred = spot_diagram(s.focused, (0.0,), film_z=s.film_z, fstop=4.0, **SPOT).fields[0].rms_radius_um
    assert res.fields[0].rms_radius_um < 2 * sharp < blurred / 10


def test_bokeh_from_a_state_is_the_bokeh_of_the_lens_focused_and_stopped_by_hand():
    hexagon = Aperture(nsides=6, roundness=0.1)
    s = camera_state(DGAUSS, focus_mm=2000.0, fstop=4.0, aperture=hexagon)
    a = bokeh_image(s, 1000.0, 2.0, 1.0, rays=20_000, pixels=32)
    lens, film, iris = _by_hand(DGAUSS, 2000.0, 4.0)
    # the hexagon has the round iris's area (docs/conventions.md): its corners at iris x equal_area_scale
    # (f/4 is far inside the widest iris, so no clamp); the ray-level form draws inside the radius given
    corner = iris * hexagon.equal_area_scale()
    with _old_door():
        b = bokeh_image(lens, 1000.0, 2.0, 1.0, film_z=film, stop_semi_diameter=corner, aperture=hexagon, rays=20_000,
                        pixels=32)
    assert np.array_equal(a.image, b.image) and a.extent_mm == b.extent_mm and a.rays_passed == b.rays_passed


def test_illumination_from_a_state_uses_its_iris_and_sensor():
    s = camera_state(DGAUSS, fstop=4.0, sensor_mm=(36.0, 24.0))
    a = relative_illumination(s, n_fields=4, grid=32)
    _, film, iris = _by_hand(DGAUSS, math.inf, 4.0)
    with _old_door():
        b = relative_illumination(DGAUSS, n_fields=4, grid=32, stop_semi_diameter=iris, film_z=film,
                                  sensor_width_mm=36.0, sensor_height_mm=24.0)
    assert [p.field_deg for p in a.points] == [p.field_deg for p in b.points]  # to the 36 x 24 corner
    assert [p.relative_illumination for p in a.points] == pytest.approx([p.relative_illumination for p in b.points],
                                                                        rel=1e-9)


def test_colour_from_a_state_is_the_colour_of_its_lens_on_its_film():
    s = camera_state(SONNAR, focus_mm=3000.0)
    a = chromatic_aberration(s, [0.0, 8.0])
    lens, film, _ = _by_hand(SONNAR, 3000.0, 2.0)
    with _old_door():
        b = chromatic_aberration(lens, [0.0, 8.0], film_z=film)
    assert a.longitudinal_real_mm != 0.0
    assert a.to_dict() == b.to_dict()


def test_ghosts_from_a_state_are_the_ghosts_of_its_lens_stop_and_film():
    s = camera_state(DGAUSS, focus_mm=2000.0, fstop=2.8)
    a = ghost_analysis(s, 5.0, rank_rays=400)
    lens, film, iris = _by_hand(DGAUSS, 2000.0, 2.8)
    with _old_door():
        b = ghost_analysis(lens, 5.0, rank_rays=400, film_z=film, stop_semi_diameter=iris)
    assert [(p.i, p.j) for p in a.paths] == [(p.i, p.j) for p in b.paths]
    assert [p.relative_flux for p in a.paths] == pytest.approx([p.relative_flux for p in b.paths], rel=1e-12)
    assert a.film_z_mm == b.film_z_mm


@pytest.mark.parametrize("call", [
    lambda s: spot_diagram(s, fstop=4.0),
    lambda s: spot_diagram(s, film_z=60.0),
    lambda s: bokeh_image(s, 1000.0, stop_semi_diameter=5.0),
    lambda s: bokeh_image(s, 1000.0, film_z=60.0),
    lambda s: relative_illumination(s, stop_semi_diameter=5.0),
    lambda s: relative_illumination(s, sensor_width_mm=36.0, sensor_height_mm=24.0),
    lambda s: chromatic_aberration(s, film_z=60.0),
    lambda s: chromatic_aberration(s, sensor_width_mm=36.0, sensor_height_mm=24.0),
    lambda s: ghost_analysis(s, film_z=60.0),
    lambda s: ghost_analysis(s, stop_semi_diameter=5.0),
])
def test_a_state_with_a_focus_stop_or_sensor_of_its_own_is_an_input_error(call):
    with pytest.raises(InputError, match="CameraState carries its own"):
        call(camera_state(DGAUSS, fstop=4.0, sensor_mm=(24.89, 18.66)))


def test_ghosts_refuse_a_shaped_iris():
    with pytest.raises(InputError, match="round iris"):
        ghost_analysis(camera_state(DGAUSS, aperture=Aperture(nsides=6)), rank_rays=400)


@pytest.mark.parametrize("fn, args", [(spot_diagram, ()), (bokeh_image, (1000.0,)), (relative_illumination, ()),
                                      (chromatic_aberration, ()), (ghost_analysis, ()), (trace_ghost, (None, 1, 0))])
@pytest.mark.parametrize("bad", ["dgauss_50mm", 50.0, None])
def test_anything_but_a_state_or_a_lens_first_is_a_wrong_type_error(fn, args, bad):
    with pytest.raises(WrongTypeError, match="CameraState"):
        fn(bad, *args)


def test_one_ghost_path_traced_from_a_state_is_the_path_of_its_lens_stop_and_film():
    from physcam.analysis.image_quality.ghosts import _beam

    s = camera_state(DGAUSS, focus_mm=2000.0, fstop=2.8)
    lens, film, iris = _by_hand(DGAUSS, 2000.0, 2.8)
    rays = _beam(lens, 5.0, DGAUSS.wavelength_nm, 400)
    a = trace_ghost(s, rays, 10, 6)
    b = trace_ghost(lens, rays, 10, 6, film, stop_semi_diameter=iris)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y) and np.array_equal(a.weight, b.weight)
    with pytest.raises(InputError, match="CameraState carries its own"):
        trace_ghost(s, rays, 10, 6, film)
    with pytest.raises(InputError, match="film plane"):
        trace_ghost(lens, rays, 10, 6)
