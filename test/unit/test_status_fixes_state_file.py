"""Latch persistence off (`~state_file: false`, maybe a leftover private parameter on the master from an
earlier run that a plain `rosrun` inherits) is a WARN in /diagnostics naming the parameter and saying a
latched stop will not survive a restart; it was OK with only `latch state file: off` among the values."""
import os

from rubass.actions import status
from rubass.lang import check_text

from conftest import ROOT

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")


def monitor_entry(actions, state_file):
    spec = check_text(f"action primitive {actions};\nentity a {{ rules: r: topic /x.data > 1; }}\n"
                      f"if (a.r) then {{ {actions.split(',')[0]}; }}\n", os.path.join(ROOT, "x.rbs"), [LIB])
    return status.build(spec, {"a.r": False}, [], {}, {}, {},
                        {"master": "connected", "latch state file": state_file})[-1]


def test_latch_persistence_off_with_a_latched_action_is_a_warning_naming_the_parameter():
    e = monitor_entry("stop", "off (~state_file: false)")
    assert e.level == status.WARN, e
    assert "LATCH PERSISTENCE OFF" in e.message and "~state_file is false" in e.message
    assert "will not survive a restart" in e.message and "stop" in e.message


def test_persistence_on_or_no_latched_action_stays_ok():
    assert monitor_entry("stop", "/tmp/x.latches.json").level == status.OK
    assert monitor_entry("warn", "off (~state_file: false)").level == status.OK  # nothing to keep
