"""A connection that ends while its publisher stays registered (TCP's keepalive giving up after a
link cut longer than ~2.5 min, or the publisher closing it) is one rospy never makes again by
itself: an acceptance tester's 170 s cut left /speed unread for good, with either receiver,
though its publisher went on publishing. The monitor connects again (rubass/ros/reconnect.py).
Here the publisher closes the connection itself and stays registered, as after such a cut."""
import subprocess

import pytest
from rosharness import PY, monitor_values, spec, wait_log

pytestmark = [pytest.mark.ros, pytest.mark.slow]

BODY = "entity a { rules:\n  fast: topic /cmd_vel.linear.x > 1;\n}\nif (a.fast) then { brake; }\n"
DROPPER = """
import sys, time
import rospy
from geometry_msgs.msg import Twist
rospy.init_node("driver")
pub = rospy.Publisher("/cmd_vel", Twist, queue_size=10, tcp_nodelay=True)
while pub.get_num_connections() == 0:
    time.sleep(0.05)
time.sleep(0.5)
pub.publish(Twist())
time.sleep(3.0)  # connected a while (the monitor looks every 2 s): one it had, then lost
for c in list(pub.impl.connections):  # ends it as a dead link's keepalive would: still registered
    c.close()
print("closed", flush=True)
end = time.time() + 20
while pub.get_num_connections() == 0 and time.time() < end:
    time.sleep(0.05)
print("connected again" if pub.get_num_connections() else "never connected again", flush=True)
msg = Twist()
msg.linear.x = 2.0
for _ in range(20):
    pub.publish(msg)
    time.sleep(0.05)
time.sleep(1.0)
"""


@pytest.mark.parametrize("receiver", ["one_thread", "rospy"])
def test_a_connection_that_ended_while_its_publisher_stays_registered_is_made_again(ros, tmp_path, receiver):
    mon = ros.monitor(spec(tmp_path, BODY), receiver=receiver)
    brakes = ros.probe_bg({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                           "steps": [{"wait_publishers": "/brake"}, {"mark": "ready"}, {"sleep": 14.0}]}, name="base")
    assert '"ready"' in brakes.stdout.readline()
    driver = ros.spawn([PY, "-c", DROPPER], "driver", stdout=subprocess.PIPE, text=True)
    assert driver.stdout.readline().strip() == "closed"
    assert driver.stdout.readline().strip() == "connected again", ros.log(mon)
    wait_log(mon, ros, "topic /cmd_vel: the connection from its publisher /driver had ended", 5)
    out, _ = brakes.communicate(timeout=30)
    assert '"data": true' in out, ros.log(mon)  # the violation after the reconnection is stopped
    assert int(monitor_values(ros)["connections made again"]) >= 1


BASE = """
import time
import rospy
from std_msgs.msg import Bool
rospy.init_node("base")
got = []
sub = rospy.Subscriber("/brake", Bool, lambda m: got.append(time.time()), tcp_nodelay=True)
end = time.time() + 20
while not got and time.time() < end:
    time.sleep(0.05)
print("braking" if got else "no brake", flush=True)
time.sleep(3.0)  # connected a while (the monitor looks every 2 s): one it had, then lost
for c in list(sub.impl.connections):  # its subscription ends as after a long cut: still registered
    c.close()
cut = time.time()
time.sleep(0.5)
end = time.time() + 15
while not [t for t in got if t > cut + 0.5] and time.time() < end:
    time.sleep(0.05)
print("braking again" if [t for t in got if t > cut + 0.5] else "no brake since", flush=True)
"""


def test_a_subscriber_whose_connection_ended_is_told_through_the_master_to_connect_again(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, BODY))
    base = ros.spawn([PY, "-c", BASE], "base", stdout=subprocess.PIPE, text=True)
    ros.probe({"advertise": [{"topic": "/cmd_vel", "type": "geometry_msgs/Twist"}],
               "steps": [{"wait_subscribers": "/cmd_vel"}, {"sleep": 0.3},
                         {"publish": "/cmd_vel", "msg": {"linear": {"x": 2.0}}}, {"sleep": 0.5}]})
    assert base.stdout.readline().strip() == "braking", ros.log(mon)
    assert base.stdout.readline().strip() == "braking again", ros.log(mon)
    assert "topic /brake: subscriber /base lost its connection to the monitor" in ros.log(mon)
