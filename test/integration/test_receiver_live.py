"""The monitor's receiver on a live system (rubass/ros/receiver.py, issue 17): one thread reads
every watched topic, through publishers that come and go, latched and large messages, a `limit`
action reading a topic the spec reads too, and `~receiver: rospy` for rospy's own threads."""
import json
import os
import subprocess
import time

import pytest
from rosharness import PY, TWIST, brake_after, monitor_values, spec, wait_log

pytestmark = [pytest.mark.ros, pytest.mark.slow]

FAST = "entity a { rules:\n  fast: topic /cmd_vel.linear.x > 1;\n}\nif (a.fast) then { brake; }\n"


def until_value(ros, key, want, timeout=10.0):
    end, got = time.monotonic() + timeout, None
    while time.monotonic() < end:
        got = monitor_values(ros)[key]
        if got == want:
            return
    raise AssertionError(f"{key}: {got!r}, never {want!r}")


def test_one_thread_reads_the_topics_and_publishers_may_come_and_go(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, FAST))
    # each brake_after is a new publisher node: a new connection (the master's publisherUpdate),
    # and its end when the node exits
    for _ in range(3):
        assert brake_after(ros, 2.0), ros.log(mon)
        assert not brake_after(ros, 0.5, grace=0.3), ros.log(mon)
    until_value(ros, "receiving", "one thread, 0 connections")  # every ended publisher's connection dropped
    assert "Traceback" not in ros.log(mon) and "receiver:" not in ros.log(mon), ros.log(mon)


LATCHED = """
import rospy, sys
from std_msgs.msg import Float64, UInt8MultiArray
rospy.init_node(sys.argv[1])
if sys.argv[1] == "latched":
    pub = rospy.Publisher("/mode", Float64, queue_size=1, latch=True)
    pub.publish(Float64(3.0))
else:
    pub = rospy.Publisher("/big", UInt8MultiArray, queue_size=1, tcp_nodelay=True)
    while pub.get_num_connections() == 0:
        rospy.sleep(0.05)
    rospy.sleep(0.5)
    pub.publish(UInt8MultiArray(data=bytes(range(256)) * 16384))  # 4 MiB: many reads
print("published", flush=True)
rospy.spin()
"""


def test_a_latched_message_sent_before_the_monitor_started_and_a_4_mib_message_are_read(ros, tmp_path):
    latched = ros.spawn([PY, "-c", LATCHED, "latched"], "latched", stdout=subprocess.PIPE, text=True)
    assert latched.stdout.readline().strip() == "published"
    body = ("entity a { rules:\n  mode: topic /mode.data > 2;\n  big: len(topic /big.data) > 4000000;\n}\n"
            "if (a.mode) then { warn; }\nif (a.big) then { brake; }\n")
    mon = ros.monitor(spec(tmp_path, body))
    listener = ros.probe_bg({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                             "steps": [{"wait_publishers": "/brake"}, {"mark": "ready"},
                                       {"wait": "/brake", "timeout": 20}], "linger": 0.1}, name="listener")
    assert '"ready"' in listener.stdout.readline()
    big = ros.spawn([PY, "-c", LATCHED, "big"], "big", stdout=subprocess.PIPE, text=True)
    assert big.stdout.readline().strip() == "published"
    out, _ = listener.communicate(timeout=30)
    got = [json.loads(x) for x in out.splitlines() if x.startswith("{")]
    assert any(r["kind"] == "recv" and r["msg"]["data"] is True for r in got), ros.log(mon)
    started = [x for x in ros.log(mon).splitlines() if x.startswith("[WARN]") and "started" in x]
    assert len(started) == 1 and "a.mode" in started[0], ros.log(mon)  # the latched 3.0 started `warn`
    assert monitor_values(ros)["receiving"] == "one thread, 2 connections"


CRAWL = ("actions:\n  crawl:\n    plugin: limit\n    input: /cmd_vel\n    topic: /safety_cmd\n"
         "    linear_x: [-0.1 m/s, 0.2 m/s]\n"
         "  brake: {plugin: publish, topic: /brake, type: std_msgs/Bool, message: {data: true}, rate: 20 Hz}\n")


def test_a_limit_action_reading_a_topic_of_the_spec_gets_it_on_a_rospy_thread_and_both_work(ros, tmp_path):
    """The `limit` action publishes from its callback: that topic's connection is never the receiver's."""
    (tmp_path / "lib.yaml").write_text(CRAWL)
    path = tmp_path / "s.rbs"
    path.write_text('import "lib.yaml";\naction primitive crawl, brake;\n'
                    "entity a { rules:\n  fast: topic /cmd_vel.linear.x > 1;\n  on: topic /trig.data > 0;\n}\n"
                    "if (a.on) then { crawl; }\nif (a.fast) then { brake; }\n")
    mon = ros.monitor(str(path))
    rec = ros.probe({
        "listen": [{"topic": "/safety_cmd", "type": TWIST}, {"topic": "/brake", "type": "std_msgs/Bool"}],
        "advertise": [{"topic": "/cmd_vel", "type": TWIST}, {"topic": "/trig", "type": "std_msgs/Float64"}],
        "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_subscribers": "/trig"}, {"wait_publishers": "/safety_cmd"},
                  {"wait_publishers": "/brake"}, {"sleep": 0.5},
                  {"publish": "/trig", "msg": {"data": 1.0}}, {"sleep": 0.3}, {"mark": "go"},
                  {"publish": "/cmd_vel", "msg": {"linear": {"x": 2.0}}, "repeat": 5, "period": 0.05},
                  {"sleep": 0.5}], "linger": 0.1})
    go = next(r["wall"] for r in rec if r["kind"] == "mark")
    clamped = [r["msg"]["linear"]["x"] for r in rec if r["kind"] == "recv" and r["topic"] == "/safety_cmd"
               and r["wall"] > go]
    assert clamped and max(clamped) == pytest.approx(0.2), (clamped, ros.log(mon))
    assert any(r["kind"] == "recv" and r["topic"] == "/brake" and r["wall"] > go for r in rec), ros.log(mon)
    values = monitor_values(ros)
    # the probe has ended: both its connections too (/cmd_vel's, read by a rospy thread, is no longer
    # counted as given: a tester found it counted for good)
    assert values["receiving"] == "one thread, 0 connections", values


def test_receiver_rospy_keeps_rospys_threads_and_a_bad_value_is_refused(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, FAST), receiver="rospy")
    assert brake_after(ros, 2.0), ros.log(mon)
    assert monitor_values(ros)["receiving"] == "rospy's threads (~receiver: rospy)"
    bad = ros.monitor(spec(tmp_path, FAST, name="t.rbs"), name="rubass2", wait=False, receiver="threads")
    assert bad.wait(20) == 1
    log = ros.log(bad)
    assert ("~receiver must be one_thread (one thread reads every watched topic) or rospy (a rospy thread per "
            "connection, as rospy subscribers do), got 'threads'") in log, log
    assert "Traceback" not in log


def test_a_monitor_that_read_its_topics_a_second_late_runs_the_overload_fail_safe(ros, tmp_path):
    """The monitor stalled for 2 s (SIGSTOP: the computer overloaded, swapping): nothing is dropped,
    the messages wait in the sockets' buffers, and the rules then see the robot seconds late.
    rospy's threads would say nothing; the receiver's arrival stamps start ~overload_actions."""
    import signal

    mon = ros.monitor(spec(tmp_path, FAST), overload_actions="[brake]")
    probe = ros.probe_bg({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                          "advertise": [{"topic": "/cmd_vel", "type": TWIST}],
                          "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_publishers": "/brake"}, {"sleep": 0.3},
                                    {"mark": "go"},
                                    {"publish": "/cmd_vel", "msg": {"linear": {"x": 0.0}}, "repeat": 200,
                                     "period": 0.02}, {"sleep": 0.5}], "linger": 0.1}, name="driver")
    time.sleep(2.5)  # the driver publishes from ~1 s on; the monitor is stopped in the middle of it
    os.kill(mon.pid, signal.SIGSTOP)
    # 2 s: the kernel gives a run of packets that waited together the newest one's stamp, so at
    # 50 Hz a stall reads as ~70 % of its length (measured); 1.4 s is still well past 0.5 s
    time.sleep(2.0)
    os.kill(mon.pid, signal.SIGCONT)
    out, _ = probe.communicate(timeout=30)
    rec = [json.loads(x) for x in out.splitlines() if x.startswith("{")]
    brakes = [r for r in rec if r["kind"] == "recv" and r["topic"] == "/brake" and r["msg"]["data"] is True]
    log = ros.log(mon)
    assert brakes, log  # no rule is violated (x = 0): only the fail-safe brakes
    assert "overloaded: its topics are read" in log and "s late (their messages wait in the sockets' buffers" in log
    assert "overload over (no message dropped or read 0.5 s late for 1 s): releasing brake" in log, log


def test_without_overload_actions_late_reading_is_a_warning_in_the_log_and_diagnostics(ros, tmp_path):
    import signal

    mon = ros.monitor(spec(tmp_path, FAST))
    # the status right after the stall says it: listening from before it (a CI run's listener,
    # started after, came too late for it)
    diag = ros.probe_bg({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                         "steps": [{"wait_publishers": "/diagnostics"}, {"mark": "ready"}, {"sleep": 9.0}]},
                        name="diag")
    assert '"ready"' in diag.stdout.readline()
    driver = ros.probe_bg({"advertise": [{"topic": "/cmd_vel", "type": TWIST}],
                           "steps": [{"wait_subscribers": "/cmd_vel"},
                                     {"publish": "/cmd_vel", "msg": {"linear": {"x": 0.0}}, "repeat": 300,
                                      "period": 0.02}]}, name="driver")
    time.sleep(2.5)
    os.kill(mon.pid, signal.SIGSTOP)
    time.sleep(2.0)
    os.kill(mon.pid, signal.SIGCONT)
    out, _ = diag.communicate(timeout=30)
    rec = [json.loads(x) for x in out.splitlines() if x.startswith("{")]
    driver.communicate(timeout=30)
    mons = [s for r in rec if r["kind"] == "recv" for s in r["msg"]["status"] if s["name"] == "rubass: monitor"]
    late = [s for s in mons if dict((kv["key"], kv["value"]) for kv in s["values"])["read late"] != "no"]
    assert late and late[0]["level"] == 1 and "(READ LATE: " in late[0]["message"], (mons, ros.log(mon))
    assert "s late (their messages wait in the sockets' buffers: the monitor cannot keep up); no ~overload_actions " \
           "are set" in ros.log(mon), ros.log(mon)


FLOOD = """
import json, sys, time
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Bool
rospy.init_node("flood")
brakes = []
rospy.Subscriber("/brake", Bool, lambda m: brakes.append(time.time()) if m.data else None)
pub = rospy.Publisher("/cmd_vel", Twist, queue_size=100, tcp_nodelay=True)
while pub.get_num_connections() == 0 or "/brake" not in dict(rospy.get_published_topics()):
    time.sleep(0.05)
time.sleep(0.3)
go = time.time()
for i in range(1000):  # linear.y changes each time: every rule that reads it is evaluated again
    msg = Twist()
    msg.linear.y = msg.angular.z = float(i)
    pub.publish(msg)
    time.sleep(0.002)
end = time.time()
time.sleep(1.0)
print(json.dumps({"go": go, "end": end, "brakes": brakes}), flush=True)
"""


def test_an_engine_that_cannot_keep_up_runs_the_overload_fail_safe_long_before_its_queue_is_full(ros, tmp_path):
    """3,000 rules evaluated again on every /cmd_vel message at ~500 Hz: more than the engine can do
    (~6.5 ms a message on our 2-core VM, in process: 3 cores' worth).
    The receiver reads on time and queues what the busy engine cannot take: nothing is dropped
    (the queue holds 100,000), but the rules, and their stops, fall seconds behind. Before the
    queue's waits were measured a 6,000-rule spec stopped the robot 4.7 s late with no fail-safe."""
    rules = "".join(f"  l{i}: abs(topic /cmd_vel.linear.y - {i + 1000}) < 0.5 and topic /cmd_vel.angular.z < {i};\n"
                    for i in range(3000))
    body = "entity a { rules:\n  fast: topic /cmd_vel.linear.x > 1;\n" + rules + "}\nif (a.fast) then { stop; }\n"
    mon = ros.monitor(spec(tmp_path, body), overload_actions="[brake]")
    diag = ros.probe_bg({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"},
                                    {"topic": "/rubass/heartbeat", "type": "std_msgs/Header"}],
                         "steps": [{"wait_publishers": "/diagnostics"}, {"mark": "ready"}, {"sleep": 12.0}]},
                        name="diag")
    assert '"ready"' in diag.stdout.readline()
    flood = ros.spawn([PY, "-c", FLOOD], "flood", stdout=subprocess.PIPE, text=True)
    out, _ = flood.communicate(timeout=120)
    got = json.loads(out.strip().splitlines()[-1])
    log = ros.log(mon)
    assert got["brakes"] and got["brakes"][0] < got["end"], log  # while it still floods: seconds, not minutes
    assert "overloaded: its messages are evaluated" in log and "(they wait in the engine's queue" in log, log
    out, _ = diag.communicate(timeout=60)
    rec = [json.loads(x) for x in out.splitlines() if x.startswith("{")]
    said = [s["message"] for r in rec if r["kind"] == "recv" and r["topic"] == "/diagnostics"
            for s in r["msg"]["status"] if s["name"] == "rubass: monitor"]
    # the status says it, or, when the engine did not answer it within 5 s behind its queue, why not
    assert any("OVERLOADED, evaluating its messages" in m for m in said), said
    # the busy engine still ticks between queued messages; its heartbeat must not say it keeps up
    beats = [r["wall"] for r in rec if r["kind"] == "recv" and r["topic"] == "/rubass/heartbeat"]
    during = [b for b in beats if got["go"] <= b <= got["end"] + 1.0]
    gaps = [b - a for a, b in zip([got["go"]] + during, during + [got["end"] + 1.0])]
    assert max(gaps) >= 1.0, (len(during), max(gaps))
    wait_log(mon, ros, "overload over (no message dropped or read 0.5 s late for 1 s): releasing brake", 60)
    assert monitor_values(ros)["dropped messages"] == "0"  # the queue took them all: late, not lost
