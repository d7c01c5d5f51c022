"""A hand-written system model file: every problem at its line (docs/model.md), and indices
beyond a fixed-size array (acceptance findings)."""
import pytest

from rubass.lang import SpecError, load_spec
from rubass.lang.modelfile import dump_model, parse_model
from rubass.lang.source import Source

PACK = ("definitions:\n  acme_msgs/Pack: |\n    std_msgs/Header header\n    float32 pack_voltage\n"
        "    acme_msgs/Cell[] cells\n  acme_msgs/Cell: |\n    float32 voltage\n    float32 temp\n")


def problems(text):
    model, diags = parse_model(Source("robot.yaml", text))
    assert model is None or not diags
    return [f"{d.span.line}:{d.span.col}: {d.message}" for d in diags]


def test_a_good_hand_written_model_with_units_of_its_fields():
    assert problems("rubass_model: 1\ntopics:\n  /bms:\n    type: acme_msgs/Pack\n"
                    "    units: {pack_voltage: V, cells.voltage: V}\n"
                    "units:\n  acme_msgs/Cell: {voltage: V, temp: degC}\n  other_msgs/Unknown: {x: m}\n" + PACK) == []


@pytest.mark.parametrize("units,expected", [
    ("topics:\n  /bms:\n    type: acme_msgs/Pack\n    units: {pack_votlage: V}\n",
     "4:13: the units of topic '/bms': acme_msgs/Pack has no field 'pack_votlage'; did you mean 'pack_voltage'? "
     "(its fields: header, pack_voltage, cells)"),
    ("topics:\n  /bms: {type: acme_msgs/Pack, units: {cells.volts: V}}\n",
     "2:40: the units of topic '/bms': 'cells' (acme_msgs/Cell) has no field 'volts'; did you mean 'voltage'? "
     "(its fields: voltage, temp)"),
    ("topics: {}\nunits:\n  acme_msgs/Cell: {voltage: V, tmp: degC}\n",
     "3:32: the units of acme_msgs/Cell: acme_msgs/Cell has no field 'tmp'; did you mean 'temp'? "
     "(its fields: voltage, temp)"),
    ("topics: {}\nunits:\n  acme_msgs/Pack: {pack_voltage.x: V}\n",
     "3:20: the units of acme_msgs/Pack: 'pack_voltage' is a float32, not a message: it has no field 'x'"),
    ("topics: {}\nunits:\n  acme_msgs/Pack: {cells: V}\n",
     "3:20: the units of acme_msgs/Pack: 'cells' is an acme_msgs/Cell[], a message: it takes no unit"),
])
def test_units_of_a_field_the_definition_lacks_are_errors_at_the_field(units, expected):
    assert problems(units + PACK) == [expected]


@pytest.mark.parametrize("definition,expected", [
    ("    float64 x\n    flaot32 bad\n",
     "5:5: the definition of a_msgs/B: line 2: unknown field type 'flaot32'; did you mean 'float32'? "
     "(a primitive such as float64, a message of package a_msgs written 'Type', or 'package/Type')"),
    ("    float64 x\n\n    # c\n    uint8 x\n",
     "7:5: the definition of a_msgs/B: line 4: field 'x' is named twice (first on line 1)"),
])
def test_definition_problems_are_errors_at_their_line(definition, expected):
    assert problems("topics: {}\ndefinitions:\n  a_msgs/B: |\n" + definition) == [expected]


def test_every_definition_problem_at_once_and_types_that_may_be_installed_are_accepted():
    found = problems("topics: {}\ndefinitions:\n  a_msgs/B: |\n    flaot32 a\n    C c\n    Header h\n"
                     "    geometry_msgs/Twist t\n    Vector3 v\n    C[] a\n  a_msgs/C: |\n    strin s\n")
    assert [f.split(": line ")[0] for f in found] == [
        "4:5: the definition of a_msgs/B", "9:5: the definition of a_msgs/B", "11:5: the definition of a_msgs/C"]
    assert "field 'a' is named twice" in found[1] and "did you mean 'string'?" in found[2]


@pytest.mark.parametrize("version", ["7", "'1'", "true", "1.0"])
def test_an_unknown_format_version_is_an_error(version):
    assert problems(f"rubass_model: {version}\ntopics: {{}}\n") == [
        f"1:15: 'rubass_model' is the model file's format version: 1 is known here, got "
        f"{ {'7': 7, chr(39) + '1' + chr(39): '1', 'true': True, '1.0': 1.0}[version]!r} "
        f"(a newer rubass may have written it)"]


@pytest.mark.parametrize("text,expected", [
    ("topics:\n  /a: std_msgs/Float64\nnodes: []\ntopics:\n  /b: std_msgs/Float64\n", "4:1: key 'topics'"),
    ("topics:\n  /a: std_msgs/Float64\n  /a: std_msgs/String\n", "3:3: key '/a'"),
    ("topics:\n  /a: {type: a_msgs/B, units: {x: V, x: A}}\n", "2:38: key 'x'"),
])
def test_a_key_written_twice_is_an_error_at_the_second(text, expected):
    found = problems(text)
    assert [f[:len(expected)] for f in found] == [expected], found
    assert "is written twice in one mapping" in found[0] and "YAML would keep only the last" in found[0]


def test_a_written_model_reads_back_without_problems():
    model, diags = parse_model(Source("robot.yaml", "topics:\n  /bms: acme_msgs/Pack\n" + PACK))
    assert diags == []
    assert problems(dump_model(model, "a test")) == []


def test_an_index_beyond_a_fixed_size_array_is_an_error_at_its_place(tmp_path):
    model, _ = parse_model(Source("robot.yaml", "topics:\n  /fix: sensor_msgs/NavSatFix\ndefinitions:\n"
                                                "  sensor_msgs/NavSatFix: |\n    float64[9] position_covariance\n"
                                                "    float64[] free\n"))
    spec = ("action primitive stop;\nentity gps { rules: ok: topic /fix.position_covariance[8] > 1;\n"
            "  last: topic /fix.position_covariance[-9] > 1; any: topic /fix.free[100] > 1;\n"
            "  bad: topic /fix.position_covariance[9] > 1; }\n")
    (tmp_path / "s.rbs").write_text(spec)
    with pytest.raises(SpecError) as info:
        load_spec(str(tmp_path / "s.rbs"), model=model)
    found = [f"{d.span.line}:{d.span.col}: {d.message}" for d in info.value.diagnostics if "beyond" in d.message]
    assert found == ["4:8: 'position_covariance[9]' is beyond the end of 'position_covariance', a float64[9]: "
                     "its indices are 0 to 8"]
