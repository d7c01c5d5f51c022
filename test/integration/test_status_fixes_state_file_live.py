"""A `~state_file: false` left on the master by an earlier run (private parameters stay there) is read
by a later plain `rosrun`: latch persistence is then off, and the monitor's status says so, WARN
naming the parameter (it was OK, only `latch state file: off` among its values)."""
import subprocess

import pytest
from rosharness import spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SPEC = "entity a { rules:\n  high: topic /x.data > 1;\n}\nif (a.high) then { stop; }\n"


def test_a_leftover_state_file_false_is_a_warning_in_diagnostics(ros, tmp_path):
    subprocess.run(["rosparam", "set", "/rubass/state_file", "false"], env=ros.env, check=True, timeout=20)
    mon = ros.monitor(spec(tmp_path, SPEC))  # no _state_file:= given: the master's leftover is read
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"wait": "/diagnostics", "timeout": 10}, {"sleep": 1.2}]})
    mons = [s for r in rec if r["kind"] == "recv" for s in r["msg"]["status"] if s["name"] == "rubass: monitor"]
    assert mons, ros.log(mon)
    assert mons[-1]["level"] == 1, mons[-1]
    assert "LATCH PERSISTENCE OFF: ~state_file is false" in mons[-1]["message"], mons[-1]
    assert "will not survive a restart" in mons[-1]["message"], mons[-1]
