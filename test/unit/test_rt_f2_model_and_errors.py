"""`rubass test`: the spec checked against the topic types the file declares (units, as `check --bag`),
and every error of a file reported in one run, in line order."""
import os

import pytest

from rubass.cli import main

LIB = """actions:
  stop: {plugin: log, level: warn}
  warn: {plugin: log, level: warn}
"""
SPEC = """import "lib.yaml";
action primitive stop, warn;
entity base {
  rules:
    fast: topic /odom.twist.twist.linear.x > LIMIT;
}
caution: if (base.fast) then { warn; }
"""
ODOM = """spec: w.rbs
{model}tests:
  - name: t
    topics:
      /odom:
        type: nav_msgs/Odometry
        rate: 10 Hz
        field: twist.twist.linear.x
        values: "0x10 4x10"
"""


def run(capsys, *args):
    code = main(["test", *args])
    out, err = capsys.readouterr()
    return code, out, err


def line_of(path, text):
    return next(k + 1 for k, line in enumerate(open(path, encoding="utf-8")) if text in line)


@pytest.fixture
def spec(write):
    write("lib.yaml", LIB)

    def make(limit):
        return write("w.rbs", SPEC.replace("LIMIT", limit))

    return make


def test_a_unit_error_the_declared_types_show_is_an_error_at_the_spec_line(spec, write, capsys):
    """The test declares /odom a nav_msgs/Odometry: twist.twist.linear.x is a speed (REP 103), so
    `> 3 s` is the error `rubass check --bag` and `rubass replay` report (it passed, exit 0)."""
    rbs = spec("3 s")
    path = write("w.test.yaml", ODOM.format(model=""))
    code, out, err = run(capsys, path)
    assert code == 2, out + err
    col = open(rbs).read().splitlines()[4].index("> 3 s") + 1
    assert f"{path}:1: error: spec {rbs} does not fit the types of the topics this file declares" in err, err
    assert f"{rbs}:5:{col}: error: compares a speed with a time" in err, err
    assert "PASS" not in out and out.rstrip().endswith(f"not run: 1 error in {path}\n0 passed, 0 failed")


def test_the_right_unit_still_passes(spec, write, capsys):
    spec("3 m/s")
    path = write("w.test.yaml", ODOM.format(model="") + "    expect:\n      - {at: 1 s, start: caution}\n")
    code, out, err = run(capsys, path)
    assert code == 0 and "PASS  t" in out and not err, out + err


def test_a_model_with_topics_only_takes_the_installed_definitions(spec, write, capsys):
    """A hand-written `model:` naming /odom's type without its definition: the installed one gives the
    units, as `rubass check --model` does (it passed)."""
    rbs = spec("3 s")
    write("robot.model.yaml", "rubass_model: 1\ntopics:\n  /odom: nav_msgs/Odometry\n")
    path = write("w.test.yaml", ODOM.format(model="model: robot.model.yaml\n"))
    code, out, err = run(capsys, path)
    assert code == 2 and f"{path}:1: error: spec {rbs} cannot be used" in err, err
    assert "compares a speed with a time" in err


def test_a_field_the_declared_type_lacks_stays_an_error_at_the_topic_line(spec, write, capsys):
    """The declared type is what the test shows: a field it lacks is said at the test's topic, naming the type."""
    spec("3 m/s")
    path = write("w.test.yaml", """spec: w.rbs
tests:
  - name: t
    topics:
      /odom: {type: geometry_msgs/Twist, rate: 10 Hz, field: linear.x, values: "0x10"}
""")
    code, _, err = run(capsys, path)
    assert code == 2 and f"{path}:5: error: rule 'base.fast' reads /odom.twist.twist.linear.x, but in " \
                         f"geometry_msgs/Twist" in err, err
    assert "does not fit" not in err


def test_a_topic_two_tests_give_two_types_is_not_checked_against_either(spec, write, capsys):
    spec("3 m/s")
    path = write("w.test.yaml", ODOM.format(model="") + """  - name: u
    topics:
      /odom: {type: std_msgs/Float64, rate: 10 Hz, field: data, values: "0x10"}
""")
    code, out, err = run(capsys, path)
    assert "does not fit" not in err and "cannot be used" not in err, err
    assert "rule 'base.fast' reads /odom.twist.twist.linear.x, but in std_msgs/Float64" in err  # test u's own error


# every error of a file in one run ------------------------------------------------------------------------------

def test_every_error_of_a_file_in_line_order(spec, write, capsys):
    """An unknown behaviour (line 11) and an unknown key (line 12): both, in line order (only 12 was said)."""
    spec("3 m/s")
    path = write("w.test.yaml", ODOM.format(model="") + """    expect:
      - {at: 1 s, start: cautoin}
      - {at: 2 s, strat: caution}
""")
    code, out, err = run(capsys, path)
    assert code == 2
    lines = [l for l in err.splitlines() if ": error: " in l]
    assert lines == [
        f"{path}:11: error: 'cautoin' is neither a behaviour's name nor a declared action; did you mean 'caution'?",
        f"{path}:12: error: unknown key 'strat' in an expectation; did you mean 'start'? (keys: at, start, release, "
        f"never, active, from, to, tolerance)"], err
    assert out.rstrip().endswith(f"not run: 2 errors in {path}\n0 passed, 0 failed")


def test_errors_of_several_tests_keys_and_messages_all_come(spec, write, capsys):
    spec("3 m/s")
    path = write("w.test.yaml", """spec: w.rbs
tests:
  - name: a
    duraton: 3 s
    topics:
      /fix:
        type: sensor_msgs/NavSatFix
        messages:
          - {at: 1 s, altitud: 3}
          - {at: 2 s, status: {status: 1.5}}
  - name: b
    nodes:
      controller:
        - {at: 0 s, cpu: lots}
    expect:
      - {at: 1 s, start: 9}
""")
    code, _, err = run(capsys, path)
    assert code == 2
    said = [int(l.split(":")[1]) for l in err.splitlines() if ": error: " in l]
    assert said == [line_of(path, "duraton"), line_of(path, "altitud"), line_of(path, "status: 1.5"),
                    line_of(path, "cpu: lots"), line_of(path, "start: 9")], err


def test_a_spec_error_and_a_file_error_together(spec, write, capsys):
    rbs = write("lib.yaml", LIB) and write("w.rbs", "entity base { rules: r: topic /x.data > 1 qq; }\n")
    path = write("w.test.yaml", "spec: w.rbs\ntests:\n  - name: t\n    expct: []\n")
    code, _, err = run(capsys, path)
    assert code == 2
    assert err.index(f"{path}:1: error: spec {rbs} cannot be used") < err.index(f"{path}:4: error: unknown key 'expct'")


def test_the_file_error_order_is_kept_for_one_error(write, capsys):
    """A file with one error still says it once, as before."""
    write("lib.yaml", LIB)
    write("w.rbs", SPEC.replace("LIMIT", "3 m/s"))
    path = write("w.test.yaml", "spec: w.rbs\ntests: []\n")
    code, _, err = run(capsys, path)
    assert code == 2 and err.strip() == f"{path}:2: error: tests is empty: a file needs at least one test"
    assert os.path.exists(path)


def test_a_misspelt_required_key_is_said_with_its_suggestion(write, capsys):
    """`spce:` for `spec:`: the unknown key with its did-you-mean, not only the missing spec."""
    path = write("w.test.yaml", "spce: w.rbs\ntests:\n  - name: t\n")
    code, _, err = run(capsys, path)
    assert code == 2
    assert err.strip() == f"{path}:1: error: unknown key 'spce' in a test file; did you mean 'spec'? (keys: spec, " \
                          f"actions, model, tests)", err


def test_an_index_past_a_fixed_size_array_is_the_models_error(write, capsys):
    """What only the model sees (float64[9] has no [9]) stays an error, as `check --bag` says it."""
    write("lib.yaml", LIB)
    rbs = write("w.rbs", SPEC.replace("/odom.twist.twist.linear.x > LIMIT", "/fix.position_covariance[9] > 1"))
    path = write("w.test.yaml", "spec: w.rbs\ntests:\n  - name: t\n    topics:\n      /fix:\n"
                                "        type: sensor_msgs/NavSatFix\n        messages: [{at: 1 s, altitude: 3}]\n")
    code, _, err = run(capsys, path)
    assert code == 2 and f"{path}:1: error: spec {rbs} does not fit" in err, err
    assert "beyond the end of 'position_covariance'" in err
