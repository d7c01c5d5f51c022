"""The monitor's path and list parameters as a bringup launch file gives them (an acceptance sweep of
launch files, namespaces and remapping): `<param value="[stop]">` hands over the string "[stop]",
which was taken as the action "[stop]"; a relative ~spec was looked for in the node's working
directory ($ROS_HOME under roslaunch) with no word of it; `package://` was not understood in ~actions,
~spec or `--actions`. And topics are named as the robot names them, a namespace or a remap applied."""
import os

import pytest

from rubass.actions.dispatch import Dispatcher
from rubass.actions.status import topic_shown, unknown_reasons
from rubass.engine.events import Event
from rubass.engine.loop import Message, NodeSample
from rubass.lang import check_text, load_spec
from rubass.lang.paths import clear_cache
from rubass.ros.params import ParamError, read_config, relative_note


def _config(**params):
    return read_config(lambda name, default: params.get(name, default))


@pytest.mark.parametrize("text, names", [("[stop]", ["stop"]), ("[stop, warn]", ["stop", "warn"]),
                                         ("['stop', \"warn\"]", ["stop", "warn"]), ("stop, warn", ["stop", "warn"]),
                                         ("stop warn", ["stop", "warn"]), ("[]", [])])
def test_a_list_written_in_one_string_is_the_list_it_writes(text, names):
    config = _config(spec="/s.rbs", overload_actions=text, error_actions=text)
    assert config.overload_actions == names and config.error_actions == names


@pytest.mark.parametrize("text, said", [("[stop", "is not a YAML list at column"), ("[1, 2]", "got [1, 2]"),
                                        ("[stop, [warn]]", "got ['stop', ['warn']]")])
def test_a_broken_list_in_one_string_is_a_param_error_naming_it(text, said):
    with pytest.raises(ParamError) as err:
        _config(spec="/s.rbs", overload_actions=text)
    assert "~overload_actions must be a list of action names" in str(err.value) and said in str(err.value)


def test_library_paths_in_one_string_written_as_a_list(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    config = _config(spec="/s.rbs", actions="[a.yaml, /x/b.yaml]")
    assert config.actions == [str(tmp_path / "a.yaml"), "/x/b.yaml"]


def test_a_relative_spec_is_made_absolute_and_a_missing_one_says_where_it_was_looked_for(tmp_path, monkeypatch):
    home = tmp_path / "ros_home"
    home.mkdir()
    monkeypatch.chdir(home)  # roslaunch starts a node in $ROS_HOME
    config = _config(spec="../safety/safety.rbs", actions=["lib.yaml", "/abs/lib.yaml"])
    assert config.spec == str(tmp_path / "safety" / "safety.rbs")  # as reloads read it, whatever the cwd then
    assert config.actions == [str(home / "lib.yaml"), "/abs/lib.yaml"]
    note = relative_note(config)
    assert note.startswith("(~spec '../safety/safety.rbs', ~actions 'lib.yaml' are relative paths, taken from "
                           f"the monitor's working directory {home}: roslaunch starts a node in $ROS_HOME"), note
    assert "$(find PKG)" in note
    (tmp_path / "safety").mkdir()
    (tmp_path / "safety" / "safety.rbs").write_text("")
    assert relative_note(config).startswith("(~actions 'lib.yaml' is a relative path"), relative_note(config)
    (home / "lib.yaml").write_text("")
    assert relative_note(config) == ""  # every file there: nothing to explain


def test_absolute_paths_get_no_note(tmp_path):
    config = _config(spec=str(tmp_path / "missing.rbs"), actions=[str(tmp_path / "missing.yaml")])
    assert config.relative == () and relative_note(config) == ""


def _package(tmp_path, monkeypatch):
    pkg = tmp_path / "src" / "my_robot"
    (pkg / "safety").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package format='2'><name>my_robot</name></package>")
    (pkg / "safety" / "lib.yaml").write_text("actions:\n  stop: {plugin: log, level: error}\n")
    (pkg / "safety" / "s.rbs").write_text("action primitive stop;\nentity e { rules: r: true; }\nif (e.r) then { stop; }\n")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "src"))
    clear_cache()
    return pkg


def test_package_paths_in_spec_and_actions(tmp_path, monkeypatch):
    pkg = _package(tmp_path, monkeypatch)
    config = _config(spec="package://my_robot/safety/s.rbs", actions="[package://my_robot/safety/lib.yaml]")
    assert config.spec == str(pkg / "safety" / "s.rbs") and config.actions == [str(pkg / "safety" / "lib.yaml")]
    assert config.relative == ()
    assert load_spec(config.spec, config.actions).actions["stop"].plugin == "log"
    with pytest.raises(ParamError) as err:
        _config(spec="package://no_such_pkg/s.rbs")
    assert str(err.value).startswith("~spec: cannot use 'package://no_such_pkg/s.rbs': ROS package 'no_such_pkg' "
                                     "not found on ROS_PACKAGE_PATH"), str(err.value)


def test_check_actions_takes_a_package_path_and_names_a_missing_package(tmp_path, monkeypatch):
    pkg = _package(tmp_path, monkeypatch)
    spec = str(pkg / "safety" / "s.rbs")
    assert load_spec(spec, ["package://my_robot/safety/lib.yaml"]).actions["stop"].plugin == "log"
    from rubass.lang import SpecError
    with pytest.raises(SpecError) as err:
        load_spec(spec, ["package://nope/lib.yaml"])
    text = "\n".join(d.message for d in err.value.diagnostics)
    assert "cannot use the action library 'package://nope/lib.yaml': ROS package 'nope' not found" in text
    assert "not defined in any action library" not in text  # its actions are not "undefined": the error says why


def test_a_topic_is_shown_as_the_robot_names_it():
    assert topic_shown("cmd_vel", "/cmd_vel") == "/cmd_vel"  # at the root: only the '/'
    assert topic_shown("/cmd_vel", "/cmd_vel") == "/cmd_vel"
    assert topic_shown("cmd_vel", "/base/cmd_vel") == "/base/cmd_vel (cmd_vel in the spec)"
    assert topic_shown("safety_cmd", "/robot4/safety_cmd", "the action library") == \
        "/robot4/safety_cmd (safety_cmd in the action library)"
    assert topic_shown("cmd_vel", None) == "cmd_vel"


def test_status_and_events_name_the_topic_the_monitor_subscribes_to():
    spec = check_text("action primitive stop;\nentity e { rules: fast: topic cmd_vel.linear.x > 1 m/s; }\n"
                      "if (e.fast) then { stop; }\n",
                      extra_libraries=[os.path.join(os.path.dirname(__file__), "..", "..", "config", "fig2_actions.yaml")])
    topics = {"cmd_vel": {"messages": 0, "errors": [], "resolved": "/base/cmd_vel"}}
    assert unknown_reasons(spec, "e.fast", topics, {}, {}) == ["no message on /base/cmd_vel (cmd_vel in the spec) yet"]
    records = []
    d = Dispatcher({}, records.append, lambda: 1.0, {"cmd_vel": "/base/cmd_vel"}.get)
    d.report_event(Event(1.0, "start", 1), spec.behaviours[0], ("e.fast",), Message("cmd_vel", 1.0, None, 1.0, 0))
    assert records[-1]["cause"] == "message on /base/cmd_vel", records


def test_status_and_events_name_a_node_as_the_robot_names_it():
    """A sweep of namespaces: causes and unknown reasons named a node as the spec spelled it (`ctl`)
    while the monitor sampled /robot1/ctl."""
    spec = check_text("action primitive stop;\nentity e: ctl { rules: hot: cpu(node ctl) > 50 %; }\n"
                      "if (e.hot) then { stop; }\n",
                      extra_libraries=[os.path.join(os.path.dirname(__file__), "..", "..", "config", "fig2_actions.yaml")])
    nodes = {"ctl": {"why": "the master cannot be reached (refused) and the node was never seen",
                     "resolved": "/robot1/ctl"}}
    assert unknown_reasons(spec, "e.hot", {}, nodes, {}) == [
        "node /robot1/ctl (ctl in the spec): the master cannot be reached (refused) and the node was never seen"]
    records = []
    d = Dispatcher({}, records.append, lambda: 1.0, {"ctl": "/robot1/ctl"}.get)
    d.report_event(Event(1.0, "start", 1), spec.behaviours[0], ("e.hot",), NodeSample("ctl", 1.0, True, 60.0, 0))
    assert records[-1]["cause"] == "node sample of /robot1/ctl", records


def test_an_absolute_or_package_path_needs_no_working_directory(tmp_path, monkeypatch):
    """A re-sweep: started in a folder since removed, the monitor refused an absolute ~spec as relative."""
    pkg = _package(tmp_path, monkeypatch)

    def gone():
        raise FileNotFoundError(2, "No such file or directory")

    monkeypatch.setattr(os, "getcwd", gone)
    config = _config(spec=str(pkg / "safety" / "s.rbs"), actions=["package://my_robot/safety/lib.yaml"])
    assert config.spec == str(pkg / "safety" / "s.rbs") and config.relative == ()
    with pytest.raises(ParamError) as err:
        _config(spec="s.rbs")
    assert "'s.rbs' is relative, and the monitor's working directory no longer exists" in str(err.value)


def test_a_data_error_names_the_topic_the_monitor_reads():
    spec = check_text("action primitive stop;\nentity e { rules: fast: topic cmd_vel.linear.x > 1 m/s; }\n"
                      "if (e.fast) then { stop; }\n",
                      extra_libraries=[os.path.join(os.path.dirname(__file__), "..", "..", "config", "fig2_actions.yaml")])
    errors = {("cmd_vel", "('linear', 'x')"): "std_msgs/String has no field 'linear'"}
    topics = {"cmd_vel": {"messages": 3, "errors": [], "resolved": "/base/cmd_vel"}}
    assert unknown_reasons(spec, "e.fast", topics, {}, errors) == [
        "rule 'e.fast' reads cmd_vel.linear.x (on /base/cmd_vel): std_msgs/String has no field 'linear'"]
    topics["cmd_vel"]["resolved"] = "/cmd_vel"  # at the root: only the '/'
    assert unknown_reasons(spec, "e.fast", topics, {}, errors) == [
        "rule 'e.fast' reads /cmd_vel.linear.x: std_msgs/String has no field 'linear'"]


def test_commands_and_test_files_take_package_paths(tmp_path, monkeypatch, capsys):
    """A re-sweep: `rubass check package://…` said "no such file" of a file that exists, and a test file's
    `spec:`/`actions:` made it `<dir>/package:/…`."""
    from rubass.cli import main

    pkg = _package(tmp_path, monkeypatch)
    (pkg / "safety" / "t.test.yaml").write_text(
        "spec: package://my_robot/safety/s.rbs\nactions: [package://my_robot/safety/lib.yaml]\ntests:\n"
        "  - name: starts\n    duration: 1 s\n    expect:\n      - {at: 0 s, start: 1}\n")
    monkeypatch.chdir(tmp_path)
    assert main(["check", "package://my_robot/safety/s.rbs", "--actions", "package://my_robot/safety/lib.yaml"]) == 0
    assert main(["test", str(pkg / "safety" / "t.test.yaml")]) == 0, capsys.readouterr()
    capsys.readouterr()
    assert main(["check", "package://nope/s.rbs"]) == 1
    err = capsys.readouterr().err
    assert "package://nope/s.rbs: error: cannot read spec: ROS package 'nope' not found on ROS_PACKAGE_PATH" in err, err
