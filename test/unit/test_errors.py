"""Every class of spec error: its line, its column and its message text."""
import textwrap

import pytest

from rubass.lang import SpecError, check_text, load_spec

LIB = """\
actions:
  stop: {plugin: publish, topic: /cmd_vel, type: geometry_msgs/Twist}
  warn: {plugin: log}
"""


def errors(write, spec, lib=LIB):
    """[(line, col, message)] of the errors of a spec written beside the standard library."""
    write("actions.yaml", lib)
    path = write("s.rbs", textwrap.dedent(spec))
    with pytest.raises(SpecError) as info:
        load_spec(path)
    return [(d.span.line, d.span.col, d.message) for d in info.value.diagnostics]


HEAD = 'import "actions.yaml";\naction primitive stop;\n'

CASES = [
    ("undefined name with suggestion",
     HEAD + "const LIMIT = 2 m/s;\nentity e { rules: r: topic /v.x > LIMT; }\nif (e.r) then { stop; }\n",
     (4, 35, "undefined name 'LIMT'; did you mean 'LIMIT'?")),
    ("undefined entity",
     HEAD + "entity base { rules: r: topic /v.x > 1; }\nif (bsae.r) then { stop; }\n",
     (4, 5, "undefined entity 'bsae'; did you mean 'base'?")),
    ("undefined rule",
     HEAD + "entity base { rules: fast: topic /v.x > 1; }\nif (base.fsat) then { stop; }\n",
     (4, 5, "entity 'base' has no rule 'fsat'; did you mean 'fast'?")),
    ("rule used without its entity",
     HEAD + "entity base { rules: fast: topic /v.x > 1; }\nif (fast) then { stop; }\n",
     (4, 5, "'fast' is a rule of entity 'base': write 'base.fast'")),
    ("duplicate rule",
     HEAD + "entity e { rules:\n  r: topic /v.x > 1;\n  r: topic /v.x > 2;\n}\nif (e.r) then { stop; }\n",
     (5, 3, "duplicate rule 'r' in entity 'e'; first defined at {dir}/s.rbs:4:3")),
    ("duplicate top-level name",
     HEAD + "const e = 1;\nentity e { rules: r: topic /v.x > 1; }\nif (e.r) then { stop; }\n",
     (4, 8, "duplicate name 'e' (an entity); first defined at {dir}/s.rbs:3:7")),
    ("undeclared action",
     HEAD + "entity e { rules: r: topic /v.x > 1; }\nif (e.r) then { stpo; }\n",
     (4, 17, "action 'stpo' is not declared: add 'action primitive stpo;'; did you mean 'stop'?")),
    ("an action declared twice",
     'import "actions.yaml";\naction primitive stop;\naction primitive stop;\n'
     "entity e { rules: r: topic /v.x > 1; }\nif (e.r) then { stop; }\n",
     (3, 18, "duplicate action 'stop': already declared at {dir}/s.rbs:2:18")),
    ("declared action missing from the libraries",
     HEAD.replace("stop;", "stop, brake;") + "entity e { rules: r: topic /v.x > 1; }\nif (e.r) then { brake; }\n",
     (2, 24, "action 'brake' is not defined in any action library (loaded: {dir}/actions.yaml)")),
    ("cyclic rules",
     HEAD + "entity e { rules:\n  a: b and topic /v.x > 1;\n  b: a;\n}\nif (e.a) then { stop; }\n",
     (4, 3, "cyclic rule reference: e.a -> e.b -> e.a")),
    ("chained comparison",
     HEAD + "entity e { rules: r: 0 < topic /v.x < 1; }\nif (e.r) then { stop; }\n",
     (3, 37, "comparisons cannot be chained: write '(a < b) and (b < c)' instead of 'a < b < c'")),
    ("for without a unit",
     HEAD + "entity e { rules: r: topic /v.x > 1 for 0.4; }\nif (e.r) then { stop; }\n",
     (3, 41, "the duration of 'for' needs a unit of time: write '0.4 s'")),
    ("for with a length",
     HEAD + "entity e { rules: r: topic /v.x > 1 for 3 m; }\nif (e.r) then { stop; }\n",
     (3, 41, "the duration of 'for' must be a time, not a length")),
    ("comparing time with length",
     HEAD + "entity e { rules: r: age(topic /x) > 3 m; }\nif (e.r) then { stop; }\n",
     (3, 36, "compares a time with a length")),
    ("comparing a share with memory",
     HEAD + "entity e: n { rules: r: cpu(node n) > 2 MB; }\nif (e.r) then { stop; }\n",
     (3, 37, "compares a plain number with a memory")),
    ("adding speed and time",
     HEAD + "entity e { rules: r: topic /v.x + 1 m/s + 2 s > 0; }\nif (e.r) then { stop; }\n",
     (3, 41, "cannot add or subtract a speed and a time")),
    ("unknown unit",
     HEAD + "entity e { rules: r: topic /v.x > 3 m/min; }\nif (e.r) then { stop; }\n",
     (3, 35, "unknown unit 'm/min'; a speed is written in m/s, cm/s, km/h")),
    ("missing import",
     'import "nothere.yaml";\n' + HEAD + "entity e { rules: r: topic /v.x > 1; }\nif (e.r) then { stop; }\n",
     (1, 1, "cannot import '{dir}/nothere.yaml': no such file")),
    ("unknown package",
     'import "package://no_such_pkg/x.yaml";\n' + HEAD + "entity e { rules: r: topic /v.x > 1; }\nif (e.r) then { stop; }\n",
     (1, 1, "cannot import 'package://no_such_pkg/x.yaml': ROS package 'no_such_pkg' not found on "
            "ROS_PACKAGE_PATH (source the workspace's setup.bash)")),
    ("node not in the entity header",
     HEAD + "entity e: driver { rules: r: not alive(node drvier); }\nif (e.r) then { stop; }\n",
     (3, 40, "node 'drvier' is not in the nodes of entity 'e' (driver); did you mean 'driver'?")),
    ("unknown function",
     HEAD + "entity e { rules: r: mx(topic /v.x, 1) > 1; }\nif (e.r) then { stop; }\n",
     (3, 22, "unknown function 'mx'; did you mean 'max'?")),
    ("rule that is not a condition",
     HEAD + "entity e { rules: r: 3 m; }\nif (e.r) then { stop; }\n",
     (3, 22, "rule 'r' must be a condition (true or false), not a number (length)")),
    ("constant reading a topic",
     HEAD + "const C = topic /v.x;\nentity e { rules: r: topic /v.x > C; }\nif (e.r) then { stop; }\n",
     (3, 11, "a constant cannot read a topic")),
    ("topic without a field",
     HEAD + "entity e { rules: r: topic /v > 1; }\nif (e.r) then { stop; }\n",
     (3, 22, "'topic /v' needs a field, e.g. 'topic /v.data'; use age() or frequency() for the topic itself")),
    ("syntax error",
     HEAD + "entity e { rules: r: topic /v.x > ; }\n",
     (3, 35, "expected expression, found ';'")),
    ("keyword as a name",
     HEAD + "const for = 1;\n",
     (3, 7, "'for' is a keyword and cannot be used as a name")),
]


@pytest.mark.parametrize("title,spec,expected", CASES, ids=[c[0] for c in CASES])
def test_error_place_and_text(write, tmp_path, title, spec, expected):
    line, col, msg = expected
    found = errors(write, spec)
    assert (line, col, msg.format(dir=tmp_path)) in found, found


def test_all_errors_are_reported_in_one_run(write):
    found = errors(write, HEAD + "entity e { rules:\n  a: topic /v.x > LIMT;\n  b: age(topic /x) > 3 m;\n}\n"
                                 "if (e.c) then { stpo; }\n")
    assert [(l, c) for l, c, _ in found] == [(4, 19), (5, 20), (7, 5), (7, 17)]


def test_render_is_compiler_style_with_caret(write, tmp_path):
    write("actions.yaml", LIB)
    path = write("s.rbs", HEAD + "entity e { rules: r: topic /v.x > LIMT; }\nif (e.r) then { stop; }\n")  # no warning
    with pytest.raises(SpecError) as info:
        load_spec(path)
    assert str(info.value).splitlines() == [
        f"{path}:3:35: error: undefined name 'LIMT'",
        "    entity e { rules: r: topic /v.x > LIMT; }",
        "                                      ^",
    ]


LIB_CASES = [
    ("unknown plugin", "actions:\n  stop:\n    plugin: publsh\n",
     (3, 13, "action 'stop': unknown plugin 'publsh' (built-ins: publish, serial, service, log, limit; "
             "custom: 'package.module:Class'); did you mean 'publish'?")),
    ("missing key", "actions:\n  stop:\n    plugin: publish\n    topic: /cmd_vel\n",
     (2, 3, "action 'stop': missing key 'type' (plugin 'publish' needs it)")),
    ("mistyped key", "actions:\n  stop:\n    plugin: serial\n    port: /dev/ttyACM0\n    baud: fast\n    on_start: S\n",
     (5, 11, "action 'stop': 'baud' must be a positive integer, got 'fast'")),
    ("unknown key", "actions:\n  stop:\n    plugin: publish\n    topic: /c\n    type: geometry_msgs/Twist\n    rat: 2 Hz\n",
     (6, 5, "action 'stop': unknown key 'rat' for plugin 'publish'; did you mean 'rate'?")),
    ("bad rate unit", "actions:\n  stop:\n    plugin: publish\n    topic: /c\n    type: geometry_msgs/Twist\n    rate: 2 s\n",
     (6, 11, "action 'stop': 'rate' must be a positive frequency such as '20 Hz', got '2 s'")),
    ("not YAML", "actions:\n  stop: [plugin\n",
     (3, 1, "invalid YAML: expected ',' or ']', but got '<stream end>'")),
    ("not a mapping", "- stop\n", (1, 1, "an action library must be a mapping with a key 'actions'")),
    ("no actions key", "action:\n  stop: {}\n", (1, 1, "an action library needs a top-level key 'actions'")),
]


@pytest.mark.parametrize("title,lib,expected", LIB_CASES, ids=[c[0] for c in LIB_CASES])
def test_library_error_names_file_and_key(write, tmp_path, title, lib, expected):
    found = errors(write, HEAD + "entity e { rules: r: topic /v.x > 1; }\nif (e.r) then { stop; }\n", lib)
    line, col, msg = expected
    assert (line, col, msg) in found, found


def test_library_errors_name_the_yaml_file(write, tmp_path):
    write("actions.yaml", "actions:\n  stop:\n    plugin: publsh\n")
    path = write("s.rbs", HEAD + "entity e { rules: r: topic /v.x > 1; }\nif (e.r) then { stop; }\n")
    with pytest.raises(SpecError) as info:
        load_spec(path)
    assert str(info.value).startswith(f"{tmp_path}/actions.yaml:3:13: error: action 'stop': unknown plugin")


def test_package_import_resolves_on_ros_package_path(write, tmp_path, monkeypatch):
    from rubass.lang import paths

    write("ws/my_robot/package.xml", "<package format='3'><name>my_robot</name></package>")
    write("ws/my_robot/safety/actions.yaml", LIB)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ws"))
    paths.clear_cache()
    spec = check_text('import "package://my_robot/safety/actions.yaml";\naction primitive stop;\n'
                      "entity e { rules: r: topic /v.x > 1; }\nif (e.r) then { stop; }\n",
                      str(tmp_path / "elsewhere" / "s.rbs"))
    assert spec.libraries == [str(tmp_path / "ws" / "my_robot" / "safety" / "actions.yaml")]


def test_absolute_import(write, tmp_path):
    lib = write("lib/actions.yaml", LIB)
    spec = check_text(f'import "{lib}";\naction primitive stop;\nentity e {{ rules: r: topic /v.x > 1; }}\n'
                      "if (e.r) then { stop; }\n", str(tmp_path / "s.rbs"))
    assert spec.actions["stop"].plugin == "publish"


@pytest.mark.parametrize("lib", ["actions:\n  stop: {plugin: publish, topic: /c\n  warn: {plugin: log}\n",
                                 "- stop\n", "action:\n  stop: {}\n"], ids=["not YAML", "not a mapping", "no key"])
def test_a_library_that_cannot_be_read_is_the_only_error_its_actions_get(write, lib):
    """Its own error says what is wrong; 'action is not defined in any action library' for each of
    its actions, printed first, sent the user to the spec instead (acceptance finding)."""
    found = errors(write, HEAD + "entity e { rules: r: topic /v.x > 1; }\nif (e.r) then { stop; }\n", lib)
    assert len(found) == 1 and "not defined" not in found[0][2], found


def test_articles_and_unit_formulas_read_as_english(write):
    found = errors(write, HEAD + "const e = 1;\nentity e { rules: r: age(topic /v) * 1 m > 1 m; }\n"
                          "entity f { rules: r: age(topic /v) * 1 m > 1 m; }\nif (f.r) then { stop; }\n")
    messages = [m for _, _, m in found]
    assert any(m.startswith("duplicate name 'e' (an entity)") for m in messages), messages
    assert "compares a quantity in m*s with a length" in messages, messages


@pytest.mark.parametrize("index", ["1.5:2", "", "a", "*:2", "::"])
def test_a_bad_index_after_a_field_path_says_what_an_index_is(write, index):
    found = errors(write, HEAD + f"entity e {{ rules: r: min(topic /s.ranges[{index}]) < 1 m; }}\n"
                                 "if (e.r) then { stop; }\n")
    assert found == [(3, 41, f"'[{index}]' is not an index: write an integer ([0], [-1]), a slice of integers "
                             "([0:90], [-90:]) or [*] for the whole array")], found


def test_a_missing_brace_before_a_statement_says_so(write):
    found = errors(write, HEAD + "entity e { rules: r: topic /v.x > 1;\nif (e.r) then { stop; }\n")
    assert found == [(4, 1, "'if' is a keyword and cannot be used as a name (a statement cannot start inside "
                            "an entity: is a '}' missing before this 'if'?)")], found
    found = errors(write, HEAD + "const if = 1;\n")
    assert found == [(3, 7, "'if' is a keyword and cannot be used as a name")], found


def test_a_long_run_of_not_is_named_where_it_starts(write):
    found = errors(write, HEAD + "entity e { rules: r: " + "not " * 1000 + "topic /v.x > 1; }\nif (e.r) then { stop; }\n")
    assert found == [(3, 22, "expressions are nested too deeply to parse (a long run of 'not' or '-' here; "
                             "two cancel out: remove pairs)")], found


def test_errors_inside_a_duplicate_definition_are_reported_with_the_duplicate(write):
    """A duplicate entity, constant or rule is checked too, in place of the first of its name: fixing
    the name must not reveal a second round of errors (found in an acceptance sweep)."""
    found = errors(write, HEAD + "const LIM = 1 m/s;\nconst LIM = 2 m/s + 1 s;\n"
                          "entity e { rules: r: topic /v.x > LIM; }\n"
                          "entity e { rules:\n  q: undefined_rule and topic /v.x > 1;\n"
                          "  q: topic /v.x > 1 for 2;\n}\nif (e.r) then { stop; }\n")
    assert [(line, m.split(";")[0]) for line, _, m in found] == [
        (4, "duplicate name 'LIM' (a constant)"),
        (4, "cannot add or subtract a speed and a time"),
        (6, "duplicate name 'e' (an entity)"),
        (7, "undefined name 'undefined_rule'"),
        (8, "duplicate rule 'q' in entity 'e'"),
        (8, "the duration of 'for' needs a unit of time: write '2 s'"),
    ], found


def test_a_duplicate_without_errors_of_its_own_adds_none(write):
    found = errors(write, HEAD + "entity e { rules: r: topic /v.x > 1; }\nentity e { rules: r: topic /v.x > 2; }\n"
                                 "if (e.r) then { stop; }\n")
    assert [m.split(";")[0] for _, _, m in found] == ["duplicate name 'e' (an entity)"], found


@pytest.mark.parametrize("unit,expected", [
    ("C", "unknown unit 'C'; did you mean 'degC'?"),
    ("degc", "unknown unit 'degc'; did you mean 'degC'?"),
    ("volts", "unknown unit 'volts'; did you mean 'V'?"),
    ("K", "unknown unit 'K'; rubass has no kelvin: a temperature is written in degC"),
    ("°C", "expected ';', found '°C;' ('°' is no character of the language: write degC for a temperature, "
           "deg for an angle)"),
    ("µs", "expected ';', found 'µs;' ('µ' is no character of the language: write us for microseconds)"),
])
def test_a_unit_suggestion_is_one_the_spec_can_write(write, unit, expected):
    """'60 C' suggested '°C', which does not parse (acceptance sweep): a spec writes degC."""
    found = errors(write, HEAD + f"entity e {{ rules: r: topic /t.data > 60 {unit}; }}\nif (e.r) then {{ stop; }}\n")
    assert [m for _, _, m in found] == [expected], found
