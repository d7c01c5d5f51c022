"""With use_sim_time, a /clock that stops (a paused simulator) stops ROS time: the heartbeat
stops (the watchdog acts) and the monitor says why, once, in its log and in /diagnostics
(acceptance: nothing was logged)."""
import json
import subprocess

import pytest

from rosharness import PY, spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SIM = r'''
import json, threading, time
import rospy
from diagnostic_msgs.msg import DiagnosticArray
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64, Header

rospy.init_node("sim", disable_signals=True)
out = {"beats": [], "diag": []}
lock = threading.Lock()
def beat(m):
    with lock: out["beats"].append(time.time())
def diag(m):
    with lock:
        out["diag"] += [(time.time(), s.level, s.message) for s in m.status if s.name == "rubass: monitor"]
rospy.Subscriber("/rubass/heartbeat", Header, beat)
rospy.Subscriber("/diagnostics", DiagnosticArray, diag)
clock = rospy.Publisher("/clock", Clock, queue_size=10)
x = rospy.Publisher("/x", Float64, queue_size=10)
end = time.time() + 10
while x.get_num_connections() < 1 and time.time() < end:
    clock.publish(Clock(clock=rospy.Time.from_sec(50.0)))
    time.sleep(0.05)

def run(t0, seconds):
    start = time.time()
    while time.time() - start < seconds:
        clock.publish(Clock(clock=rospy.Time.from_sec(t0 + (time.time() - start))))
        time.sleep(0.01)
    return t0 + seconds

t = run(50.0, 1.5)
out["paused"] = time.time()
time.sleep(4.0)              # the simulator paused
out["resumed"] = time.time()
run(t, 1.5)
print(json.dumps(out))
rospy.signal_shutdown("done")
'''


def test_a_clock_that_stops_is_said_once_and_shown_in_diagnostics_until_it_moves(ros, tmp_path):
    import rosgraph

    rosgraph.Master("/test", master_uri=ros.master.uri).setParam("/use_sim_time", True)
    mon = ros.monitor(spec(tmp_path, "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { brake; }\n"),
                      wait=False, diagnostics_rate=5)
    out = subprocess.run([PY, "-c", SIM], env=ros.env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    rec = json.loads(out.stdout.strip().splitlines()[-1])
    paused, resumed = rec["paused"], rec["resumed"]
    log = ros.log(mon)
    assert log.count("no /clock for") == 1, log
    assert "ROS time stands still at 51." in log and "/clock moves again" in log, log
    beats = rec["beats"]
    assert not [b for b in beats if paused + 0.2 < b < resumed], "no heartbeat while time stands still"
    assert [b for b in beats if b > resumed + 0.2], "the heartbeat is back"
    during = [d for d in rec["diag"] if paused + 3.0 < d[0] < resumed]
    assert during and all(d[1] == 2 and "no /clock for" in d[2] for d in during), during
    after = [d for d in rec["diag"] if d[0] > resumed + 0.5]
    assert after and all("no /clock" not in d[2] for d in after), after
