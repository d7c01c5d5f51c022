"""Bad data in messages (issue #7): NaN and inf, huge arrays, NaN inside arrays, wrong types.
No exception; unknown where a value cannot be trusted."""
from rubass.engine import UNKNOWN
from rubass.engine.fields import convert

from test_engine_basics import engine

NAN, INF = float("nan"), float("inf")


def value_of(rule_body, msg):
    e = engine("entity a { rules: r: " + rule_body + "; }\nif (a.r) then { warn; }\n")
    e.on_message("/x", 1.0, msg)
    return e.rule_value("a.r")


def test_nan_is_unknown_inf_is_a_number_and_inf_minus_inf_is_unknown():
    assert value_of("topic /x.data > 1", {"data": NAN}) is UNKNOWN
    assert value_of("topic /x.data > 1", {"data": INF}) is True
    assert value_of("topic /x.data > 1", {"data": -INF}) is False
    assert value_of("topic /x.data - topic /x.data > 1", {"data": INF}) is UNKNOWN  # inf - inf is NaN
    assert value_of("topic /x.data * 0 < 1", {"data": INF}) is UNKNOWN  # inf * 0 is NaN
    assert value_of("sqrt(topic /x.data) > 1", {"data": -1.0}) is UNKNOWN


def test_array_functions_skip_nan_and_are_unknown_on_an_empty_or_all_nan_array():
    assert value_of("min(topic /x.ranges) < 0.5", {"ranges": [NAN, 0.4, INF]}) is True
    assert value_of("max(topic /x.ranges) > 5", {"ranges": [NAN, 0.4, INF]}) is True
    assert value_of("min(topic /x.ranges) < 0.5", {"ranges": [NAN, NAN]}) is UNKNOWN
    assert value_of("min(topic /x.ranges) < 0.5", {"ranges": []}) is UNKNOWN
    assert value_of("len(topic /x.ranges) == 0", {"ranges": []}) is True
    assert value_of("topic /x.ranges[5] > 0", {"ranges": [1.0]}) is UNKNOWN  # a short array
    assert value_of("topic /x.ranges[0] > 0", {"ranges": [NAN]}) is UNKNOWN


def test_uint8_arrays_stay_bytes_and_work():
    assert value_of("max(topic /x.data) > 200", {"data": bytes([1, 2, 250])}) is True
    assert value_of("len(topic /x.data) == 3", {"data": bytearray(b"abc")}) is True
    assert value_of("topic /x.data[1] == 98", {"data": b"abc"}) is True
    assert value_of("min(topic /x.data) > 0", {"data": b""}) is UNKNOWN


def test_a_field_of_the_wrong_type_is_unknown_not_an_error():
    assert value_of("topic /x.data > 1", {"data": "fast"}) is UNKNOWN
    assert value_of("topic /x.data > 1", {"data": True}) is UNKNOWN
    assert value_of("min(topic /x.data) > 1", {"data": 3.0}) is UNKNOWN
    assert value_of("min(topic /x.data) > 1", {"data": [True, False]}) is UNKNOWN  # bool is not a number


def test_a_huge_array_is_copied_as_it_is_not_converted_element_by_element():
    big = tuple(float(i % 1000) for i in range(1_000_000))
    out = convert(list(big))
    assert isinstance(out, tuple) and len(out) == len(big) and out[123] is big[123]  # the same objects
    assert convert(b"\x00" * 10_000_000) == b"\x00" * 10_000_000  # bytes stay bytes: no 10M floats
    e = engine("entity a { rules: r: len(topic /x.data) > 5 and max(topic /x.data) == 999; }\n"
               "if (a.r) then { warn; }\n")
    e.on_message("/x", 1.0, {"data": big})
    assert e.rule_value("a.r") is True
