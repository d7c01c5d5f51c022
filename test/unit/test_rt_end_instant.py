"""What falls due exactly at a test's duration is seen (TESTING.md: expectations up to the duration,
within the tolerance). Regression sweep finding: an `age() > 0.5 s` start due at the duration was
not (its crossing is scheduled a hair after its instant) while a `for` one was."""
from rubass.cli import main

LIB = "actions:\n  c: {plugin: log}\n"
SPEC = """import "lib.yaml";
action primitive c;
entity e { rules: silent: age(topic /cmd_vel) > 0.5 s; long: (topic /cmd_vel.linear.x > 0.1) for 1 s; }
silent: if (e.silent) then { c; }
long: if (e.long) then { c; }
"""
TESTS = """spec: s.rbs
tests:
  - name: an age crossing at the duration
    duration: 1.4 s
    topics:
      /cmd_vel: {type: geometry_msgs/Twist, rate: 10 Hz, field: linear.x, values: "0x10"}
    expect:
      - {at: 1.4 s, start: silent}
  - name: a for deadline at the duration
    duration: 1.5 s
    topics:
      /cmd_vel: {type: geometry_msgs/Twist, rate: 10 Hz, field: linear.x, values: "0.5x20"}
    expect:
      - {at: 1 s, start: long}
      - {never: silent}
"""


def test_a_start_due_at_the_duration_is_seen(tmp_path, capsys):
    (tmp_path / "lib.yaml").write_text(LIB)
    (tmp_path / "s.rbs").write_text(SPEC)
    (tmp_path / "s.test.yaml").write_text(TESTS)
    assert main(["test", str(tmp_path / "s.test.yaml")]) == 0, capsys.readouterr().out
