"""`header.stamp` read as a field (a sensor-sync check), not only through stamp_age().

Acceptance finding: the engine left the stamp out of the fields it reads (stamp_age reads it on its
own), so `abs(topic /odom.header.stamp - topic /imu.header.stamp) > 0.2 s` was unknown forever:
never true, never false, with no word from check, replay, the tests or the monitor."""
from rubass.cli import main

LIB = "actions:\n  c: {plugin: log}\n"
SPEC = """import "lib.yaml";
action primitive c;
entity s {
  rules:
    skew: abs(topic /odom.header.stamp - topic /imu.header.stamp) > 0.2 s;
    stale: stamp_age(topic /odom) > 5 s;
}
SKEW: if (s.skew) then { c; }
IN_SYNC: if (not s.skew) then { c; }
"""
TESTS = """spec: s.rbs
tests:
  - name: skewed stamps
    duration: 2 s
    topics:
      /odom: {type: nav_msgs/Odometry, messages: [{at: 0.5 s, header: {stamp: 1.1}}]}
      /imu: {type: sensor_msgs/Imu, messages: [{at: 0.5 s, header: {stamp: 1.5}}]}
    expect:
      - {at: 0.5 s, start: SKEW}
      - {never: IN_SYNC}
  - name: stamps in sync
    duration: 2 s
    topics:
      /odom: {type: nav_msgs/Odometry, messages: [{at: 0.5 s, header: {stamp: 1.1}}]}
      /imu: {type: sensor_msgs/Imu, messages: [{at: 0.5 s, header: {stamp: 1.2}}]}
    expect:
      - {at: 0.5 s, start: IN_SYNC}
      - {never: SKEW}
"""


def test_a_rule_on_header_stamps_gets_values(tmp_path, capsys):
    (tmp_path / "lib.yaml").write_text(LIB)
    (tmp_path / "s.rbs").write_text(SPEC)
    (tmp_path / "s.test.yaml").write_text(TESTS)
    assert main(["test", str(tmp_path / "s.test.yaml")]) == 0, capsys.readouterr().out
