"""`rubass test`: a topic two tests declare with different types is checked with each test's own types
(F2b item 3): every error once, naming the test whose types show it."""
import pytest

from rubass.cli import main

LIB = """actions:
  warn: {plugin: log, level: warn}
"""
SPEC = """import "lib.yaml";
action primitive warn;
entity base {
  rules:
    far: topic /odom.twist.twist.linear.x > 0.5 m;
    late: topic /odom.linear.x > 1 s;
    wide: topic /scan.range_max > 3 s;
}
if (base.far or base.late or base.wide) then { warn; }
"""
ODOM_TEST = """  - name: {name}
    topics:
      /odom: {{type: nav_msgs/Odometry, rate: 10 Hz, field: twist.twist.linear.x, values: "0x5"}}
{scan}    expect:
      - {{never: warn}}
"""
TWIST_TEST = """  - name: twist
    topics:
      /odom: {type: geometry_msgs/Twist, rate: 10 Hz, field: linear.x, values: "0x5"}
    expect:
      - {never: warn}
"""
SCAN = """      /scan: {type: sensor_msgs/LaserScan, rate: 10 Hz, field: range_max, values: "5x5"}
"""


def run(capsys, *args):
    code = main(["test", *args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def setup(write):
    write("lib.yaml", LIB)

    def make(spec, tests):
        rbs = write("w.rbs", spec)
        return rbs, write("w.test.yaml", "spec: w.rbs\ntests:\n" + tests)

    return make


def col(rbs, line, text):
    return open(rbs).read().splitlines()[line - 1].index(text) + 1


def test_a_speed_compared_with_a_length_is_found_though_another_test_types_the_topic_otherwise(setup, capsys):
    spec = SPEC.replace("    late: topic /odom.linear.x > 1 s;\n", "").replace(
        "    wide: topic /scan.range_max > 3 s;\n", "").replace(" or base.late or base.wide", "")
    rbs, path = setup(spec, ODOM_TEST.format(name="odometry", scan="") + TWIST_TEST)
    code, out, err = run(capsys, path)
    assert code == 2, out + err
    assert f"{path}:1: error: spec {rbs} does not fit the types of the topics test 'odometry' (line 3) declares" \
           in err, err
    assert f"{rbs}:5:{col(rbs, 5, '> 0.5 m')}: error: compares a speed with a length" in err, err
    assert f"{path}:10: error: rule 'base.far' reads /odom.twist.twist.linear.x, but in geometry_msgs/Twist" in err


def test_each_combination_of_types_shows_its_own_errors_once(setup, capsys):
    tests = ODOM_TEST.format(name="odometry", scan=SCAN) + TWIST_TEST + ODOM_TEST.format(name="again", scan="")
    rbs, path = setup(SPEC, tests)
    code, out, err = run(capsys, path)
    assert code == 2, out + err
    far = f"{rbs}:5:{col(rbs, 5, '> 0.5 m')}: error: compares a speed with a length"
    late = f"{rbs}:6:{col(rbs, 6, '> 1 s')}: error: compares a speed with a time"
    wide = f"{rbs}:7:{col(rbs, 7, '> 3 s')}: error: compares a length with a time"
    for said in (far, late, wide):
        assert err.count(said) == 1, err  # once, though two tests declare /odom a nav_msgs/Odometry
    heads = [line for line in err.splitlines() if "does not fit the types" in line]
    assert [h.split(" the topics ")[1].split(" (as ")[0] for h in heads] == [
        "this file declares",  # /scan: one type in the file
        "test 'odometry' (line 3) declares",
        "test 'twist' (line 9) declares"], err
    blocks = err.split("does not fit the types")
    assert wide in blocks[1] and far in blocks[2] and late in blocks[3], err
    assert "again" not in err  # its types are those of 'odometry'
    assert out.rstrip().endswith("0 passed, 0 failed") and "not run: " in out
