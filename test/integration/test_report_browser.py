"""The report rendered by a real browser (headless Chromium, Debian's `chromium`): it loads offline,
its matrix, tests and timeline are in the rendered page, and a screenshot comes out."""
import os
import shutil
import signal
import subprocess

import pytest

from rubass.cli import main

from conftest import ROOT

pytestmark = pytest.mark.slow


def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    pytest.skip("chromium is not installed (tools/deps.sh installs Debian's chromium)")


def _run(args, tmp_path, timeout=90):
    """Run headless Chromium in its own session and profile; kill its whole group on any exit."""
    cmd = [_chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--no-first-run",
           f"--user-data-dir={tmp_path / 'profile'}", "--disable-background-networking", *args]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True,
                            env={**os.environ, "HOME": str(tmp_path)})
    try:
        out, err = proc.communicate(timeout=timeout)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    return proc.returncode, out.decode("utf-8", "replace"), err.decode("utf-8", "replace")


def _bag(path):
    rosbag = pytest.importorskip("rosbag")
    import rospy
    from geometry_msgs.msg import Twist

    with rosbag.Bag(path, "w") as b:
        for k in range(40):
            m = Twist()
            m.linear.x = 0.3 if k < 10 else 0.62
            b.write("/mobile_base/commands/velocity", m, rospy.Time.from_sec(1000 + 0.1 * k))
    return path


def test_report_renders_in_chromium(tmp_path, capsys):
    out = str(tmp_path / "kobuki.html")
    code = main(["report", os.path.join(ROOT, "config", "kobuki.rbs"),
                 "--tests", os.path.join(ROOT, "config", "tests", "kobuki.test.yaml"),
                 "--hazards", os.path.join(ROOT, "config", "kobuki_hazards.yaml"),
                 "--bag", _bag(str(tmp_path / "run.bag")), "-o", out])
    assert code == 0, capsys.readouterr()
    url = "file://" + out
    rc, dom, err = _run(["--dump-dom", url], tmp_path)
    assert rc == 0, err[-2000:]
    assert "Hazard → rule → behaviour → test" in dom
    assert "SR-K1" in dom and "no rule" in dom  # H8 (tip-over) has no rule: a gap, marked
    assert "<svg" in dom and "6 passed, 0 failed" in dom
    png = tmp_path / "report.png"
    rc, _, err = _run(["--window-size=1200,2000", f"--screenshot={png}", url], tmp_path)
    assert rc == 0 and png.exists(), err[-2000:]
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 50_000  # a rendered page, not a blank one
