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
