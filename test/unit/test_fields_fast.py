"""extract's cached attribute getters (issue 17) read what the checked walk reads."""
import pytest

from rubass.engine import UNKNOWN
from rubass.engine.fields import FieldError, extract
from rubass.lang.ast import Slice


class V:
    __slots__ = ("x", "y")

    def __init__(self, x, y=0):
        self.x, self.y = x, y


class M:
    __slots__ = ("v", "arr", "flag")

    def __init__(self, x, arr=(1.0, 2.0), flag=True):
        self.v, self.arr, self.flag = V(x), arr, flag


def test_each_message_gives_its_own_value_after_the_first_read():
    assert [extract(M(x), ("v", "x")) for x in (1, 2.5, float("nan"))][:2] == [1.0, 2.5]
    assert extract(M(float("nan")), ("v", "x")) is UNKNOWN
    assert extract(M(3), ("flag",)) is True and extract(M(3, flag=False), ("flag",)) is False


def test_missing_fields_and_other_shapes_still_fail_or_read_as_before():
    extract(M(1), ("v", "x"))
    with pytest.raises(FieldError, match="no field 'v.z'"):
        extract(M(1), ("v", "z"))
    with pytest.raises(FieldError, match="not a value"):
        extract(M(1), ("v",))
    odd = M(1)
    odd.v = {"x": 4}  # a dict where the first message had a message: the checked walk reads it
    assert extract(odd, ("v", "x")) == 4.0
    assert extract({"v": {"x": 5}}, ("v", "x")) == 5.0


def test_array_terms_and_missing_elements_are_returned_as_they_are():
    assert extract(M(1, arr=(1.0, 2.0, 3.0)), ("arr", Slice(0, 2))) == (1.0, 2.0)
    assert extract(M(1, arr=(V(1), V(2))), ("arr", Slice(None, None)))[1].x == 2  # elements stay messages
    assert extract(M(1, arr=(1.0,)), ("arr", 3)) is UNKNOWN
