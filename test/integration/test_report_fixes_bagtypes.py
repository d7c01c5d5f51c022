"""`rubass report --bag` refuses a recording whose types the spec cannot read, as `rubass replay` and
`rubass check --bag` do: the errors at the spec's line, exit 1, the recording shown as not replayed."""
import os
import subprocess
import sys

import pytest

pytest.importorskip("rosbag")

from conftest import ROOT, shared_path  # noqa: E402

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")


def rubass(*args):
    proc = subprocess.run([sys.executable, "-m", "rubass", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=180)
    return proc.returncode, proc.stdout, proc.stderr


def spec(tmp_path, rule):
    path = tmp_path / "s.rbs"
    path.write_text(f'import "{LIB}";\naction primitive stop;\nentity base {{\n  rules:\n    @id("SR-1") @hazard("H1") {rule}\n}}\n'
                    'overspeed: if (base.fast) then { stop; }\n')
    return str(path)


@pytest.mark.parametrize("rule, error", [
    ("fast: topic /odom.twist.linear.x > 0.2 m/s;",
     ":5:37: error: 'twist' (geometry_msgs/TwistWithCovariance) has no field 'linear'"),
    ("fast: topic /odom.pose.pose.position.x > 3 s;", ":5:70: error: compares a length with a time"),
])
def test_report_refuses_a_recording_the_spec_cannot_read(tmp_path, rule, error):
    bag = shared_path("data", "turtlebot3_sim.bag")
    path = spec(tmp_path, rule)
    out = str(tmp_path / "r.html")
    code, _, check_err = rubass("check", "--bag", bag, path)
    assert code == 1 and path + error in check_err
    code, stdout, err = rubass("report", path, "--bag", bag, "-o", out)
    assert code == 1
    assert path + error in err  # the same error, at its place
    assert f"not replayed: {bag}" in stdout
    page = open(out, encoding="utf-8").read()
    assert "not replayed" in page and "No behaviour started" not in page and "<svg" not in page.split("Recordings")[1]


def test_report_replays_a_recording_the_spec_reads(tmp_path):
    bag = shared_path("data", "turtlebot3_sim.bag")
    path = spec(tmp_path, "fast: topic /odom.twist.twist.linear.x > 0.2 m/s;")
    out = str(tmp_path / "r.html")
    code, stdout, err = rubass("report", path, "--bag", bag, "-o", out)
    assert "not replayed" not in stdout + err
    page = open(out, encoding="utf-8").read()
    assert "1 / 1</b>recordings replayed" in page and "not replayed" not in page
