"""`rubass check` fixes of an acceptance sweep (pure, no ROS): a custom plugin whose package this Python
cannot find is a warning at its `plugin:` value (the monitor would refuse to start), without running any
of the package; an action undefined because the spec's import failed says that the import failed. On bags
written with the rosbag API (no master; skipped without ROS 1): `check --bag` reads the spec against every
type recorded on a topic; `report` refuses a bag given as the spec, and prints the spec's warnings and
replay's warning for a node no recorded sample covers."""
import json
import os

import pytest

from conftest import ROOT
from rubass.cli import main
from rubass.lang import SpecError, check_text
from rubass.lang.libcheck import plugin_module_warnings
from rubass.lang.library import parse_library
from rubass.lang.source import Source

SPEC = 'import "lib.yaml";\naction primitive stop;\nentity e { rules: fast: topic /v.data > 1; }\n' \
       'if (e.fast) then { stop; }\n'
LIB = ("actions:\n"
       "  stop: {plugin: log, level: warn}\n"
       "  horn:\n"
       "    plugin: {module}:Horn   # a custom plugin\n"
       "    volume: 0.8\n")


def check(tmp_path, capsys, module):
    (tmp_path / "lib.yaml").write_text(LIB.replace("{module}", module))
    (tmp_path / "s.rbs").write_text(SPEC)
    status = main(["check", str(tmp_path / "s.rbs")])
    out = capsys.readouterr()
    return status, out.out, out.err


# -- a custom plugin whose package cannot be found ----------------------------------------------------

def test_a_custom_plugin_whose_package_is_not_here_is_a_warning_at_its_plugin_value(tmp_path, capsys):
    status, out, err = check(tmp_path, capsys, "no_such_robot_pkg_h2.safety")
    assert status == 0, err  # a warning: on the robot its package may be on the path
    assert "ok (" in out
    lib = str(tmp_path / "lib.yaml")
    assert (f"{lib}:4:13: warning: action 'horn': plugin module 'no_such_robot_pkg_h2.safety' cannot be found "
            f"here (no package or module 'no_such_robot_pkg_h2' on this Python's path): the monitor will refuse "
            f"to start unless it can import it there") in err  # before: nothing, and the monitor refused
    assert "    plugin: no_such_robot_pkg_h2.safety:Horn" in err and "\n                ^" in err


def test_a_findable_package_is_looked_up_not_run(tmp_path, capsys, monkeypatch):
    pkg = tmp_path / "site" / "h2_robot_pkg"
    pkg.mkdir(parents=True)
    ran = tmp_path / "ran"
    (pkg / "__init__.py").write_text(f"open({str(ran)!r}, 'w').write('imported')\n")
    (pkg / "safety.py").write_text(f"open({str(ran)!r}, 'w').write('imported')\n")
    monkeypatch.syspath_prepend(str(tmp_path / "site"))
    status, out, err = check(tmp_path, capsys, "h2_robot_pkg.safety")
    assert status == 0 and "warning" not in err, err
    assert not ran.exists()  # the library's package was found, not imported


def test_built_in_plugins_get_no_such_warning(tmp_path, capsys):
    status, _, err = check(tmp_path, capsys, "rubass.actions.base")  # found: it is this package
    assert status == 0 and "warning" not in err, err
    actions, diags = parse_library(Source("l.yaml", "actions:\n  a: {plugin: log}\n  b: {plugin: publish, "
                                                    "topic: /s, type: std_msgs/Empty, message: {}}\n"))
    assert not diags
    assert plugin_module_warnings(actions, lambda name: False) == []  # only custom plugins are looked up


def test_the_warning_comes_with_the_errors_of_a_spec_that_does_not_check(tmp_path, capsys):
    (tmp_path / "lib.yaml").write_text(LIB.replace("{module}", "no_such_robot_pkg_h2"))
    (tmp_path / "s.rbs").write_text(SPEC.replace("stop; }", "stopp; }"))
    assert main(["check", str(tmp_path / "s.rbs")]) == 1
    err = capsys.readouterr().err
    assert "warning: action 'horn': plugin module 'no_such_robot_pkg_h2' cannot be found here" in err
    assert "s.rbs: 1 error" in err


# -- an import that failed ------------------------------------------------------------------------

def undefined_hint(text, path, extra=()):
    try:
        check_text(text, path, list(extra))
    except SpecError as exc:
        return [d.message for d in exc.diagnostics]
    raise AssertionError("the spec checked")


def test_an_undefined_action_after_a_failed_package_import_says_the_import_failed(tmp_path, monkeypatch):
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "nothing"))
    spec = 'import "package://h2_missing_robot/safety/actions.yaml";\naction primitive stop, warn;\n' \
           'entity e { rules: r: topic /v.data > 1; }\nif (e.r) then { stop; warn; }\n'
    messages = undefined_hint(spec, str(tmp_path / "s.rbs"))
    assert messages[0].startswith("cannot import 'package://h2_missing_robot/safety/actions.yaml': ROS package")
    assert messages[1] == ("action 'stop' is not defined in any action library (its library "
                           "'package://h2_missing_robot/safety/actions.yaml' could not be loaded: see the error "
                           "above)")  # before: "no action library is loaded: add 'import "actions.yaml";' …"
    assert not any("no action library is loaded" in m for m in messages)


def test_a_missing_file_beside_a_loaded_library_is_named_with_it(tmp_path):
    (tmp_path / "lib.yaml").write_text("actions:\n  warn: {plugin: log}\n")
    spec = 'import "lib.yaml";\nimport "gone.yaml";\naction primitive stop, warn;\n' \
           'entity e { rules: r: topic /v.data > 1; }\nif (e.r) then { stop; warn; }\n'
    messages = undefined_hint(spec, str(tmp_path / "s.rbs"))
    assert any(m.startswith("cannot import") and "no such file" in m for m in messages)
    lib = os.path.join(str(tmp_path), "lib.yaml")
    assert (f"action 'stop' is not defined in any action library (its library 'gone.yaml' could not be loaded: "
            f"see the error above; loaded: {lib})") in messages


def test_with_no_import_at_all_the_hint_is_unchanged(tmp_path):
    messages = undefined_hint("action primitive stop;\nentity e { rules: r: topic /v.data > 1; }\n"
                              "if (e.r) then { stop; }\n", str(tmp_path / "s.rbs"))
    assert messages == ["action 'stop' is not defined in any action library (no action library is loaded: add "
                        "'import \"actions.yaml\";' or pass --actions)"]


# -- on recordings written with the rosbag API (no master): check --bag, report --bag ------------------
try:  # ROS 1 only from /usr/bin/python3: these tests are skipped elsewhere
    import rosbag
    import rospy
    from geometry_msgs.msg import Twist
    from std_msgs.msg import Float64, String
except ImportError:
    rosbag = None

def needs_rosbag(test):
    return pytest.mark.ros(pytest.mark.skipif(rosbag is None, reason="needs ROS 1 (rosbag)")(test))
T0 = 1700000000.0
ACTIONS = os.path.join(ROOT, "docs", "examples", "actions.yaml")


def write_bag(path, items):
    with rosbag.Bag(path, "w") as bag:
        for t, topic, msg in items:
            bag.write(topic, msg, rospy.Time.from_sec(T0 + t))
    return path


def two_type_bag(tmp_path):
    """/speed recorded as std_msgs/Float64, then as geometry_msgs/Twist (rosbag's writer keeps one type per
    topic: written under a name of the same length, renamed in the file)."""
    twist = Twist()
    twist.linear.x = 1.0
    pre = write_bag(str(tmp_path / "pre.bag"), [(i * 0.1, "/speed", Float64(data=1.0)) for i in range(10)] +
                    [(1 + i * 0.1, "/speex", twist) for i in range(10)] + [(0.0, "/other", Float64())])
    path = str(tmp_path / "two.bag")
    with open(pre, "rb") as src, open(path, "wb") as out:
        out.write(src.read().replace(b"/speex", b"/speed"))
    return path


def spec_file(write, body, actions="stop"):
    return write("s.rbs", f'import "{ACTIONS}";\naction primitive {actions};\n' + body)


def run(capsys, *argv):
    status = main(list(argv))
    out = capsys.readouterr()
    assert "Traceback" not in out.err, out.err
    return status, out.out, out.err


def checked_against_bag(spec, bag):
    from rubass.ros.model_sources import bag_model, load_spec_against

    try:
        load_spec_against(spec, [], bag_model(bag), bag)
    except SpecError as exc:
        return exc.render()
    return ""


@needs_rosbag
def test_check_bag_reads_the_spec_against_every_recorded_type(write, tmp_path):
    bag = two_type_bag(tmp_path)
    line = "entity e { rules: fast: topic /speed.data > 0.5 for 1 s; }"
    spec = spec_file(write, line + "\nif (e.fast) then { stop; }\n")
    said = checked_against_bag(spec, bag)  # before: the spec checked (only the first type was read)
    assert said.startswith(f"{spec}:3:{line.index('topic') + 1}: error: geometry_msgs/Twist has no field 'data' "
                           "(its fields: linear, angular); /speed is recorded as geometry_msgs/Twist too in two.bag "
                           "(first as std_msgs/Float64): this is the spec read against geometry_msgs/Twist\n"), said
    assert said.count("error:") == 1
    # a spec that does not read the topic, or reads a field both types have... has nothing to hear
    other = write("o.rbs", f'import "{ACTIONS}";\naction primitive stop;\n'
                           "entity e { rules: r: topic /other.data > 0.5; }\nif (e.r) then { stop; }\n")
    assert checked_against_bag(other, bag) == ""


@needs_rosbag
def test_check_bag_says_the_errors_of_both_types_in_one_run(write, tmp_path):
    bag = two_type_bag(tmp_path)
    spec = spec_file(write, "entity e { rules:\n  fast: topic /speed.data > 0.5;\n  bad: topic /speed.nope > 1;\n}\n"
                            "if (e.fast or e.bad) then { stop; }\n")
    said = checked_against_bag(spec, bag)
    assert f"{spec}:5:8: error: std_msgs/Float64 has no field 'nope'" in said
    assert f"{spec}:5:8: error: geometry_msgs/Twist has no field 'nope' (its fields: linear, angular); /speed is " \
           "recorded as geometry_msgs/Twist too" in said
    assert f"{spec}:4:9: error: geometry_msgs/Twist has no field 'data'" in said
    assert said.count("error:") == 3


@needs_rosbag
def test_rubass_check_bag_exits_1_on_another_recorded_type(write, tmp_path, capsys):
    bag = two_type_bag(tmp_path)
    spec = spec_file(write, "entity e { rules: fast: topic /speed.data > 0.5 for 1 s; }\nif (e.fast) then { stop; }\n")
    status, out, err = run(capsys, "check", "--bag", bag, spec)
    assert status == 1 and "ok" not in out, out
    assert "geometry_msgs/Twist has no field 'data'" in err and f"{spec}: 1 error" in err


@needs_rosbag
def test_report_with_a_bag_given_as_the_spec(write, tmp_path, capsys):
    bag = write_bag(str(tmp_path / "x.bag"), [(0.0, "/x", Float64(data=0))])
    spec = spec_file(write, "entity e { rules: over: topic /x.data > 1; }\nif (e.over) then { stop; }\n")
    status, out, err = run(capsys, "report", bag, "--bag", spec, "-o", str(tmp_path / "r.html"))
    assert status == 1 and out == ""
    assert err == (f"rubass report: error: {bag} is a ROS bag, not a spec (usage: rubass report SPEC --bag BAG "
                   "[--tests FILE.test.yaml ...] -o report.html)\n")  # before: "spec is not UTF-8 text", bytes
    assert not os.path.exists(str(tmp_path / "r.html"))


@needs_rosbag
def test_report_bag_prints_the_specs_warnings_once(write, tmp_path, capsys):
    bags = [write_bag(str(tmp_path / f"{n}.bag"), [(0.0, "/x", Float64(data=0)), (1.0, "/x", Float64(data=2))])
            for n in ("a", "b")]
    spec = spec_file(write, "entity e { rules:\n  f: topic /x.data > 1;\n  s: stamp_age(topic /x) > 1 s;\n}\n"
                            "if (e.f) then { warn; }\n", actions="warn, stop")
    status, out, err = run(capsys, "report", spec, "--bag", *bags, "-o", str(tmp_path / "r.html"))
    assert status == 0, err
    lines = err.splitlines()
    unused = f"{spec}:2:24: warning: action 'stop' is declared but never used"
    assert lines[0] == unused, err  # before: no warning at all
    assert lines.count(unused) == 1  # the spec's own, once for two recordings
    always = [n for n in lines if n.startswith(f"{spec}:5:16: warning: stamp_age(topic /x) is always unknown")]
    assert len(always) == 1, err  # read against the recordings' types: said as `rubass check --bag` says it


@needs_rosbag
def test_report_bag_warns_of_a_node_no_recorded_sample_covers(write, tmp_path, capsys):
    items = []
    for i in range(40):
        d = {"node": "controller", "time": T0 + i * 0.1 - 0.003, "alive": True, "cpu": 0.1, "memory": 1e6}
        items.append((i * 0.1, "/rubass/node_samples", String(data=json.dumps(d))))
    bag = write_bag(str(tmp_path / "n.bag"), items)
    spec = spec_file(write, "entity base: controller, planner { rules:\n  dead: not alive(node controller);\n"
                            "  gone: not alive(node planner);\n}\nif (base.dead or base.gone) then { stop; }\n")
    page = str(tmp_path / "r.html")
    status, out, err = run(capsys, "report", spec, "--bag", bag, "-o", page)
    assert status == 0, err
    said = "the recording has node samples, but none of node planner (/planner); its alive(), cpu() and " \
           "memory() stay unknown"
    assert f"rubass report: warning: {bag}: {said}" in err.splitlines()  # before: nothing, as if all were sampled
    assert "node controller" not in err
    with open(page, encoding="utf-8") as fh:
        assert "none of node planner (/planner)" in fh.read()  # and on the page, beside the recording
