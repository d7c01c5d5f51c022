"""Sim time, a clock jump back (a simulator reset) while a behaviour is active and stays true:
~events reports one start and, once the cause is gone, one release, not a second start."""
import json
import subprocess

import pytest
from rosharness import PY, spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SIM = r'''
import json, threading, time
import rospy
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64, String

rospy.init_node("sim", disable_signals=True)
events = []
lock = threading.Lock()
def event(m):
    with lock: events.append(json.loads(m.data))
rospy.Subscriber("/rubass/events", String, event)
clock = rospy.Publisher("/clock", Clock, queue_size=10)
odom = rospy.Publisher("/odom", Float64, queue_size=10)
end = time.time() + 10
while odom.get_num_connections() < 1 and time.time() < end:  # the monitor watches from the first /clock
    clock.publish(Clock(clock=rospy.Time.from_sec(111.0)))
    time.sleep(0.05)
time.sleep(0.5)

def run(t0, seconds, flowing):
    """Sim time from t0 at the wall's pace: /clock at 100 Hz, /odom at 10 Hz while flowing."""
    start = time.time()
    i = 0
    while time.time() - start < seconds:
        clock.publish(Clock(clock=rospy.Time.from_sec(t0 + (time.time() - start))))
        if flowing and i % 10 == 0:
            odom.publish(Float64(0.0))
        i += 1
        time.sleep(0.01)
    return t0 + seconds

t = run(112.0, 1.2, False)   # no /odom: silent from 112.5 s
t = run(5.0, 2.5, False)     # a simulator reset to 5 s; still silent (true again at 5.5 s)
t = run(t, 1.5, True)        # /odom flows: the cause is gone
time.sleep(0.5)
with lock:
    print(json.dumps(events))
rospy.signal_shutdown("done")
'''


def test_a_behaviour_true_across_a_clock_jump_gets_one_start_and_one_release(ros, tmp_path):
    subprocess.run(["rosparam", "set", "/use_sim_time", "true"], env=ros.env, check=True, timeout=20)
    mon = ros.monitor(spec(tmp_path, "entity a { rules: silent: age(topic /odom) > 0.5 s; }\n"
                                     "silence: if (a.silent) then { brake; }\n"))
    script = tmp_path / "sim.py"
    script.write_text(SIM)
    run = subprocess.run([PY, str(script)], env=ros.env, capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    events = json.loads(run.stdout.strip().splitlines()[-1])
    log = ros.log(mon)
    assert "ROS time jumped back" in log, log
    assert [(e["event"], e.get("name")) for e in events] == [("start", "silence"), ("release", "silence")], \
        f"{events}\n{log}"
    assert events[0]["time"] > 100.0 and 7.0 < events[1]["time"] < 9.5, events
