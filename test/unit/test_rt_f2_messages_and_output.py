"""`rubass test`: error wording and suggestions, the JUnit file's folder, and the wrong interpreter."""
import sys

import pytest

from rubass.cli import main
from rubass.lang.units import unit_suggestion
from rubass.testing.messages import MessageError, NoRosPython, convert, message_class

LIB = """actions:
  warn: {plugin: log, level: warn}
"""
SPEC = """import "lib.yaml";
action primitive warn;
entity base {
  rules:
    @id("SR-1") @hazard("H1")
    high: topic /fix.altitude > 100 m;
}
climb: if (base.high) then { warn; }
"""
FIX = """spec: w.rbs
tests:
  - name: t
    covers: [{covers}]
    topics:
      /fix:
        type: sensor_msgs/NavSatFix
        messages:
          - {{at: 1 s, {fields}}}
"""


def run(capsys, *args):
    code = main(["test", *args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def files(write):
    write("lib.yaml", LIB)
    write("w.rbs", SPEC)

    def make(fields="altitude: 3", covers="SR-1"):
        return write("w.test.yaml", FIX.format(fields=fields, covers=covers))

    return make


def test_a_fraction_for_a_nested_integer_field_reads_plainly(files, capsys):
    """Was: `'status'.status is a int8: 1.5 is not an integer`."""
    path = files("status: {status: 1.5}")
    code, _, err = run(capsys, path)
    assert code == 2
    assert f"{path}:9: error: /fix (sensor_msgs/NavSatFix): status.status is an int8: 1.5 is not an integer" in err


@pytest.mark.parametrize("slot,value,said", [
    ("int8", 1.5, "x is an int8: 1.5 is not an integer"),
    ("uint8", 1.5, "x is a uint8: 1.5 is not an integer"),
    ("float64", "a", "x is a float64: 'a' is not a number"),
])
def test_articles(slot, value, said):
    with pytest.raises(MessageError) as exc:
        convert(slot, value, "x")
    assert str(exc.value) == said


def test_a_misspelt_field_of_an_explicit_message_gets_a_suggestion(files, capsys):
    path = files("altitud: 3")
    code, _, err = run(capsys, path)
    assert code == 2 and "sensor_msgs/NavSatFix has no field 'altitud'; did you mean 'altitude'?" in err, err


def test_a_misspelt_nested_field_gets_a_suggestion(files, capsys):
    path = files("status: {statos: 1}")
    code, _, err = run(capsys, path)
    assert code == 2 and "'status' (sensor_msgs/NavSatStatus) has no field 'statos'; did you mean 'status'?" in err


def test_a_covers_typo_suggests_the_close_id(files, capsys):
    path = files(covers="SR-01")
    code, _, err = run(capsys, path)
    assert code == 0
    assert f"{path}:4: warning: test 't' covers 'SR-01', which is no @id or @hazard of the spec; did you mean " \
           f"'SR-1'?" in err, err


@pytest.mark.parametrize("unit,said", [
    ("m/sec", "; did you mean 'm/s'?"),  # was 'sec': a compound unit is suggested whole
    ("deg/sec", "; did you mean 'deg/s'?"),
    ("km/hr", "; did you mean 'km/h'?"),
    ("rad/sec^2", "; did you mean 'rad/s^2'?"),
    ("m/s2", "; did you mean 'm/s^2'?"),
    ("secs", "; did you mean 's'?"),
    ("mm/s", "; a speed is written in m/s, cm/s, km/h"),
    ("qq", ""),
])
def test_unit_suggestions(unit, said):
    assert unit_suggestion(unit) == said


def test_a_series_unit_typo_suggests_the_unit(write, capsys):
    write("lib.yaml", LIB)
    write("w.rbs", SPEC.replace("/fix.altitude > 100 m", "/odom.twist.twist.linear.x > 1 m/s"))
    path = write("w.test.yaml", "spec: w.rbs\ntests:\n  - name: t\n    topics:\n      /odom:\n"
                                "        type: nav_msgs/Odometry\n        rate: 10 Hz\n"
                                "        field: twist.twist.linear.x\n        values: \"0.6m/secx3\"\n")
    code, _, err = run(capsys, path)
    assert code == 2 and "'m/sec' is not a unit rubass knows; did you mean 'm/s'?" in err, err


# --junit into a folder that does not exist ---------------------------------------------------------------------

def test_junit_creates_its_folder(files, tmp_path, capsys):
    path = files()
    out_xml = tmp_path / "out" / "deeper" / "tests.xml"
    code, out, err = run(capsys, path, "--junit", str(out_xml))
    assert code == 0, out + err
    assert out_xml.read_text().startswith("<?xml") and "testcase" in out_xml.read_text()


def test_junit_whose_folder_cannot_be_made_says_so(files, tmp_path, capsys):
    path = files()
    blocker = tmp_path / "out"
    blocker.write_text("a file, not a folder")
    code, out, err = run(capsys, path, "--junit", str(blocker / "tests.xml"))
    assert code == 2 and out.rstrip().splitlines()[-1] == "1 passed, 0 failed"
    assert f"rubass test: error: cannot write {blocker}/tests.xml: cannot create the folder {blocker}: " in err, err


# an interpreter without ROS Python ------------------------------------------------------------------------------

def test_no_ros_python_names_the_interpreter(monkeypatch):
    monkeypatch.setitem(sys.modules, "genpy", None)  # `import genpy` raises ImportError, as with no ROS
    with pytest.raises(NoRosPython) as exc:
        message_class("geometry_msgs/Twist")
    text = str(exc.value)
    assert "is not installed" not in text
    assert f"interpreter ({sys.executable}) cannot import" in text and text.endswith("run rubass with /usr/bin/python3")


def test_no_ros_python_is_one_error_for_the_file(files, write, monkeypatch, capsys):
    path = write("w.test.yaml", FIX.format(fields="altitude: 3", covers="SR-1") +
                 "  - name: u\n    topics:\n      /odom: {type: nav_msgs/Odometry, rate: 1 Hz, field: "
                 "twist.twist.linear.x, values: \"0\"}\n")
    monkeypatch.setitem(sys.modules, "roslib.message", None)
    code, _, err = run(capsys, path)
    assert code == 2
    assert err.count("error:") == 1 and f"{path}:7: error: message type sensor_msgs/NavSatFix needs ROS 1's " \
                                       f"Python message support" in err, err
