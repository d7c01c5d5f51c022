"""The spec's warnings against a recording with a topic in two types (an acceptance sweep): they were
those of the topic's first type only, so `stamp_age()` of /speed recorded as Float64 then TwistStamped
was said "always unknown" though the replay's own output gave it values, and in the reverse order,
where it is unknown for most of the recording, nothing was said. Each warning now names the type it
holds for, in replay and check --bag alike."""
import subprocess
import sys

import pytest

from conftest import ROOT

rosbag = pytest.importorskip("rosbag")
pytestmark = pytest.mark.ros

T0 = 1700000000.0
LIB = "actions:\n  stop: {plugin: publish, topic: /cmd_vel, type: geometry_msgs/Twist, message: {}, rate: 20 Hz}\n"


def recording(path, stamped_first):
    import genpy
    from geometry_msgs.msg import TwistStamped
    from std_msgs.msg import Float64

    def stamped(s):
        m = TwistStamped()
        m.header.stamp = genpy.Time.from_sec(T0 + s - 3.0)  # 3 s old
        return m

    kinds = [stamped, lambda s: Float64(data=0.1)]
    kinds = kinds if stamped_first else kinds[::-1]
    with rosbag.Bag(str(path), "w") as bag:
        for i in range(20):
            bag.write("/speed", kinds[0](i * 0.1), genpy.Time.from_sec(T0 + i * 0.1))
        bag._topic_connections.pop("/speed", None)  # a second connection, as `rosbag record` writes
        for i in range(30):
            bag.write("/speed", kinds[1](2 + i * 0.1), genpy.Time.from_sec(T0 + 2 + i * 0.1))
    return str(path)


@pytest.mark.parametrize("stamped_first", [False, True])
def test_a_warning_of_one_recorded_type_names_that_type(tmp_path, stamped_first):
    (tmp_path / "lib.yaml").write_text(LIB)
    spec = tmp_path / "s.rbs"
    spec.write_text('import "lib.yaml";\naction primitive stop;\nentity e { rules: r: stamp_age(topic /speed) > 1 s; }\n'
                    "if (e.r) then { stop; }\n")
    bag = recording(tmp_path / "two.bag", stamped_first)
    expected = ("/speed is recorded as std_msgs/Float64 too in two.bag (first as geometry_msgs/TwistStamped): this "
                "is the spec read against std_msgs/Float64" if stamped_first else
                "this holds for its std_msgs/Float64 messages only (/speed is recorded as geometry_msgs/TwistStamped "
                "too in two.bag)")
    for args in (["replay", str(spec), bag], ["check", "--bag", bag, str(spec)]):
        proc = subprocess.run([sys.executable, "-m", "rubass", *args], cwd=ROOT, capture_output=True, text=True,
                              timeout=120)
        assert proc.returncode == 0, proc.stderr
        lines = [line for line in proc.stderr.splitlines() if "warning: stamp_age(topic /speed) is always unknown" in line]
        assert len(lines) == 1 and lines[0].endswith(expected), (args[0], proc.stderr)
