"""A recording whose definition of one topic's type cannot be read (a custom message recorded with a
broken definition). An acceptance sweep: all four commands refused the whole recording even when the
spec never read that topic, and `report --bag` said the spec "cannot read this recording's types".
Now only a spec that reads that topic's fields is refused (replay, check --bag, report --bag);
`model --bag` still refuses to write a model with a type it cannot describe."""
import io
import subprocess
import sys

import pytest

from conftest import ROOT

rosbag = pytest.importorskip("rosbag")
pytestmark = pytest.mark.ros

T0 = 1700000000.0
LIB = "actions:\n  stop: {plugin: publish, topic: /cmd_vel, type: geometry_msgs/Twist, message: {}, rate: 20 Hz}\n"
BROKEN = "flaot64 data\n!!! nonsense\n"


def at(s):
    import genpy

    return genpy.Time.from_sec(T0 + s)


def broken_on(path, topic):
    """/speed Float64 0.1 then 0.9 from 2 s; `topic` (maybe /speed) also as acme_msgs/X with a broken definition."""
    from std_msgs.msg import Float64

    md5 = "0123456789abcdef0123456789abcdef"

    class Cls:
        _md5sum = md5

    with rosbag.Bag(str(path), "w") as bag:
        for i in range(50):
            bag.write("/speed", Float64(data=0.1 if i < 20 else 0.9), at(i * 0.1))
        bag._topic_connections.pop(topic, None)  # a second connection on it, as `rosbag record` writes
        buf = io.BytesIO()
        Float64(data=1.0).serialize(buf)
        header = {"topic": topic, "type": "acme_msgs/X", "md5sum": md5, "message_definition": BROKEN}
        for i in range(10):
            bag.write(topic, ("acme_msgs/X", buf.getvalue(), md5, None, Cls), at(1 + i * 0.1), raw=True,
                      connection_header=header)
    return str(path)


def spec(tmp_path, rule):
    (tmp_path / "lib.yaml").write_text(LIB)
    path = tmp_path / "s.rbs"
    path.write_text(f'import "lib.yaml";\naction primitive stop;\nentity e {{ rules: r: {rule}; }}\n'
                    "if (e.r) then { stop; }\n")
    return str(path)


def rubass(*args):
    return subprocess.run([sys.executable, "-m", "rubass", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=120)


@pytest.mark.parametrize("rule", ["topic /speed.data > 0.5 for 1 s", "age(topic /speed) > 0.5 s"])
def test_a_broken_definition_on_a_topic_the_spec_does_not_read_refuses_nothing(tmp_path, rule):
    bag, path = broken_on(tmp_path / "other.bag", "/other"), spec(tmp_path, rule)
    replay = rubass("replay", path, bag)
    assert replay.returncode == 0 and "Traceback" not in replay.stderr, replay.stderr
    if "data" in rule:
        assert "start" in replay.stdout and "e.r" in replay.stdout, replay.stdout
    check = rubass("check", "--bag", bag, path)
    assert check.returncode == 0 and f"{path}: ok" in check.stdout, check.stderr
    report = rubass("report", path, "--bag", bag, "-o", str(tmp_path / "r.html"))
    assert "cannot read" not in report.stderr and "not replayed" not in report.stderr, report.stderr
    assert "not replayed" not in (tmp_path / "r.html").read_text()


def test_a_broken_definition_on_a_topic_the_spec_reads_is_refused_by_each_command(tmp_path):
    bag, path = broken_on(tmp_path / "speed.bag", "/speed"), spec(tmp_path, "topic /speed.data > 0.5")
    said = f"{bag}: topic /speed: acme_msgs/X: line 2: cannot read '!!! nonsense'"
    replay = rubass("replay", path, bag)
    assert replay.returncode == 1 and said in replay.stderr, replay.stderr
    check = rubass("check", "--bag", bag, path)
    assert check.returncode == 2 and f"rubass: error: {said}" in check.stderr, check.stderr
    assert "Traceback" not in replay.stderr + check.stderr


def test_model_bag_still_refuses_a_type_it_cannot_describe(tmp_path):
    bag = broken_on(tmp_path / "other.bag", "/other")
    model = rubass("model", "--bag", bag, "-o", str(tmp_path / "m.yaml"))
    assert model.returncode == 2 and "topic /other: acme_msgs/X: line 2: cannot read" in model.stderr, model.stderr
