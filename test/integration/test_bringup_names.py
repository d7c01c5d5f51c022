"""The monitor in a robot's bringup, as an acceptance sweep of launch files found it: `<param
value="[stop]">` in a `<node>` (roslaunch hands over the string "[stop]") was refused as the action
"[stop]"; under a namespace and a remap, messages named topics as the spec spells them, not the topics
the monitor subscribes and publishes to (an engineer looked at the wrong one); a relative ~spec was looked
for in $ROS_HOME with no word of it."""
import json
import os
import signal

import pytest

from conftest import ROOT

pytestmark = pytest.mark.ros

PY = "/usr/bin/python3"
LIB = ("actions:\n  stop: {plugin: publish, topic: safety_cmd, type: geometry_msgs/Twist, message: {}, rate: 20 Hz}\n"
       "  crawl: {plugin: limit, input: nav_vel, topic: crawl_out, linear_x: [-0.1 m/s, 0.1 m/s]}\n")
SPEC = ('import "lib.yaml";\naction primitive stop, crawl;\n'
        "entity base { rules: fast: topic cmd_vel.linear.x > 1.0 m/s; odd: topic odom.twist.twist.linear.x > 5 m/s; }\n"
        "if (base.fast or base.odd) then { stop; crawl; }\n")


def test_a_namespaced_remapped_monitor_names_the_topics_it_uses_and_reads_a_list_param_written_in_a_string(ros, tmp_path):
    (tmp_path / "lib.yaml").write_text(LIB)
    (tmp_path / "safety.rbs").write_text(SPEC)
    bringup = tmp_path / "bringup.launch"
    bringup.write_text(f"""<launch>
  <group ns="robot4">
    <node pkg="rubass" type="monitor" name="rubass" output="screen">
      <param name="spec" value="{tmp_path / 'safety.rbs'}"/>
      <param name="overload_actions" value="[stop]"/>
      <remap from="cmd_vel" to="/base/cmd_vel"/>
      <remap from="nav_vel" to="planner/cmd_vel"/>
    </node>
  </group>
</launch>
""")
    ros.env["ROS_PACKAGE_PATH"] = ROOT + os.pathsep + ros.env.get("ROS_PACKAGE_PATH", "/usr/share")
    launch = ros.spawn(["roslaunch", "--wait", str(bringup)], "roslaunch")
    try:
        ros.wait_service("/robot4/rubass/reset", launch, timeout=30)
        rec = ros.probe({"listen": [{"topic": "/robot4/rubass/events", "type": "std_msgs/String"},
                                    {"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                         "advertise": [{"topic": "/base/cmd_vel", "type": "geometry_msgs/Twist"},
                                       {"topic": "/robot4/planner/cmd_vel", "type": "std_msgs/String"}],
                         "steps": [{"wait_subscribers": "/base/cmd_vel"}, {"wait_subscribers": "/robot4/planner/cmd_vel"},
                                   {"sleep": 1.2}, {"publish": "/base/cmd_vel", "msg": {"linear": {"x": 2.0}}},
                                   {"publish": "/robot4/planner/cmd_vel", "msg": {"data": "x"}},
                                   {"wait": "/robot4/rubass/events", "timeout": 5}, {"sleep": 2.5}]})
        log = ros.log(launch)
        assert "FATAL" not in log and "names [stop]" not in log, log  # "~overload_actions names [stop], which …" before
        events = [json.loads(r["msg"]["data"]) for r in rec if r["kind"] == "recv" and "events" in r["topic"]]
        assert events and events[0]["cause"] == "message on /base/cmd_vel", events  # was "message on cmd_vel"
        values = {v["key"]: v["value"] for r in rec if r["kind"] == "recv" and r["topic"] == "/diagnostics"
                  for s in r["msg"]["status"] for v in s["values"]}
        assert values.get("odd unknown because") == "no message on /robot4/odom (odom in the spec) yet", values
        # the stop reaches no one: said of the topic it is published on
        assert "no node subscribes to /robot4/safety_cmd (safety_cmd in the action library)" in log, log
        assert ("/robot4/planner/cmd_vel (nav_vel in the action library) carries std_msgs/String, not "
                "geometry_msgs/Twist") in log, log  # the limit's input, remapped
        assert "Traceback" not in log
    finally:
        launch.send_signal(signal.SIGINT)
        launch.wait(20)


def test_a_relative_spec_that_is_missing_says_from_which_folder_it_was_taken(ros, tmp_path):
    home = tmp_path / "node_cwd"
    home.mkdir()
    mon = ros.spawn([PY, os.path.join(ROOT, "scripts", "monitor"), "_spec:=../safety/safety.rbs"], "monitor",
                    cwd=str(home))
    try:
        ros.wait_service("/rubass/reset", mon)  # up, not enforcing: a reload may bring the file
        import rosharness
        rosharness.wait_log(mon, ros, "relative path")
        log = ros.log(mon)
        assert f"{tmp_path}/safety/safety.rbs: error: cannot read spec: no such file" in log, log
        assert (f"(~spec '../safety/safety.rbs' is a relative path, taken from the monitor's working directory "
                f"{home}: roslaunch starts a node in $ROS_HOME") in log, log
        # the file is written where it was looked for: a reload enforces it
        (tmp_path / "safety").mkdir()
        (tmp_path / "lib.yaml").write_text(LIB)
        (tmp_path / "safety" / "safety.rbs").write_text(SPEC.replace('"lib.yaml"', '"../lib.yaml"'))
        out = ros.call("/rubass/reload")
        assert "reloaded" in out.stdout.lower() or "true" in out.stdout.lower(), (out.stdout, ros.log(mon))
    finally:
        mon.send_signal(signal.SIGTERM)
        mon.wait(15)
