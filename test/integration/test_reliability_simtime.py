"""Issue 13 (4): with use_sim_time, watching starts at the first /clock message (not at time 0),
and when the clock jumps back (a simulator reset) windows restart and a persisting violation of
`(x > 1) for 1 s` is still stopped within its time."""
import json
import subprocess

import pytest
from rosharness import PY, spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SIM = r'''
import json, threading, time
import rospy
from geometry_msgs.msg import Twist
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Bool, Float64, Header

rospy.init_node("sim", disable_signals=True)
out = {"heartbeats": 0, "brakes": 0, "stops": []}
lock = threading.Lock()
def beat(m):
    with lock: out["heartbeats"] += 1
def brake(m):
    with lock: out["brakes"] += 1
def stop(m):
    with lock: out["stops"].append(time.time())
rospy.Subscriber("/rubass/heartbeat", Header, beat)
rospy.Subscriber("/brake", Bool, brake)
rospy.Subscriber("/safety_cmd", Twist, stop)
clock = rospy.Publisher("/clock", Clock, queue_size=10)
x = rospy.Publisher("/x", Float64, queue_size=10)
odom = rospy.Publisher("/odom", Float64, queue_size=10)
end = time.time() + 10
while (x.get_num_connections() < 1 or odom.get_num_connections() < 1) and time.time() < end:
    time.sleep(0.05)
time.sleep(1.0)
out["heartbeats_before_clock"] = out["heartbeats"]

def run(t0, seconds, value):
    """Sim time from t0 at the wall's pace: /clock at 100 Hz, /x and /odom at 10 Hz."""
    start = time.time()
    i = 0
    while time.time() - start < seconds:
        clock.publish(Clock(clock=rospy.Time.from_sec(t0 + (time.time() - start))))
        if i % 10 == 0:
            x.publish(Float64(value))
            odom.publish(Float64(0.0))
        i += 1
        time.sleep(0.01)
    return t0 + seconds

t = run(112.0, 2.5, 0.0)   # the clock starts at 112 s; /odom flows
out["brakes_while_flowing"] = out["brakes"]
t = run(t, 0.5, 5.0)       # the violation starts ...
out["stops_before_jump"] = len(out["stops"])
jump = time.time()
run(5.0, 2.5, 5.0)         # ... and persists across a simulator reset to 5 s
out["stop_after_jump_s"] = (out["stops"][0] - jump) if out["stops"] else None
print(json.dumps(out))
rospy.signal_shutdown("done")
'''


def test_sim_time_starts_watching_at_the_first_clock_and_a_reset_restarts_the_windows(ros, tmp_path):
    subprocess.run(["rosparam", "set", "/use_sim_time", "true"], env=ros.env, check=True, timeout=20)
    mon = ros.monitor(spec(tmp_path, "entity a { rules:\n  silent: age(topic /odom) > 0.5 s;\n"
                                     "  fast: (topic /x.data > 1) for 1 s;\n}\n"
                                     "if (a.silent) then { brake; }\nif (a.fast) then { stop; }\n"))
    script = tmp_path / "sim.py"
    script.write_text(SIM)
    run = subprocess.run([PY, str(script)], env=ros.env, capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout.strip().splitlines()[-1])
    log = ros.log(mon)
    assert out["heartbeats_before_clock"] == 0, "no heartbeat before the first /clock message"
    assert out["brakes_while_flowing"] == 0, "age(topic /odom) counts from the first /clock, not from 0\n" + log
    assert out["stops_before_jump"] == 0
    assert out["stop_after_jump_s"] is not None and out["stop_after_jump_s"] < 2.0, f"{out}\n{log}"
    assert "ROS time jumped back" in log
    assert mon.poll() is None
