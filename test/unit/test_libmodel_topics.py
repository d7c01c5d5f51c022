"""Action libraries: actions on one topic agree on its type, a limit against a system model,
duplicate keys, every error in one run, standard-library plugins (acceptance findings)."""
import pytest

from rubass.cli import main
from rubass.lang import SpecError, check_text
from rubass.lang.library import parse_library, priority_conflicts
from rubass.lang.source import Source

SPEC = "entity x {{ rules: r: topic /x.data > 1; }}\naction primitive {names};\nif (x.r) then {{ {calls} }}\n"


def lib(text, name="lib.yaml"):
    actions, diags = parse_library(Source(name, text))
    return actions, [f"{d.span.line}:{d.span.col}: {d.message}" for d in diags]


def run_check(tmp_path, capsys, library, names, *options):
    (tmp_path / "lib.yaml").write_text(library)
    (tmp_path / "s.rbs").write_text('import "lib.yaml";\n' + SPEC.format(
        names=", ".join(names), calls=" ".join(n + ";" for n in names)))
    status = main(["check", *options, str(tmp_path / "s.rbs")])
    out = capsys.readouterr()
    return status, out.out + out.err


def test_two_types_on_one_topic_are_an_error_at_the_second_type():
    actions, diags = lib("actions:\n"
                         "  a: {plugin: publish, topic: /o, type: geometry_msgs/Twist, priority: 2}\n"
                         "  b: {plugin: limit, type: geometry_msgs/TwistStamped, input: /nav, topic: /o, "
                         "linear_x: [0, 0.1 m/s]}\n")
    assert diags == ["3:28: action 'b': publishes geometry_msgs/TwistStamped on /o, but action 'a' (line 2) "
                     "publishes geometry_msgs/Twist there: one topic carries one message type (ROS would send one "
                     "action's messages as the other's type, garbage to every subscriber); give one of them "
                     "another topic or the same type"]
    assert set(actions) == {"a"}


def test_a_publish_of_string_beside_twist_and_spellings_of_one_topic():
    _, diags = lib("actions:\n"
                   "  a: {plugin: publish, topic: cmd_vel, type: geometry_msgs/Twist, priority: 2}\n"
                   "  b: {plugin: publish, topic: /cmd_vel, type: std_msgs/String, priority: 1}\n"
                   "  c: {plugin: limit, input: /nav, topic: /cmd_vel/, priority: 3, linear_x: [0, 0.1 m/s]}\n")
    assert [d.split(": publishes")[0] for d in diags] == ["3:47: action 'b'"]
    assert "std_msgs/String on /cmd_vel, but action 'a' (line 2) publishes geometry_msgs/Twist" in diags[0]


def test_a_limit_of_the_default_type_is_reported_at_its_topic():
    _, diags = lib("actions:\n"
                   "  a: {plugin: publish, topic: /o, type: geometry_msgs/TwistStamped}\n"
                   "  b: {plugin: limit, input: /nav, topic: /o, priority: 1, linear_x: [0, 0.1 m/s]}\n")
    assert [d[:40] for d in diags] == ["3:42: action 'b': publishes geometry_msg"]


def test_types_on_one_topic_across_libraries_and_for_the_monitor(tmp_path):
    (tmp_path / "a.yaml").write_text("actions:\n  a: {plugin: publish, topic: /o, type: geometry_msgs/Twist}\n")
    (tmp_path / "b.yaml").write_text("actions:\n  b: {plugin: publish, topic: o, type: std_msgs/String, "
                                     "priority: 1}\n")
    with pytest.raises(SpecError) as info:
        check_text('import "b.yaml";\nimport "a.yaml";\n' + SPEC.format(names="a, b", calls="a; b;"),
                   str(tmp_path / "s.rbs"))
    text = str(info.value)
    assert text.startswith(f"{tmp_path}/a.yaml:2:41: error: action 'a': publishes geometry_msgs/Twist on /o, "
                           f"but action 'b' ({tmp_path}/b.yaml:2:3) publishes std_msgs/String there"), text
    assert len(info.value.diagnostics) == 1  # and 'a' is not also "undefined"
    # the monitor checks the loaded actions again with its own resolution of names
    a, _ = parse_library(Source("a.yaml", (tmp_path / "a.yaml").read_text()))
    b, _ = parse_library(Source("b.yaml", (tmp_path / "b.yaml").read_text()))
    found = priority_conflicts(list(a.values()) + list(b.values()), lambda t: "/robot/" + t.strip("/"))
    assert [(d.subject, str(d.span)) for d in found] == [("b", "b.yaml:2:40")]


def test_a_limit_is_checked_against_the_model_types(tmp_path, capsys):
    (tmp_path / "mm.yaml").write_text("rubass_model: 1\ntopics:\n  /cmd_vel_safety: geometry_msgs/TwistStamped\n"
                                      "  /nav_vel: geometry_msgs/TwistStamped\n  /x: std_msgs/Float64\n")
    library = ("actions:\n  crawl: {plugin: limit, input: /nav_vel, topic: /cmd_vel_safety, "
               "linear_x: [0, 0.1 m/s]}\n")
    status, out = run_check(tmp_path, capsys, library, ["crawl"], "--model", str(tmp_path / "mm.yaml"))
    assert status == 1
    assert (f"lib.yaml:2:33: error: action 'crawl': its input /nav_vel carries geometry_msgs/TwistStamped in the "
            f"system model {tmp_path}/mm.yaml, but the limit reads geometry_msgs/Twist (its default type): it would "
            f"refuse every command; set 'type: geometry_msgs/TwistStamped'") in out, out
    assert "lib.yaml:2:50: error: action 'crawl': its topic /cmd_vel_safety carries" in out, out
    fixed = library.replace("{plugin: limit,", "{plugin: limit, type: geometry_msgs/TwistStamped,")
    status, out = run_check(tmp_path, capsys, fixed, ["crawl"], "--model", str(tmp_path / "mm.yaml"))
    assert status == 0, out


@pytest.mark.parametrize("text,expected", [
    ("  a: {plugin: publish, topic: /o, type: geometry_msgs/Twist, priority: 5, priority: 0}\n",
     "2:75: action 'a': key 'priority' is written twice in one mapping (first at 2:62); YAML would keep only "
     "the last: remove one"),
    ("  a:\n    plugin: publish\n    topic: /o\n    type: geometry_msgs/Twist\n    message:\n"
     "      linear: {x: 1}\n      linear: {x: 2}\n",
     "8:7: action 'a': key 'linear' is written twice in one mapping (first at 7:7); YAML would keep only the "
     "last: remove one"),
])
def test_a_key_written_twice_in_an_action_is_an_error_at_the_second(text, expected):
    actions, diags = lib("actions:\n" + text)
    assert diags == [expected] and actions == {}


def test_merged_keys_are_no_duplicates():
    actions, diags = lib("actions:\n  a: &base {plugin: publish, topic: /o, type: geometry_msgs/Twist}\n"
                         "  b: {<<: *base, topic: /p}\n")
    assert diags == [] and actions["b"].params["topic"] == "/p"


@pytest.mark.parametrize("plugin", ["subprocess:Popen", "json:JSONDecoder", "os.path:join"])
def test_a_standard_library_plugin_is_an_error_at_check(plugin):
    assert lib(f"actions:\n  a: {{plugin: {plugin}}}\n")[1] == [
        f"2:15: action 'a': plugin module '{plugin.split(':')[0]}' is part of Python's standard library; a custom "
        f"plugin must be a class in the robot's own package"]


def test_every_library_error_in_one_run(tmp_path, capsys):
    library = ("actions:\n  a: {plugin: publish, topic: /a, type: geometry_msgs/Twist, rate: fast}\n"
               "  b: {plugin: publish, topic: /b, type: geometry_msgs/Twist, message: {angualr: {z: 1.0}}}\n")
    status, out = run_check(tmp_path, capsys, library, ["a", "b"])
    assert status == 1
    assert "lib.yaml:2:68: error: action 'a': 'rate' must be a positive frequency" in out, out
    assert ("lib.yaml:3:72: error: action 'b': geometry_msgs/Twist has no field 'angualr'; "
            "did you mean 'angular'?") in out, out
    assert out.rstrip().endswith("s.rbs: 2 errors"), out


def test_a_service_type_typo_suggests_the_installed_type_of_its_package(tmp_path, capsys):
    pytest.importorskip("std_srvs.srv")
    library = ("actions:\n  h: {plugin: service, service: /v, type: std_srvs/Trigerr}\n"
               "  i: {plugin: service, service: /w, type: std_srvs/SetBool}\n")
    status, out = run_check(tmp_path, capsys, library, ["h", "i"])
    assert status == 1
    assert "unknown service type 'std_srvs/Trigerr'" in out and "did you mean 'std_srvs/Trigger'?" in out, out


def test_a_limit_whose_topic_is_a_spelling_of_its_input_is_an_error():
    _, diags = lib("actions:\n  c: {plugin: limit, input: cmd_vel, topic: /cmd_vel/, linear_x: [0, 0.1 m/s]}\n")
    assert diags == ["2:45: action 'c': 'topic' must differ from 'input' (cmd_vel): it would filter its own output"]
