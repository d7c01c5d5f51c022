"""The monitor's --help lists every private parameter with its range, and the ranges it states are the
ones read_config enforces (`~queue_size` below 10 was fatal while documented only as "int, default 100000")."""
import os
import re

import pytest

from rubass.ros.params import HELP, KNOWN, ParamError, read_config

from conftest import ROOT


def config(**params):
    params.setdefault("spec", "s.rbs")
    return read_config(lambda name, default: params.get(name, default))


def test_help_names_every_parameter_and_the_queue_size_range():
    for name in KNOWN:
        assert f"~{name} (" in HELP, name
    assert "~queue_size (int, 10 to 10000000, 100000)" in HELP


@pytest.mark.parametrize("name,lo,hi", [(m.group(1), float(m.group(2)), float(m.group(3)))
                                        for m in re.finditer(r"~(\w+) \((?:Hz|int), (-?[\d.]+) to ([\d.]+),", HELP)])
def test_each_stated_range_is_the_enforced_one(name, lo, hi):
    whole = name in ("queue_size", "nice")
    kind = int if whole else float
    assert getattr(config(**{name: kind(lo)}), name) == kind(lo)
    assert getattr(config(**{name: kind(hi)}), name) == kind(hi)
    below, above = (int(lo) - 1, int(hi) + 1) if whole else (lo * 0.5, hi * 2)
    for bad in (below, above):
        with pytest.raises(ParamError, match=f"~{name} must be"):
            config(**{name: bad})


def test_the_docs_table_states_the_queue_size_range():
    text = open(os.path.join(ROOT, "docs", "monitor.md")).read()
    assert "| `~queue_size` | int, 10 to 10000000 | 100000 |" in text
    assert "Private parameters stay on the master" in text


@pytest.mark.parametrize("value", ["one_thread", "rospy"])
def test_the_receiver_is_one_of_its_two_values(value):
    assert config().receiver == "one_thread"  # the default
    assert config(receiver=value).receiver == value


@pytest.mark.parametrize("bad", ["threads", "", 1, True, None, ["rospy"]])
def test_any_other_receiver_is_refused_with_both_values_named(bad):
    with pytest.raises(ParamError) as err:
        config(receiver=bad)
    assert str(err.value) == (f"~receiver must be one_thread (one thread reads every watched topic) or rospy (a rospy "
                              f"thread per connection, as rospy subscribers do), got {bad!r}")
    text = open(os.path.join(ROOT, "docs", "monitor.md")).read()
    assert "| `~receiver` | `one_thread` or `rospy` | `one_thread` |" in text
