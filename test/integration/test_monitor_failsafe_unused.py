"""An action named only in ~overload_actions or ~error_actions is used by them: the monitor does
not warn that it is 'declared but never used' (an action nothing uses still gets the warning)."""
import pytest

from rosharness import spec, wait_log

pytestmark = pytest.mark.ros


def test_fail_safe_actions_are_not_declared_but_never_used(ros, tmp_path):
    # the spec declares stop, brake and warn; only warn is used by a behaviour
    mon = ros.monitor(spec(tmp_path, "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { warn; }\n"),
                      overload_actions="[stop]")
    wait_log(mon, ros, "enforcing")
    log = ros.log(mon)
    assert "action 'stop' is declared but never used" not in log, log
    assert "action 'brake' is declared but never used" in log, log  # nothing uses brake


def test_error_actions_count_as_a_use_too(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { warn; }\n"),
                      overload_actions="[stop]", error_actions="[brake]")
    wait_log(mon, ros, "enforcing")
    assert "declared but never used" not in ros.log(mon), ros.log(mon)
