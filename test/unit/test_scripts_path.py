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


SCRIPTS = sorted(os.listdir(os.path.join(ROOT, "scripts")))


def test_every_script_has_the_fallback():
    """All of them: the demo's simulated robots too (acceptance finding: `roslaunch rubass
    kobuki_sim.launch` from a plain checkout left only the monitor running, the robot's nodes
    dead with ModuleNotFoundError)."""
    assert {"monitor", "agent", "rubass", "kobuki_sim", "frobit_sim", "goal_driver", "fault_injector"} <= set(SCRIPTS)
    for name in SCRIPTS:
        text = open(os.path.join(ROOT, "scripts", name)).read()
        assert "sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.realpath(__file__))))" in text, name


def test_every_script_imports_its_main_from_a_plain_checkout(tmp_path):
    """Each script up to its last line (the call of main) runs from another folder with no PYTHONPATH."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    for name in SCRIPTS:
        path = os.path.join(ROOT, "scripts", name)
        code = ("import sys; p = sys.argv[1]; lines = open(p).read().rstrip().splitlines(); "
                "exec(compile(chr(10).join(lines[:-1]), p, 'exec'), {'__file__': p, '__name__': 'x'}); print('ok')")
        out = subprocess.run(["/usr/bin/python3", "-c", code, path], cwd=str(tmp_path), env=env,
                             capture_output=True, text=True, timeout=60)
        assert out.returncode == 0 and out.stdout.strip() == "ok", (name, out.stderr[-500:])
