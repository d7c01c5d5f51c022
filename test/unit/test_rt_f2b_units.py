"""unit_suggestion suggests only a unit of the unit's own dimension (F2b review item 4)."""
import pytest

from rubass.lang.units import unit_suggestion


@pytest.mark.parametrize("unit", [
    "s^2/m",    # was 'm/s^2': the inverse dimension
    "m/sec^0",  # was 'm': a zeroth power means no unit
    "s2/m",     # the top part is a time: never 'm/s^2'
    "Hz^2",     # was 'Hz'
    "m/s/s",    # was 'm/s', a speed
    "s^-1",
])
def test_no_unit_of_another_dimension_is_suggested(unit):
    assert unit_suggestion(unit) == ""


@pytest.mark.parametrize("unit,said", [
    ("m/sec", "; did you mean 'm/s'?"),
    ("m/s2", "; did you mean 'm/s^2'?"),
    ("m/s^1", "; did you mean 'm/s'?"),
    ("rad/sec^2", "; did you mean 'rad/s^2'?"),
    ("m/ss", "; did you mean 'm/s'?"),
])
def test_a_unit_of_the_same_dimension_is_still_suggested(unit, said):
    assert unit_suggestion(unit) == said
