"""A rejected reload while nothing is enforced says so (it does not claim previous rules keep running)."""
import os
import signal

import pytest

from rosharness import wait_log

pytestmark = pytest.mark.ros


def test_a_rejected_reload_while_nothing_is_enforced_does_not_claim_previous_rules(ros, tmp_path):
    missing = str(tmp_path / "nonexistent.rbs")
    mon = ros.monitor(missing)
    out = ros.call("/rubass/reload")
    assert "nothing is enforced yet" in out.stdout, out.stdout
    assert "previous rules" not in out.stdout, out.stdout
    os.kill(mon.pid, signal.SIGHUP)
    wait_log(mon, ros, "reload (SIGHUP) rejected")
    log = ros.log(mon)
    assert "previous rules keep running" not in log, log
    assert "reload (SIGHUP) rejected, nothing is enforced yet" in log, log
