"""Header stamps against the engine's time (LANGUAGE.md §11, TESTING.md): in rule tests a message
at 0 s has a real stamp (only `stamp: 0` is the zero stamp)."""
import textwrap

from rubass.cli import main

SPEC = """action primitive warn;
entity imu { rules: stale: stamp_age(topic /imu) > 0.5 s; }
stale_imu: if (imu.stale) then { warn; }
"""
LIB = "actions:\n  warn: {plugin: log}\n"


def run_tests(tmp_path, capsys, tests):
    (tmp_path / "lib.yaml").write_text(LIB)
    (tmp_path / "s.rbs").write_text('import "lib.yaml";\n' + SPEC)
    path = tmp_path / "s.test.yaml"
    path.write_text("spec: s.rbs\ntests:\n" + textwrap.indent(textwrap.dedent(tests), "  "))
    code = main(["test", str(path)])
    out, err = capsys.readouterr()
    return code, out + err


def test_a_message_at_0_s_has_a_real_stamp(tmp_path, capsys):
    code, out = run_tests(tmp_path, capsys, """\
        - name: one message at 0 s then silence is stale at 0.5 s
          duration: 2 s
          topics:
            /imu:
              type: sensor_msgs/Imu
              messages: [{at: 0 s}]
          expect: [{at: 0.5 s, start: stale_imu}]
        - name: a stamp set 1 s in the past is stale at once
          duration: 2 s
          topics:
            /imu:
              type: sensor_msgs/Imu
              messages: [{at: 1.2 s, header: {stamp: 0.2}}]
          expect: [{at: 1.2 s, start: stale_imu}]
        """)
    assert code == 0, out
    assert "2 passed, 0 failed" in out


def test_the_zero_stamp_is_unknown_so_it_never_fires(tmp_path, capsys):
    code, out = run_tests(tmp_path, capsys, """\
        - name: zero stamp
          duration: 3 s
          topics:
            /imu:
              type: sensor_msgs/Imu
              messages: [{at: 0.5 s, header: {stamp: 0}}]
          expect: [{never: stale_imu}]
        """)
    assert code == 0, out
