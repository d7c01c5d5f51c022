"""The package builds in a catkin workspace and rosrun finds it there."""
import os
import shutil
import subprocess

import pytest

from conftest import ROOT

pytestmark = [pytest.mark.ros, pytest.mark.slow]


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    if not shutil.which("catkin_make"):
        pytest.skip("catkin_make is not installed")
    ws = tmp_path_factory.mktemp("ws")
    src = ws / "src" / "rubass"
    src.parent.mkdir()
    shutil.copytree(ROOT, src, ignore=shutil.ignore_patterns(".git", ".venv*", "__pycache__", "out", ".hypothesis"))
    env = dict(os.environ, ROS_HOME=str(ws / "ros_home"))
    build = subprocess.run(["catkin_make", "-C", str(ws), "-DPYTHON_EXECUTABLE=/usr/bin/python3"], cwd=ws, env=env,
                           capture_output=True, text=True, timeout=300)
    assert build.returncode == 0, build.stdout[-3000:] + build.stderr[-3000:]
    return ws


def in_workspace(ws, command):
    """Run a shell command with the workspace's devel space sourced, from outside the repo."""
    return subprocess.run(["bash", "-c", f"source {ws}/devel/setup.bash && {command}"], cwd="/",
                          capture_output=True, text=True, timeout=120,
                          env={k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "PYTHONPATH"))})


def test_rosrun_finds_the_command(workspace):
    proc = in_workspace(workspace, "rosrun rubass rubass check $(rospack find rubass)/config/kobuki.rbs")
    assert proc.returncode == 0, proc.stderr
    assert "kobuki.rbs: ok (4 rules" in proc.stdout


def test_rubass_is_on_path_and_package_paths_resolve(workspace, tmp_path):
    spec = tmp_path / "s.rbs"
    spec.write_text('import "package://rubass/config/kobuki_actions.yaml";\naction primitive stop;\n'
                    "entity e { rules: r: topic /x.data > 1; }\nif (e.r) then { stop; }\n")
    proc = in_workspace(workspace, f"rubass check {spec}")
    assert proc.returncode == 0, proc.stderr


def test_rosrun_starts_the_monitor_from_the_workspace(workspace, ros, tmp_path):
    (tmp_path / "s.rbs").write_text('import "package://rubass/config/kobuki_actions.yaml";\n'
                                    "action primitive stop;\nentity e { rules: r: topic /x.data > 1; }\n"
                                    "if (e.r) then { stop; }\n")
    env = {k: v for k, v in ros.env.items() if k not in ("PYTHONPATH", "ROS_PACKAGE_PATH")}
    cmd = f"source {workspace}/devel/setup.bash && exec rosrun rubass monitor __name:=rubass _spec:={tmp_path}/s.rbs"
    proc = subprocess.Popen(["bash", "-c", cmd], env=env, cwd="/", stdout=open(tmp_path / "mon.log", "w"),
                            stderr=subprocess.STDOUT, start_new_session=True)
    ros.procs.append(proc)
    proc.log_path = tmp_path / "mon.log"
    ros.wait_service("/rubass/reset", proc, timeout=30)
    assert "success: True" in ros.call("/rubass/reset").stdout
