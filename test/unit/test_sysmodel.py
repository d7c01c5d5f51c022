"""The system model, pure: .msg text parsing, field paths resolved to kinds and units, the model
file, missing topics and nodes. No ROS: definitions are written out here."""
import pytest

from rubass.lang import ast
from rubass.lang.grammar import parse_source
from rubass.lang.modelfile import dump_model, parse_model
from rubass.lang.msgdef import DefinitionError, Registry, parse_full, parse_msg, parse_srv
from rubass.lang.source import Source
from rubass.lang.std_units import joint_state_units
from rubass.lang.sysmodel import SystemModel, graph_warnings
from rubass.lang.units import GEO_DEGREE, UNITS, VOLTAGE, dim, parse_quantity

HEADER = "uint32 seq\ntime stamp\nstring frame_id\n"
VECTOR3 = "float64 x\nfloat64 y\nfloat64 z\n"
LASERSCAN = """# Single scan from a planar laser range-finder
Header header            # timestamp in the header is the acquisition time
float32 angle_min        # start angle of the scan [rad]
float32 angle_max
float32 angle_increment
float32 time_increment
float32 scan_time
float32 range_min
float32 range_max
float32[] ranges
float32[] intensities
"""
TWIST_FULL = """# This expresses velocity in free space broken into its linear and angular parts.
Vector3  linear
Vector3  angular

================================================================================
MSG: geometry_msgs/Vector3
# This represents a vector in free space.
float64 x
float64 y
float64 z"""
BATTERY = "my_msgs/Cell[4] cells\nfloat32 pack_voltage\nstring name\nbool ok\nuint8 MODE_A = 1\n" \
          "string LABEL = a # not a comment\nduration uptime\n"
CELL = "float32 voltage\nfloat32 temp\n"


def registry():
    r = Registry()
    r.add(parse_msg("std_msgs/Header", HEADER))
    r.add(parse_msg("sensor_msgs/LaserScan", LASERSCAN))
    r.add_full("geometry_msgs/Twist", TWIST_FULL)
    r.add(parse_msg("my_msgs/Battery", BATTERY))
    r.add(parse_msg("my_msgs/Cell", CELL))
    return r


def model(**kw):
    return SystemModel({"/scan": "sensor_msgs/LaserScan", "cmd_vel": "geometry_msgs/Twist",
                        "/battery": "my_msgs/Battery", "/ghost": "ghost_msgs/Ghost"},
                       kw.pop("nodes", None), registry(), **kw)


# -- .msg text ----------------------------------------------------------------------------
def test_parse_msg_fields_constants_and_arrays():
    spec = parse_msg("my_msgs/Battery", BATTERY)
    assert spec.names == ["cells", "pack_voltage", "name", "ok", "uptime"]  # constants left out
    cells = spec.get("cells")
    assert (cells.type, cells.is_array, cells.length) == ("my_msgs/Cell", True, 4)
    assert parse_msg("sensor_msgs/LaserScan", LASERSCAN).get("header").type == "std_msgs/Header"


def test_parse_full_splits_dependencies():
    specs = parse_full("geometry_msgs/Twist", TWIST_FULL)
    assert set(specs) == {"geometry_msgs/Twist", "geometry_msgs/Vector3"}
    assert specs["geometry_msgs/Twist"].get("linear").type == "geometry_msgs/Vector3"  # same package


def test_parse_srv_and_errors():
    req, resp = parse_srv("std_srvs/SetBool", "bool data\n---\nbool success\nstring message\n")
    assert req.names == ["data"] and resp.names == ["success", "message"]
    with pytest.raises(DefinitionError, match="line 2"):
        parse_msg("a/B", "float64 x\nthis is not a field at all\n")
    with pytest.raises(DefinitionError, match="---"):
        parse_srv("a/S", "bool data\n")


def test_definition_text_round_trips():
    spec = parse_msg("my_msgs/Battery", BATTERY)
    assert parse_msg("my_msgs/Battery", spec.text()) == spec


# -- field paths ----------------------------------------------------------------------------
@pytest.mark.parametrize("topic,path,kind,dimension", [
    ("/cmd_vel", ("linear", "x"), "num", dim(m=1, s=-1)),
    ("cmd_vel", ("angular", "z"), "num", dim(rad=1, s=-1)),
    ("/scan", ("ranges",), "array", dim(m=1)),
    ("/scan", ("ranges", 3), "num", dim(m=1)),
    ("/scan", ("ranges", ast.Slice(0, 90)), "array", dim(m=1)),
    ("/scan", ("angle_min",), "num", dim(rad=1)),
    ("/scan", ("scan_time",), "num", dim(s=1)),
    ("/scan", ("intensities", 0), "num", None),
    ("/scan", ("header", "stamp"), "num", dim(s=1)),
    ("/scan", ("header", "frame_id"), "str", None),
    ("/battery", ("ok",), "bool", None),
    ("/battery", ("cells",), "array", None),
    ("/battery", ("cells", 0, "voltage"), "num", None),
    ("/battery", ("uptime",), "num", dim(s=1)),
])
def test_field_kinds_and_standard_units(topic, path, kind, dimension):
    info = model().field(topic, path)
    assert (info.kind, info.dim) == (kind, dimension)


def test_array_elements_of_messages():
    info = model().field("/battery", ("cells",))
    assert info.elem_kind == "msg"
    assert model().field("/scan", ("ranges",)).elem_kind == "num"


@pytest.mark.parametrize("topic,path,why", [
    ("/cmd_vel", ("linaer", "x"), "geometry_msgs/Twist has no field 'linaer'; did you mean 'linear'?"),
    ("/cmd_vel", ("linear", "w"), "'linear' (geometry_msgs/Vector3) has no field 'w'"),
    ("/scan", ("ranges", "x"), "'ranges' is an array (float32[]): index it, e.g. 'ranges[0].x'"),
    ("/scan", ("angle_min", "x"), "'angle_min' is a float32, not a message: it has no field 'x'"),
    ("/scan", ("angle_min", 0), "'angle_min' is not an array"),
])
def test_missing_fields_say_why(topic, path, why):
    info = model().field(topic, path)
    assert info.kind == "missing" and why in info.why


def test_a_message_is_not_a_value():
    info = model().field("/cmd_vel", ("linear",))
    assert info.kind == "msg" and info.why == "it is a geometry_msgs/Vector3 (fields: x, y, z)"


def test_unknown_topics_and_types_say_nothing():
    m = model()
    assert m.field("/nope", ("x",)) is None
    assert m.field("/ghost", ("x",)) is None  # a type without a definition cannot be checked
    assert m.has_stamp("/scan") is True and m.has_stamp("/cmd_vel") is False and m.has_stamp("/nope") is None
    assert m.undefined_types() == ["ghost_msgs/Ghost"]


def test_custom_units_per_type_and_per_topic():
    m = model(units={"my_msgs/Cell": {"voltage": VOLTAGE}, "my_msgs/Battery": {"pack_voltage": VOLTAGE}},
              topic_units={"/scan": {"intensities": dim()}})
    assert m.field("/battery", ("cells", 1, "voltage")).dim == VOLTAGE
    assert m.field("/battery", ("pack_voltage",)).dim == VOLTAGE
    assert m.field("/scan", ("intensities", 0)).dim == dim()


def test_joint_state_units_by_joint_kind():
    assert joint_state_units({"l": "continuous", "r": "revolute"})["velocity"] == dim(rad=1, s=-1)
    assert joint_state_units({"lift": "prismatic"})["position"] == dim(m=1)
    assert joint_state_units({"l": "continuous", "lift": "prismatic"}) == {}
    assert joint_state_units({}) == {}


# -- units --------------------------------------------------------------------------------
def test_new_units():
    assert parse_quantity("12 V") == (12.0, dim(V=1))
    assert parse_quantity("500 mA") == (0.5, dim(A=1))
    assert parse_quantity("40 degC") == parse_quantity("40 °C") == (40.0, dim(degC=1))
    assert parse_quantity("101.3 kPa")[0] == pytest.approx(101300.0)
    assert "C" not in UNITS  # coulomb or Celsius: not guessed
    assert GEO_DEGREE not in [d for _, d in UNITS.values()]  # latitude has no unit: compare bare numbers


# -- the model file -------------------------------------------------------------------------
def test_model_file_round_trip():
    m = model(nodes=["/driver", "base"], units={"my_msgs/Cell": {"voltage": VOLTAGE}},
              topic_units={"/scan": {"intensities": dim()}})
    text = dump_model(m, "a test")
    back, diags = parse_model(Source("robot.yaml", text))
    assert diags == []
    assert back.topics == m.topics and back.nodes == ["/base", "/driver"]
    assert back.field("/battery", ("cells", 0, "voltage")).dim == VOLTAGE
    assert back.field("/cmd_vel", ("linear", "x")).dim == dim(m=1, s=-1)
    assert back.field("/scan", ("intensities", 0)).dim == dim()
    assert "the system model robot.yaml (from a test)" == back.source


def test_hand_written_model_file():
    text = "topics:\n  /cmd_vel: geometry_msgs/Twist\n  /bms:\n    type: my_msgs/Battery\n" \
           "    units: {pack_voltage: V}\nnodes: [driver]\n"
    m, diags = parse_model(Source("robot.yaml", text))
    assert diags == [] and m.topics == {"/cmd_vel": "geometry_msgs/Twist", "/bms": "my_msgs/Battery"}
    assert m.topic_units["/bms"] == {"pack_voltage": VOLTAGE} and m.nodes == ["/driver"]
    assert m.undefined_types() == ["geometry_msgs/Twist", "my_msgs/Battery"]


@pytest.mark.parametrize("text,where,msg", [
    ("topics: [a]\n", "robot.yaml:1:9", "'topics' must be a mapping"),
    ("topics:\n  /a: Twist\n", "robot.yaml:2:7", "must be a message type 'package/Type'"),
    ("topics:\n  /a: {type: a/B, units: {x: furlong}}\n", "robot.yaml:2:30", "'furlong' is not an SI unit"),
    ("topics:\n  /a: {type: a/B, units: {x: cm}}\n", "robot.yaml:2:30", "'cm' is not an SI unit"),
    ("topics: {}\ntopic: {}\n", "robot.yaml:2:1", "unknown key 'topic'; did you mean 'topics'?"),
    ("nodes: []\n", "robot.yaml:1:1", "needs a key 'topics'"),
    ("topics: {}\ndefinitions:\n  a/B: |\n    float64 x y z\n", "robot.yaml:4:5", "the definition of a/B"),
    # the bad line of a block, not its 'Type: |' line
    ("topics: {}\ndefinitions:\n  a/B: |\n    float64 x\n\n    # c\n    flot64[ y\n", "robot.yaml:7:5", "line 4: cannot read"),
    ("topics: {}\ndefinitions:\n  a/B: \"float64 x y z\"\n", "robot.yaml:3:8", "the definition of a/B"),
    ("topics: {a: [\n", "robot.yaml:2:1", "invalid YAML"),
    ("topics: {}\nnodes: 3\n", "robot.yaml:2:8", "'nodes' must be a list"),
    ("topics:\n  /a: !foo x\n", "robot.yaml:2:7", "YAML tag '!foo' is not allowed"),
    ("topics: !!python/object:os.system {}\n", "robot.yaml:1:9", "is not allowed: a system model holds plain data"),
    ("topics:\n  3: a/B\n", "robot.yaml:2:3", "'3' is not a topic name"),
    ("topics: {}\nnodes: [/driver, bad name!]\n", "robot.yaml:2:18", "'bad name!' is not a node name"),  # sweep
    ("\x00", "robot.yaml:1:1", "invalid YAML"),
])
def test_model_file_errors_point_at_the_line(text, where, msg):
    m, diags = parse_model(Source("robot.yaml", text))
    assert m is None
    assert any(str(d.span) == where and msg in d.message for d in diags), [f"{d.span} {d.message}" for d in diags]


# -- topics and nodes the model lacks -------------------------------------------------------
SPEC = """action primitive stop;
entity base: driver, mobile_base {
  rules:
    fast: topic /cmd_vell.linear.x > 1 m/s;
    again: topic /cmd_vell.linear.y > 1 m/s;
    hot: cpu(node driver) > 50 %;
    ok: topic cmd_vel.linear.x > 0;
}
if (base.fast) then { stop; }
"""


def test_graph_warnings_with_suggestions():
    spec = parse_source(Source("s.rbs", SPEC))
    warnings = graph_warnings(spec, model(nodes=["/driver", "/mobile_base_node"]))
    text = [f"{d.span}: {d.severity}: {d.message}" for d in warnings]
    assert text == [
        "s.rbs:2:22: warning: node 'mobile_base' is not in the system model; did you mean '/mobile_base_node'?",
        "s.rbs:4:11: warning: topic '/cmd_vell' is not in the system model; did you mean '/cmd_vel'?",
    ]


def test_no_node_warnings_when_the_source_lists_no_nodes():
    spec = parse_source(Source("s.rbs", SPEC))
    assert [d.message.split(" is")[0] for d in graph_warnings(spec, model())] == ["topic '/cmd_vell'"]


def test_new_units_in_a_spec():
    from rubass.lang.errors import SpecError
    from rubass.lang.loader import check_text

    c = check_text("const V1 = 12 V;\nconst I1 = 500 mA;\nconst T1 = 40 degC;\nconst P1 = 1 kPa;\n"
                   "const W = V1 * I1;\nconst AA = 2 rad/s^2;\n")
    assert c.consts == {"V1": 12.0, "I1": 0.5, "T1": 40.0, "P1": 1000.0, "W": 6.0, "AA": 2.0}
    with pytest.raises(SpecError, match="cannot add or subtract a voltage and a current"):
        check_text("const X = 12 V + 1 A;\n")


def test_a_topic_nobody_publishes_is_a_warning():
    spec = parse_source(Source("s.rbs", SPEC.replace("/cmd_vell", "/scan")))
    warnings = graph_warnings(spec, model(unpublished={"scan"}))
    assert [f"{d.span}: {d.message}" for d in warnings] == [
        "s.rbs:4:11: topic '/scan' has no publisher in the system model: its data would never come"]


def test_fields_of_a_topic_whose_type_has_no_definition_are_a_warning_once():
    """`check --live` with a publisher whose definition could not be read (hung, type not installed) said
    ok and checked nothing of it; `model --live` warned (acceptance sweep)."""
    text = ("action primitive stop;\nentity e { rules:\n  a: topic /ghost.levl > 1;\n  b: topic /ghost.x > 2;\n"
            "  c: age(topic /ghost) > 1 s;\n}\nif (e.a) then { stop; }\n")
    warnings = graph_warnings(parse_source(Source("s.rbs", text)), model())
    assert [f"{d.span}: {d.message}" for d in warnings] == [
        "s.rbs:3:6: the fields of topic '/ghost' cannot be checked: the system model gives no definition of "
        "ghost_msgs/Ghost"]


def test_urdf_joint_kinds():
    from rubass.lang.std_units import urdf_joint_kinds

    text = '<robot name="r"><joint name="a" type="continuous"/><joint name="m" type="fixed"/>' \
           '<joint name="lift" type="prismatic"/></robot>'
    assert urdf_joint_kinds(text) == {"a": "continuous", "lift": "prismatic"}
    with pytest.raises(ValueError, match="not a URDF"):
        urdf_joint_kinds("<sdf/>")
    with pytest.raises(ValueError, match="not valid XML"):
        urdf_joint_kinds("<robot")


def test_quantifiers_and_array_terms_check_against_a_model():
    """any/all/count over `[*]` and slices, and len() of a whole array of messages, are accepted
    with a model (they were rejected as 'is an array' whenever a model was given)."""
    from rubass.lang.loader import check_source

    text = ("entity e { rules:\n"
            "  low: any(topic /battery.cells[*].voltage < 3.2 V);\n"
            "  hot: count(topic /battery.cells[0:2].temp > 60) >= 1;\n"
            "  near: all(topic /scan.ranges[*] > 0.2 m);\n"
            "  four: len(topic /battery.cells) == 4;\n"
            "  front: min(topic /scan.ranges[0:90]) < 0.4 m;\n}\n")
    checked = check_source(Source("q.rbs", text), model=model())
    assert {r.key for r in checked.rules} == {"e.low", "e.hot", "e.near", "e.four", "e.front"}


def test_a_quantifier_over_a_field_that_is_not_there_says_why_with_a_model():
    from rubass.lang.errors import SpecError
    from rubass.lang.loader import check_source

    text = "entity e { rules:\n  low: any(topic /battery.cells[*].volts < 3.2);\n}\n"
    with pytest.raises(SpecError, match=r"q.rbs:2:12: .*has no field 'volts'"):
        check_source(Source("q.rbs", text), model=model())


def test_a_private_topic_is_the_monitors_own_in_the_model():
    """`~scan` is the default monitor's /rubass/scan (topicnames.py); it was looked up as '/~scan'."""
    m = SystemModel({"/rubass/scan": "sensor_msgs/LaserScan"}, None, registry())
    assert m.field("~scan", ("ranges",)).kind == "array"
    assert m.field("/scan", ("ranges",)) is None
