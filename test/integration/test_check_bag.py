"""`rubass check --bag`, `rubass model --bag` and `rubass check --model` on the shared real recordings."""
import os
import subprocess
import sys

import pytest

pytest.importorskip("rosbag")

from conftest import ROOT, shared_path  # noqa: E402
from rubass.lang.units import dim  # noqa: E402

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")


def rubass(*args):
    proc = subprocess.run([sys.executable, "-m", "rubass", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=120)
    return proc.returncode, proc.stdout, proc.stderr


def spec(write, rules, name="s.rbs"):
    return write(name, f'import "{LIB}";\naction primitive stop;\nentity e {{\n  rules:\n{rules}}}\n'
                       "if (e.r) then { stop; }\n")


def test_bag_model_of_the_turtlebot_recording():
    from rubass.ros.model_sources import bag_model

    m = bag_model(shared_path("data", "turtlebot3_sim.bag"))
    assert m.topics == {"/cmd_vel": "geometry_msgs/Twist", "/imu": "sensor_msgs/Imu",
                        "/joint_states": "sensor_msgs/JointState", "/odom": "nav_msgs/Odometry",
                        "/scan": "sensor_msgs/LaserScan"}
    assert m.nodes is None and m.undefined_types() == []
    assert m.field("/odom", ("twist", "twist", "linear", "x")).dim == dim(m=1, s=-1)
    assert m.field("/odom", ("pose", "pose", "position", "y")).dim == dim(m=1)
    assert m.field("/scan", ("ranges",)).kind == "array"
    assert m.field("/imu", ("linear_acceleration", "z")).dim == dim(m=1, s=-2)
    assert m.field("/joint_states", ("name", 0)).kind == "str"
    assert m.has_stamp("/odom") and not m.has_stamp("/cmd_vel")


def test_bag_model_of_the_husky_recording():
    from rubass.ros.model_sources import bag_model

    m = bag_model(shared_path("data", "husky_outdoor_2015.bag"))
    assert m.type_of("/fix") == "sensor_msgs/NavSatFix"
    assert m.field("/fix", ("altitude",)).dim == dim(m=1)
    assert m.field("/fix", ("latitude",)).dim == dim(geo_deg=1)
    assert m.field("/fix", ("status", "status")).kind == "num"
    assert m.field("/imu/data", ("angular_velocity", "z")).dim == dim(rad=1, s=-1)
    assert m.field("/husky_velocity_controller/odom", ("twist", "linear")).kind == "missing"


def test_check_bag_warns_of_missing_topics_and_exits_0(write):
    bag = shared_path("data", "turtlebot3_sim.bag")
    path = spec(write, "    r: abs(topic /cmd_vell.linear.x) > 0.5 m/s;\n    q: age(topic /odom) > 1 s;\n")
    code, out, err = rubass("check", "--bag", bag, path)
    assert code == 0, err
    assert f"{path}:5:12: warning: topic '/cmd_vell' is not in the recording turtlebot3_sim.bag; " \
           "did you mean '/cmd_vel'?" in err
    assert "/odom" not in err and "ok (" in out


def test_model_file_from_a_bag_checks_without_the_bag(write, tmp_path):
    bag = shared_path("data", "husky_outdoor_2015.bag")
    out_file = str(tmp_path / "husky.yaml")
    code, _, err = rubass("model", "--bag", bag, "-o", out_file)
    assert code == 0, err
    assert "3 topics" in err
    text = open(out_file).read()
    assert "/fix: sensor_msgs/NavSatFix" in text and "sensor_msgs/NavSatStatus: |" in text
    path = spec(write, "    r: topic /imu/data.angular_velocity.z > 1 rad/s;\n    q: topic /fx.altitude > 3 m;\n")
    code, out, err = rubass("check", "--model", out_file, path)
    assert code == 0, err
    assert f"{path}:6:8: warning: topic '/fx' is not in the system model {out_file} (from recording " \
           "husky_outdoor_2015.bag); did you mean '/fix'?" in err


def test_bad_sources_are_reported_not_raised(write, tmp_path):
    path = spec(write, "    r: topic /cmd_vel.linear.x > 0.5 m/s;\n")
    code, _, err = rubass("check", "--bag", str(tmp_path / "none.bag"), path)
    assert code == 2 and "none.bag: no such file" in err and "Traceback" not in err
    bad = write("robot.yaml", "topics:\n  /cmd_vel: Twist\n")
    code, _, err = rubass("check", "--model", bad, path)
    assert code == 1 and f"{bad}:2:13: error: the type of topic '/cmd_vel' must be a message type" in err
    code, _, err = rubass("check", "--model", bad, "--bag", str(tmp_path / "x.bag"), path)
    assert code == 2 and "not allowed with" in err


def test_library_types_checked_by_plain_check(write):
    lib = write("lib.yaml", "actions:\n  stop:\n    plugin: publish\n    topic: /cmd_vel\n"
                            "    type: geometry_msgs/Twist\n    message: {linear: {x: 0, q: 1}}\n"
                            "  brake: {plugin: service, service: /brake, type: std_srvs/Trigger, request: {now: 1}}\n")
    path = write("s.rbs", 'import "lib.yaml";\naction primitive stop, brake;\n'
                          "entity e { rules: r: topic /x.data > 1; }\nif (e.r) then { stop; brake; }\n")
    code, _, err = rubass("check", path)
    assert code == 1, err
    assert f"{lib}:6:30: error: action 'stop': geometry_msgs/Vector3 has no field 'q' (its fields: x, y, z)" in err
    assert "message: {linear: {x: 0, q: 1}}" in err  # the YAML line, with a caret
    assert f"{lib}:7:79: error: action 'brake': std_srvs/TriggerRequest has no field 'now'" in err
    assert f"{path}: 2 errors" in err


def test_check_bag_field_errors_at_the_spec_line(write):
    bag = shared_path("data", "turtlebot3_sim.bag")
    path = spec(write, "    r: topic /cmd_vel.linear.x > 3 s;\n"
                       "    typo: topic /odom.twist.linear.x > 1 m/s;\n"
                       "    arr: topic /scan.ranges > 1 m;\n"
                       "    name: topic /odom.header.frame_id > 2;\n"
                       "    msg: topic /odom.pose.pose > 2;\n"
                       "    ok: topic /cmd_vel.linear.x > 0.5 and min(topic /scan.ranges) < 30 cm;\n"
                       "    sub: topic /scan.angle_min.x > 0;\n"
                       "    eq: topic /odom.header.frame_id == 2 or topic /odom.header.frame_id == \"odom\";\n")
    code, _, err = rubass("check", "--bag", bag, path)
    assert code == 1
    assert f"{path}:5:32: error: compares a speed with a time" in err
    assert f"{path}:6:11: error: 'twist' (geometry_msgs/TwistWithCovariance) has no field 'linear'; " \
           "did you mean 'twist.twist.linear'?" in err
    assert f"{path}:7:10: error: 'topic /scan.ranges' is an array (float32[])" in err
    assert f"{path}:8:11: error: '>' needs a number, not a string" in err
    assert f"{path}:9:10: error: 'topic /odom.pose.pose' is a message, not a value: it is a geometry_msgs/Pose" in err
    assert "        typo: topic /odom.twist.linear.x > 1 m/s;\n              ^" in err  # the line and a caret
    assert f"{path}:11:10: error: 'angle_min' is a float32, not a message: it has no field 'x'" in err
    assert f"{path}:12:37: error: '==' compares a string with a number" in err
    assert f"{path}: 7 errors" in err  # line 10 is right: a bare 0.5 adopts m/s, 30 cm fits ranges


def test_the_same_spec_without_a_model_is_accepted(write):
    path = spec(write, "    r: topic /cmd_vel.linear.x > 3 s;\n    typo: topic /odom.twist.linear.x > 1 m/s;\n")
    code, out, err = rubass("check", path)
    assert code == 0 and "ok (" in out, err


def test_model_file_units_of_custom_fields(write, tmp_path):
    model = write("robot.yaml", "topics:\n  /bms: {type: acme_msgs/Pack, units: {pack_voltage: V}}\n"
                                "definitions:\n  acme_msgs/Pack: |\n    float32 pack_voltage\n    float32 temp\n"
                                "units:\n  acme_msgs/Pack: {temp: degC}\n")
    good = spec(write, "    r: topic /bms.pack_voltage < 22 V or topic /bms.temp > 60 degC;\n", "good.rbs")
    code, out, err = rubass("check", "--model", model, good)
    assert code == 0 and "warning" not in err, err
    bad = spec(write, "    r: topic /bms.pack_voltage < 22 A or topic /bms.temp > 60 s;\n", "bad.rbs")
    code, _, err = rubass("check", "--model", model, bad)
    assert code == 1
    assert f"{bad}:5:32: error: compares a voltage with a current" in err
    assert f"{bad}:5:58: error: compares a temperature with a time" in err


def test_the_worked_example_of_docs_model_md():
    """docs/model.md prints what `rubass check --bag` says of docs/examples/model/safety.rbs."""
    import re

    bag = shared_path("data", "turtlebot3_sim.bag")
    folder = os.path.join(ROOT, "docs", "examples", "model")
    code, _, err = rubass("check", "--bag", bag, os.path.join(folder, "safety.rbs"))
    doc = open(os.path.join(ROOT, "docs", "model.md"), encoding="utf-8").read()
    printed = re.search(r"\$ \S*rubass check --bag turtlebot3_sim.bag safety.rbs\n(.*?)```", doc, re.S).group(1)
    assert code == 1
    assert err.replace(folder + os.sep, "") == printed


def test_urdf_gives_joint_state_units(write):
    bag = shared_path("data", "turtlebot3_sim.bag")
    urdf = write("r.urdf", '<robot name="tb3"><link name="b"/><link name="l"/><link name="r"/>'
                           '<joint name="wheel_left_joint" type="continuous"><parent link="b"/><child link="l"/></joint>'
                           '<joint name="wheel_right_joint" type="continuous"><parent link="b"/><child link="r"/>'
                           '</joint></robot>')
    path = spec(write, "    r: abs(topic /joint_states.velocity[0]) > 3 m/s;\n")
    code, _, err = rubass("check", "--bag", bag, path)
    assert code == 0, err  # joint kinds unknown: no dimension
    code, _, err = rubass("check", "--bag", bag, "--urdf", urdf, path)
    assert code == 1 and f"{path}:5:45: error: compares a" in err and "angular speed with a speed" in err, err
    code, _, err = rubass("check", "--bag", bag, "--urdf", path, path)
    assert code == 2 and "not valid XML" in err
