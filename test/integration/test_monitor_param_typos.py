"""A typo in a private parameter of the monitor is warned at start, with a suggestion."""
import pytest

from rosharness import spec, wait_log

pytestmark = pytest.mark.ros


def test_unknown_private_parameters_are_warned_with_a_suggestion(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { stop; }\n"),
                      rat=5, overload_action="[stop]")
    wait_log(mon, ros, "enforcing")
    log = ros.log(mon)
    assert "unknown parameter ~rat (ignored); did you mean '~rate'?" in log, log
    assert "unknown parameter ~overload_action (ignored); did you mean '~overload_actions'?" in log, log
    assert "~spec (ignored)" not in log and "unknown parameter ~queue_size" not in log, log


def test_the_agents_unknown_parameters_are_warned_too(ros, tmp_path):
    """Acceptance finding (multi-host): `_nod_rate:=5` started the agent at 10 Hz, silently."""
    import os

    from conftest import ROOT
    from rosharness import PY

    agent = ros.spawn([PY, os.path.join(ROOT, "scripts", "agent"), "__name:=agent", "_nod_rate:=5"], "agent")
    wait_log(agent, ros, "unknown parameter ~nod_rate (ignored); did you mean '~node_rate'?")
