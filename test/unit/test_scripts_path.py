"""The product's scripts run from a plain checkout (rosrun finds them on ROS_PACKAGE_PATH without
a catkin build): they find the rubass package beside them (acceptance finding: ModuleNotFoundError)."""
import os
import subprocess

from conftest import ROOT


def test_the_cli_script_runs_from_a_plain_checkout_with_no_pythonpath(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    out = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "rubass"), "check",
                          os.path.join(ROOT, "config", "kobuki.rbs")],
                         cwd=str(tmp_path), env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and "ok" in out.stdout, out.stderr


def test_every_product_script_has_the_fallback():
    for name in ("monitor", "agent", "rubass"):
        text = open(os.path.join(ROOT, "scripts", name)).read()
        assert "sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.realpath(__file__))))" in text, name
