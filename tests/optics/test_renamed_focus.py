"""One name per concept (issue 28): the focus mark is ``focus_mm`` everywhere; the old keyword
``focus_from_film_mm`` still works for one version, with a DeprecationWarning."""

import math

import pytest

from physcam.errors import InputError
from physcam.lens.library import load_lens
from physcam.optics.focusing import focus, gaussian_at_focus


def test_the_old_keyword_gives_the_same_focus_with_a_deprecation_warning():
    lens = load_lens("dgauss_50mm")
    with pytest.warns(DeprecationWarning, match="focus_mm"):
        old = focus(lens, focus_from_film_mm=2000.0)
    new = focus(lens, focus_mm=2000.0)
    assert old.film_z == new.film_z and old.object_z == new.object_z
    # a 2 m mark is 2 m from the film: the object sits 2000 mm in front of the film plane
    assert new.film_z - new.object_z == pytest.approx(2000.0, abs=1e-9)


def test_both_names_at_once_is_an_error_naming_the_new_one():
    lens = load_lens("dgauss_50mm")
    with pytest.raises(InputError, match="give focus_mm"):
        gaussian_at_focus(lens, focus_mm=math.inf, focus_from_film_mm=3000.0)


def test_the_warning_points_at_the_callers_line_for_every_renamed_function():
    # found in review: under @takes_prescription the warning pointed into physcam, where Python's
    # default filters hide a DeprecationWarning
    import warnings

    from physcam.analysis.lens_cards.diagram import lens_diagram
    from physcam.analysis.framing.field_of_view import real_field_of_view
    from physcam.errors import WrongTypeError
    from physcam.export.opencv_distortion import fit_opencv_pinhole
    from physcam.export.pbrt import pbrt_thick_lens
    from physcam.live.lens_data import distortion_for_sample, focus_for_consumer
    from physcam.optics.focusing import f_number_ratio, pupil_aspect, technical_planes

    lens = load_lens("dgauss_50mm")
    calls = [lambda: focus(lens, focus_from_film_mm=2000.0),
             lambda: gaussian_at_focus(lens, focus_from_film_mm=2000.0),
             lambda: f_number_ratio(lens, focus_from_film_mm=2000.0),
             lambda: technical_planes(lens, focus_from_film_mm=2000.0),
             lambda: pupil_aspect(lens, focus_from_film_mm=2000.0),
             lambda: real_field_of_view(lens, 36.0, 24.0, focus_from_film_mm=2000.0),
             lambda: lens_diagram(lens, focus_from_film_mm=2000.0),
             lambda: pbrt_thick_lens(lens, focus_from_film_mm=2000.0),
             lambda: fit_opencv_pinhole(lens, 36.0, 24.0, 96, 64, focus_from_film_mm=2000.0),
             lambda: focus_for_consumer(focus_from_film_mm=2000.0, entrance_pupil_mm=60.0),
             lambda: distortion_for_sample(lens, 36.0, 24.0, focus_from_film_mm=2000.0, image_size=(96, None))]
    for call in calls:
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            call()
        deprecations = [w for w in seen if issubclass(w.category, DeprecationWarning)]
        assert len(deprecations) == 1 and deprecations[0].filename == __file__, [(w.filename, str(w.message))
                                                                                  for w in deprecations]
    # the type check still names the function's own first parameter
    with pytest.raises(WrongTypeError, match="^prescription must be"):
        focus("not a lens", 1000.0)
    with pytest.raises(WrongTypeError, match="^lens must be"):
        real_field_of_view(lens=None, sensor_width_mm=36.0, sensor_height_mm=24.0)
