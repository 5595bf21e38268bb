"""The argument checks every public function uses: one bounded line for any value, never a crash."""

import pytest

from physcam.errors import InputError, WrongTypeError, require_finite, require_positive, require_type


@pytest.mark.parametrize("check", [require_finite, require_positive])
def test_a_5000_digit_integer_is_one_bounded_line(check):
    # float(10**5000) raises OverflowError and repr() of it raises ValueError in Python 3.11+
    with pytest.raises(InputError, match="finite number, got an integer of about 5001 digits") as err:
        check("focus distance", 10**5000)
    assert len(str(err.value)) < 120


def test_a_wrong_type_holding_a_huge_integer_is_named_briefly():
    with pytest.raises(WrongTypeError) as err:
        require_type("lens", 10**5000, str)
    assert "an integer of about 5001 digits" in str(err.value) and len(str(err.value)) < 120
    with pytest.raises(WrongTypeError) as err:
        require_type("lens", "x" * 10_000, int)
    assert len(str(err.value)) < 160
