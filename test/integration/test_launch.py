"""launch/monitor.launch included from a robot's launch file, under roslaunch."""
import os
import signal
import subprocess

import pytest

from conftest import ROOT

pytestmark = pytest.mark.ros


def test_monitor_launch_included_from_another_launch_file(ros, tmp_path):
    (tmp_path / "lib.yaml").write_text("actions:\n  stop: {plugin: publish, topic: /safety_cmd, "
                                       "type: geometry_msgs/Twist, message: {}, rate: 20 Hz, latch: true}\n")
    spec = tmp_path / "safety.rbs"
    spec.write_text('import "lib.yaml";\naction primitive stop;\n'
                    "entity base { rules: fast: topic /cmd_vel.linear.x > 1.0 m/s; }\nif (base.fast) then { stop; }\n")
    bringup = tmp_path / "bringup.launch"
    bringup.write_text(f"""<launch>
  <include file="$(find rubass)/launch/monitor.launch">
    <arg name="spec" value="{spec}"/>
    <arg name="rate" value="100"/>
  </include>
</launch>
""")
    ros.env["ROS_PACKAGE_PATH"] = ROOT + os.pathsep + ros.env.get("ROS_PACKAGE_PATH", "/usr/share")
    launch = ros.spawn(["roslaunch", "--wait", str(bringup)], "roslaunch")
    ros.wait_service("/rubass/reset", launch, timeout=30)
    rec = ros.probe({"listen": [{"topic": "/safety_cmd", "type": "geometry_msgs/Twist"}],
                     "advertise": [{"topic": "/cmd_vel", "type": "geometry_msgs/Twist"}],
                     "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_publishers": "/safety_cmd"}, {"sleep": 0.3},
                               {"publish": "/cmd_vel", "msg": {"linear": {"x": 2.0}}},
                               {"wait": "/safety_cmd", "timeout": 5}]})
    assert any(r["kind"] == "recv" for r in rec), ros.log(launch)
    launch.send_signal(signal.SIGINT)
    assert launch.wait(20) == 0


def test_kobuki_sim_launch_stops_the_simulated_base_on_a_drift_fault(ros, tmp_path):
    ros.env["ROS_PACKAGE_PATH"] = ROOT + os.pathsep + ros.env.get("ROS_PACKAGE_PATH", "/usr/share")
    launch = ros.spawn(["roslaunch", "--wait", "rubass", "kobuki_sim.launch"], "roslaunch")
    ros.wait_service("/rubass/reset", launch, timeout=30)
    rec = ros.probe({"listen": [{"topic": "/mobile_base/commands/safety_velocity", "type": "geometry_msgs/Twist"},
                                {"topic": "/odom", "type": "nav_msgs/Odometry"}],
                     "advertise": [{"topic": "/sim/fault", "type": "std_msgs/String"}],
                     "steps": [{"wait_subscribers": "/sim/fault", "count": 3}, {"wait": "/odom", "timeout": 10},
                               {"sleep": 1.0}, {"mark": "fault"},
                               {"publish": "/sim/fault", "msg": {"data": '{"drift": "linear", "rate": 0.5}'}},
                               {"wait": "/mobile_base/commands/safety_velocity", "timeout": 10}]})
    fault = next(r["wall"] for r in rec if r["kind"] == "mark")
    stops = [r for r in rec if r["kind"] == "recv" and r["topic"] == "/mobile_base/commands/safety_velocity"]
    assert stops, ros.log(launch)
    # the drift passes 0.5 m/s about 0.4 s after the fault, and the rule wants 1 s of it
    assert 1.0 < stops[0]["wall"] - fault < 3.0
    launch.send_signal(signal.SIGINT)
    assert launch.wait(20) == 0


def test_monitor_launch_clears_parameters_an_earlier_launch_left_and_keeps_the_robots_own(ros, tmp_path):
    """An acceptance sweep: a `state_file` false left on the master by an earlier launch (or a
    `rosparam set`) lingered into the next launch, which then kept no latch across restarts."""
    import rosgraph

    master = rosgraph.Master("/test", master_uri=ros.env["ROS_MASTER_URI"])
    master.setParam("/rubass/state_file", False)  # from a test session
    master.setParam("/rubass/rat", 5)  # a typo, by hand
    spec = tmp_path / "safety.rbs"
    spec.write_text("entity base { rules: fast: topic /cmd_vel.linear.x > 1.0 m/s; }\n")
    bringup = tmp_path / "bringup.launch"
    bringup.write_text(f"""<launch>
  <include file="$(find rubass)/launch/monitor.launch">
    <arg name="spec" value="{spec}"/>
  </include>
  <param name="rubass/diagnostics_rate" value="2"/>
</launch>
""")
    ros.env["ROS_PACKAGE_PATH"] = ROOT + os.pathsep + ros.env.get("ROS_PACKAGE_PATH", "/usr/share")
    launch = ros.spawn(["roslaunch", "--wait", str(bringup)], "roslaunch")
    try:
        ros.wait_service("/rubass/reset", launch, timeout=30)
        names = master.getParamNames()
        assert "/rubass/state_file" not in names and "/rubass/rat" not in names, names
        assert master.getParam("/rubass/diagnostics_rate") == 2  # the robot's own, set after the clearing
        assert "LATCH PERSISTENCE OFF" not in ros.log(launch) and "unknown parameter" not in ros.log(launch)
    finally:
        launch.send_signal(signal.SIGINT)
        launch.wait(20)


def test_ros_args_lists_only_spec_as_required():
    out = subprocess.run(["roslaunch", "--ros-args", os.path.join(ROOT, "launch", "monitor.launch")],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    required = out.stdout.split("Optional Arguments:")[0]
    assert "spec:" in required and "nice:" not in required and "state_file:" not in required, out.stdout
    assert "  nice (default \"as_started\")" in out.stdout and "  state_file (default \"default\")" in out.stdout
    assert "  receiver (default \"one_thread\")" in out.stdout, out.stdout
