"""Action libraries, version 2 (LANGUAGE.md §16): `priority` and the `limit` plugin's schema."""
import math
import re

import pytest

from rubass.lang.library import parse_library, priority_conflicts
from rubass.lang.source import Source

from conftest import shared_path


def lib(text):
    actions, diags = parse_library(Source("lib.yaml", text))
    return actions, [(d.span.line, d.message) for d in diags]


def errors(text):
    return lib(text)[1]


PUB = "    plugin: publish\n    type: geometry_msgs/Twist\n"
CRAWL = ("actions:\n  crawl:\n    plugin: limit\n    input: /cmd_vel\n    topic: /cmd_vel_safety\n")


def test_priority_defaults_to_zero_and_takes_any_integer():
    actions, diags = lib("actions:\n  a:\n" + PUB + "    topic: /a\n  b:\n" + PUB + "    topic: /b\n    priority: -3\n"
                         "  c:\n    plugin: log\n    priority: 12\n")
    assert diags == []
    assert (actions["a"].priority, actions["b"].priority, actions["c"].priority) == (0, -3, 12)
    assert "priority" not in actions["b"].params


@pytest.mark.parametrize("value", ["1.5", "high", "true", "[1]"])
def test_priority_must_be_an_integer(value):
    assert errors("actions:\n  a:\n" + PUB + f"    topic: /a\n    priority: {value}\n") == [
        (6, f"action 'a': 'priority' must be an integer (higher wins on a shared topic), got "
            f"{ {'1.5': 1.5, 'high': 'high', 'true': True, '[1]': [1]}[value]!r}")]


def test_two_actions_with_one_priority_on_one_topic_are_an_error_at_the_second():
    text = ("actions:\n  stop:\n" + PUB + "    topic: /cmd\n    priority: 2\n"
            "  back:\n" + PUB + "    topic: /cmd\n    priority: 2\n"
            "  crawl:\n    plugin: limit\n    input: /in\n    topic: /cmd\n    linear_x: [0, 0.1 m/s]\n")
    actions, diags = lib(text)
    assert diags == [(7, "action 'back': same priority (2) as action 'stop' (line 2), and both publish on /cmd; "
                         "which one publishes must not be left to chance: give one a higher 'priority'")]
    assert set(actions) == {"stop", "crawl"}  # crawl (priority 0) is fine beside them


def test_different_priorities_or_topics_do_not_conflict():
    assert errors("actions:\n  a:\n" + PUB + "    topic: /cmd\n  b:\n" + PUB + "    topic: /cmd\n    priority: 1\n"
                  "  c:\n" + PUB + "    topic: /other\n  w:\n    plugin: log\n  v:\n    plugin: log\n") == []


def test_conflicts_across_libraries_use_resolved_names():
    a, _ = lib("actions:\n  a:\n" + PUB + "    topic: cmd\n")
    b, _ = parse_library(Source("other.yaml", "actions:\n  b:\n" + PUB + "    topic: /robot/cmd\n"))
    assert priority_conflicts(list(a.values()) + list(b.values())) == []
    found = priority_conflicts(list(a.values()) + list(b.values()),
                               lambda t: t if t.startswith("/") else "/robot/" + t)
    assert [d.message for d in found] == [
        "action 'b': same priority (0) as action 'a' (lib.yaml:2:3), and both publish on /robot/cmd; which one "
        "publishes must not be left to chance: give one a higher 'priority'"]
    assert str(found[0].span) == "other.yaml:2:3"


def test_the_limit_example_of_language_md_validates_with_si_values_and_defaults():
    text = open(shared_path("spec", "LANGUAGE.md"), encoding="utf-8").read()
    block = next(b for b in re.findall(r"```yaml\n(.*?)```", text, re.S) if "plugin: limit" in b)
    actions, diags = lib("actions:\n" + block + "  stop:\n" + PUB + "    topic: /cmd_vel_safety\n    priority: 2\n")
    assert diags == []
    crawl = actions["crawl"]
    assert crawl.plugin == "limit" and crawl.priority == 1
    assert crawl.params["linear_x"] == (-0.1, 0.2) and crawl.params["angular_z"] == (-0.5, 0.5)
    assert crawl.params["linear_y"] is None
    assert (crawl.params["type"], crawl.params["timeout"], crawl.params["rate"]) == ("geometry_msgs/Twist", 0.5, 20.0)


def test_limit_units_are_converted_and_a_bare_zero_needs_none():
    actions, diags = lib(CRAWL + "    type: geometry_msgs/TwistStamped\n    linear_x: [0, 36 km/h]\n"
                                 "    linear_y: [-5 cm/s, 0.0]\n    angular_z: [-90 deg/s, 90 deg/s]\n"
                                 "    timeout: 200 ms\n    rate: 50 Hz\n")
    assert diags == []
    p = actions["crawl"].params
    assert p["linear_x"] == (0.0, 10.0) and p["linear_y"] == (-0.05, 0.0)
    assert p["angular_z"] == pytest.approx((-math.pi / 2, math.pi / 2))
    assert (p["type"], p["timeout"], p["rate"]) == ("geometry_msgs/TwistStamped", 0.2, 50.0)


@pytest.mark.parametrize("line, message", [
    ("    linear_x: [-0.1, 0.2 m/s]",
     "'linear_x': -0.1 needs a unit (m/s, cm/s or km/h), such as '-0.1 m/s'"),
    ("    angular_z: [-0.5 m/s, 0.5 rad/s]",
     "'angular_z' takes an angular speed (rad/s or deg/s), got '-0.5 m/s' (a speed)"),
    ("    linear_x: [-1 rad/s, 0]",
     "'linear_x' takes a speed (m/s, cm/s or km/h), got '-1 rad/s' (an angular speed)"),
    ("    linear_x: [0.3 m/s, 0.1 m/s]", "'linear_x': min '0.3 m/s' is greater than max '0.1 m/s'"),
    ("    linear_x: 0.2 m/s", "'linear_x' must be a range [min, max] such as [-0.2 m/s, 0.2 m/s], got '0.2 m/s'"),
    ("    linear_x: [0, 0.1 m/s, 0.2 m/s]",
     "'linear_x' must be a range [min, max] such as [-0.2 m/s, 0.2 m/s], got [0, '0.1 m/s', '0.2 m/s']"),
    ("    linear_x: [0, fast]", "'linear_x': 'fast' is not a quantity; write a number with a unit (m/s, cm/s or km/h)"),
    ("    linear_x: [0, 0.1 m/s]\n    type: geometry_msgs/Twist2",
     "'type' must be one of geometry_msgs/Twist, geometry_msgs/TwistStamped, got 'geometry_msgs/Twist2'; "
     "did you mean 'geometry_msgs/Twist'?"),
    ("    linear_x: [0, 0.1 m/s]\n    type: std_msgs/Float64",
     "'type' must be one of geometry_msgs/Twist, geometry_msgs/TwistStamped, got 'std_msgs/Float64'"),
    ("    linear_x: [0, 0.1 m/s]\n    timeout: 0 s", "'timeout' must be a positive time such as '0.5 s', got '0 s'"),
    ("    linear_x: [0, 0.1 m/s]\n    rate: 2 m", "'rate' must be a positive frequency such as '20 Hz', got '2 m'"),
    ("    linear_w: [0, 0.1 m/s]", "unknown key 'linear_w' for plugin 'limit'; did you mean 'linear_z'?"),
])
def test_limit_errors_name_the_line(line, message):
    found = errors(CRAWL + line + "\n")
    assert found == [(found[0][0], f"action 'crawl': {message}")], found
    assert found[0][0] >= 6


def test_a_limit_needs_an_axis_an_input_and_an_output_other_than_its_input():
    assert errors(CRAWL) == [(2, "action 'crawl': a limit action needs at least one axis range (linear_x, linear_y, "
                                 "linear_z, angular_x, angular_y, angular_z), such as 'linear_x: [-0.1 m/s, 0.2 m/s]'")]
    assert errors("actions:\n  crawl:\n    plugin: limit\n    topic: /out\n    linear_x: [0, 0.1 m/s]\n") == [
        (2, "action 'crawl': missing key 'input' (plugin 'limit' needs it)")]
    assert errors("actions:\n  crawl:\n    plugin: limit\n    input: /c\n    topic: /c\n    linear_x: [0, 0.1 m/s]\n") \
        == [(5, "action 'crawl': 'topic' must differ from 'input' (/c): it would filter its own output")]


def test_the_twist_mux_setup_in_docs_validates_and_its_spec_checks(tmp_path):
    import os

    import yaml

    from conftest import ROOT
    from rubass.lang import check_text

    text = open(os.path.join(ROOT, "docs", "actions.md"), encoding="utf-8").read()
    blocks = re.findall(r"```(\w*)\n(.*?)```", text, re.S)
    lib_text = next(b for lang, b in blocks if b.startswith("# safety_actions.yaml"))
    actions, diags = lib(lib_text)
    assert diags == [] and [(a, actions[a].priority) for a in actions] == [("stop", 3), ("back_away", 2), ("crawl", 1)]
    assert actions["back_away"].params["angular_z"] == (0.0, 0.0)
    mux = yaml.safe_load(next(b for lang, b in blocks if b.startswith("# twist_mux.yaml")))
    prio = {t["name"]: t for t in mux["topics"]}
    assert prio["safety"]["priority"] > prio["navigation"]["priority"] and prio["safety"]["timeout"] > 1 / 20
    assert "/" + prio["safety"]["topic"] == actions["crawl"].params["topic"]
    (tmp_path / "lib.yaml").write_text(lib_text)
    body = next(b for lang, b in blocks if lang == "text" and "then { crawl; }" in b)
    spec = check_text('import "lib.yaml";\naction primitive stop, back_away, crawl;\n'
                      "entity base { rules: near: topic /scan_min.data < 0.5 m; bumped: topic /bumper.data > 0;\n"
                      "  outside: topic /odom.pose.pose.position.x > 10 m; }\n" + body, str(tmp_path / "s.rbs"))
    assert [b.actions[0].name for b in spec.behaviours] == ["crawl", "back_away", "stop"]


def test_check_reports_one_priority_on_one_topic_across_two_libraries(tmp_path):
    from rubass.lang import SpecError, check_text

    (tmp_path / "a.yaml").write_text("actions:\n  stop:\n" + PUB + "    topic: /cmd\n")
    (tmp_path / "b.yaml").write_text("actions:\n  # another team's library\n  brake:\n" + PUB + "    topic: /cmd\n"
                                     "  slow:\n" + PUB + "    topic: /cmd\n    priority: 1\n")
    with pytest.raises(SpecError) as info:
        check_text('import "a.yaml";\nimport "b.yaml";\naction primitive stop, brake, slow;\n'
                   "if (true) then { stop; brake; slow; }\n", str(tmp_path / "s.rbs"))
    text = str(info.value)
    assert text.startswith(f"{tmp_path}/b.yaml:3:3: error: action 'brake': same priority (0) as action 'stop' "
                           f"({tmp_path}/a.yaml:2:3), and both publish on /cmd"), text
    assert len(info.value.diagnostics) == 1  # slow (priority 1) is fine, and brake is not also "undefined"


def test_yaml_merge_keys_share_settings_between_actions():
    """`<<: *base` (acceptance finding: it gave "missing key 'plugin'"); own keys win over merged ones."""
    actions, diags = lib("actions:\n  stop: &pub\n" + PUB + "    topic: /cmd_vel_safety\n    priority: 2\n"
                         "  brake:\n    <<: *pub\n    topic: /brake\n    priority: 3\n"
                         "  halt: {<<: [*pub], topic: /halt}\n")
    assert diags == []
    assert [(actions[n].priority, actions[n].plugin) for n in ("stop", "brake", "halt")] == \
        [(2, "publish"), (3, "publish"), (2, "publish")]


def test_a_merge_key_of_a_scalar_is_an_error_at_its_place():
    assert errors("actions:\n  stop:\n    <<: 3\n" + PUB + "    topic: /a\n") == [
        (3, "a merge key '<<' takes a mapping (such as '*base') or a list of them")]


def test_merge_keys_that_merge_each_other_stay_small():
    """An alias bomb of merges: each mapping is merged once, its keys kept once."""
    text = "a0: &a0 {k: 1}\n" + "".join(f"a{i}: &a{i} {{<<: [*a{i - 1}, *a{i - 1}], k{i}: {i}}}\n"
                                          for i in range(1, 60)) + "actions:\n  stop:\n    <<: *a59\n"
    _, diags = lib(text)
    assert any("unknown top-level key 'a0'" in m for _, m in diags)  # reported, in no time or memory
