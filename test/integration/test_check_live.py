"""`rubass check --live` and `rubass model --live` against a private master with real publishers,
one of a message type installed nowhere (its definition comes from the publisher's handshake)."""
import os
import subprocess
import sys
import time

import pytest

from conftest import ROOT

pytestmark = pytest.mark.ros
LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")

PUBLISHER = r'''
import rospy, genpy.dynamic
from geometry_msgs.msg import Twist
from sensor_msgs.msg import JointState
PACK = """Header header
float32 pack_voltage
acme_msgs/Cell[] cells
================================================================================
MSG: std_msgs/Header
uint32 seq
time stamp
string frame_id
================================================================================
MSG: acme_msgs/Cell
float32 voltage
float32 temp
"""
Pack = genpy.dynamic.generate_dynamic("acme_msgs/Pack", PACK)["acme_msgs/Pack"]
rospy.init_node("driver")
pubs = [(rospy.Publisher("/cmd_vel", Twist, queue_size=1), Twist()),
        (rospy.Publisher("/acme/pack", Pack, queue_size=1), Pack()),
        (rospy.Publisher("/joint_states", JointState, queue_size=1), JointState(name=["l", "r"]))]
rospy.Subscriber("/odom_filtered", Twist, lambda m: None)
print("ready", flush=True)
while not rospy.is_shutdown():
    for pub, msg in pubs:
        pub.publish(msg)
    rospy.sleep(0.1)
'''
URDF = """<robot name="r"><link name="base"/><link name="wl"/><link name="wr"/><link name="laser"/>
<joint name="l" type="continuous"><parent link="base"/><child link="wl"/></joint>
<joint name="r" type="continuous"><parent link="base"/><child link="wr"/></joint>
<joint name="laser_mount" type="fixed"><parent link="base"/><child link="laser"/></joint></robot>"""


@pytest.fixture
def graph(ros, tmp_path):
    import rosgraph

    master = rosgraph.Master("/test", master_uri=ros.master.uri)
    master.setParam("/robot_description", URDF)
    script = tmp_path / "publisher.py"
    script.write_text(PUBLISHER)
    proc = ros.spawn(["/usr/bin/python3", str(script)], "publisher")
    end = time.time() + 30
    while time.time() < end:
        if proc.poll() is not None:
            raise AssertionError(ros.log(proc))
        if {"/cmd_vel", "/acme/pack", "/joint_states"} <= {t for t, _ in master.getTopicTypes()}:
            return ros
        time.sleep(0.1)
    raise AssertionError("the publisher never advertised")


def rubass(ros, *args):
    proc = subprocess.run([sys.executable, "-m", "rubass", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=120, env=ros.env)
    return proc.returncode, proc.stdout, proc.stderr


def test_live_model_reads_types_nodes_foreign_definitions_and_joint_kinds(graph):
    from rubass.lang.units import dim
    from rubass.ros.model_sources import live_model

    m = live_model(graph.master.uri)
    assert m.type_of("/acme/pack") == "acme_msgs/Pack"
    assert "/driver" in m.nodes
    assert m.undefined_types() == []  # acme_msgs is installed nowhere: read from the handshake
    assert m.field("/acme/pack", ("cells", 0, "temp")).kind == "num"
    assert "did you mean 'pack_voltage'" in m.field("/acme/pack", ("voltage",)).why
    assert m.field("/joint_states", ("velocity", 0)).dim == dim(rad=1, s=-1)  # both joints continuous
    assert m.field("/cmd_vel", ("linear", "x")).dim == dim(m=1, s=-1)


def test_check_live_warns_of_unknown_topics_and_nodes(graph, write):
    path = write("s.rbs", f'import "{LIB}";\naction primitive stop;\n'
                          "entity base: drivr {\n  rules:\n    r: topic /cmd_vl.linear.x > 1 m/s;\n"
                          "    hot: cpu(node drivr) > 50 %;\n    f: topic /odom_filtered.linear.x > 1;\n}\n"
                          "if (base.r) then { stop; }\n")
    code, out, err = rubass(graph, "check", "--live", path)
    assert code == 0, err
    assert f"{path}:3:14: warning: node 'drivr' is not in the live graph at {graph.master.uri}; " \
           "did you mean '/driver'?" in err
    assert f"{path}:5:8: warning: topic '/cmd_vl' is not in the live graph" in err
    assert "did you mean '/cmd_vel'?" in err
    assert f"{path}:7:8: warning: topic '/odom_filtered' has no publisher in the live graph at " \
           f"{graph.master.uri}: its data would never come" in err


def test_model_live_then_check_with_no_master(graph, write, tmp_path):
    out_file = str(tmp_path / "robot.yaml")
    code, _, err = rubass(graph, "model", "--live", "-o", out_file)
    assert code == 0, err
    text = open(out_file).read()
    assert "/acme/pack: acme_msgs/Pack" in text and "acme_msgs/Cell: |" in text
    assert "    type: sensor_msgs/JointState\n    units:\n      position: rad\n      velocity: rad/s" in text
    assert "- /driver" in text
    graph.stop()  # no ROS running from here on
    path = write("s.rbs", f'import "{LIB}";\naction primitive stop;\n'
                          "entity base: driver {\n  rules:\n    r: topic /acme/pack.pack_voltage > 3 V;\n}\n"
                          "if (base.r) then { stop; }\n")
    code, out, err = rubass(graph, "check", "--model", out_file, path)
    assert code == 0 and "warning" not in err, err


def test_no_master_is_a_clear_error(ros, write):
    path = write("s.rbs", f'import "{LIB}";\naction primitive stop;\n'
                          "entity e { rules: r: topic /x.data > 1; }\nif (e.r) then { stop; }\n")
    code, _, err = rubass(ros, "check", "--live", "--master", "http://127.0.0.1:9", path)
    assert code == 2 and "no ROS master at http://127.0.0.1:9" in err and "Traceback" not in err


def test_monitor_refuses_a_library_field_its_type_lacks_at_start_and_at_reload(ros, tmp_path):
    from rosharness import LIB as GOOD_LIB
    from rosharness import spec as write_spec
    from rosharness import wait_log

    bad = GOOD_LIB.replace("message: {data: true}", "message: {dat: true}")
    assert bad != GOOD_LIB
    body = "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { brake; }\n"
    path = write_spec(tmp_path, body, lib=bad)
    mon = ros.monitor(path)  # up (its services answer), but not enforcing
    wait_log(mon, ros, "std_msgs/Bool has no field 'dat'; did you mean 'data'?")
    assert f"{tmp_path / 'lib.yaml'}:" in ros.log(mon)
    write_spec(tmp_path, body)
    time.sleep(0.1)
    out = ros.call("/rubass/reload")
    assert "True" in out.stdout, out.stdout
    (tmp_path / "lib.yaml").write_text(bad)
    time.sleep(0.1)
    out = ros.call("/rubass/reload")
    assert "False" in out.stdout and "has no field 'dat'" in out.stdout, out.stdout
    assert mon.poll() is None


def test_a_hung_master_is_an_error_not_a_hang(ros, write):
    import signal

    path = write("s.rbs", f'import "{LIB}";\naction primitive stop;\n'
                          "entity e { rules: r: topic /x.data > 1; }\nif (e.r) then { stop; }\n")
    os.kill(ros.master.process.pid, signal.SIGSTOP)
    try:
        code, _, err = rubass(ros, "check", "--live", path)  # the master's calls time out after 2 s
    finally:
        os.kill(ros.master.process.pid, signal.SIGCONT)
    assert code == 2 and f"no ROS master at {ros.master.uri}" in err, err
