"""`~nice`: every thread of the monitor runs at it, and /diagnostics says the value, or that it
was refused (the monitor then runs as started and still enforces)."""
import os
import pathlib
import pwd
import shutil
import tempfile

import pytest
from rosharness import PY, brake_after, monitor_values, spec

from conftest import ROOT

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SPEC = "entity a { rules:\n  fast: topic /cmd_vel.linear.x > 1;\n}\nif (a.fast) then { brake; }\n"


def thread_nice_values(pid):
    out = set()
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/stat") as fh:
                out.add(int(fh.read().rsplit(")", 1)[1].split()[16]))
        except FileNotFoundError:  # a thread that ended meanwhile
            pass
    return out


@pytest.mark.skipif(os.geteuid() != 0, reason="a nice value below 0 needs root")
def test_every_thread_runs_at_the_nice_value_and_diagnostics_show_it(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, SPEC), nice=-5)
    assert monitor_values(ros)["nice"] == "-5"
    assert thread_nice_values(mon.pid) == {-5}, ros.log(mon)
    assert "running at nice -5 (~nice)" in ros.log(mon)
    assert brake_after(ros, 2.0), ros.log(mon)
    os.setpriority(os.PRIO_PROCESS, mon.pid, -3)  # as `renice -p PID`: the main thread only
    values = monitor_values(ros)["nice"]
    assert values.startswith("mixed: -5 (") and values.endswith("threads), -3 (1 thread)"), values


@pytest.mark.skipif(os.geteuid() != 0 or shutil.which("setpriv") is None, reason="drops from root with setpriv")
def test_a_refused_nice_is_a_warning_and_the_monitor_still_enforces(ros):
    """A user without the right: the monitor as `nobody`, no capability (its files where nobody reads)."""
    home, mon = tempfile.mkdtemp(prefix="rubass-nice-"), None
    try:
        os.chmod(home, 0o777)
        nobody = pwd.getpwnam("nobody")
        os.mkdir(os.path.join(home, "log"))  # rospy's own would be chowned to the folder's owner, root, and fail:
        os.chown(os.path.join(home, "log"), nobody.pw_uid, nobody.pw_gid)  # its log lines then go nowhere
        path = spec(pathlib.Path(home), SPEC)
        # the code too: a checkout in root's home (a fresh machine's /root/…) is no place nobody may read
        shutil.copytree(os.path.join(ROOT, "rubass"), os.path.join(home, "rubass"),
                        ignore=shutil.ignore_patterns("__pycache__"))
        os.mkdir(os.path.join(home, "scripts"))
        shutil.copy(os.path.join(ROOT, "scripts", "monitor"), os.path.join(home, "scripts", "monitor"))
        env = dict(ros.env, ROS_HOME=home, ROS_LOG_DIR=os.path.join(home, "log"), HOME=home)
        env["PYTHONPATH"] = os.pathsep.join([home] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep)
                                                      if p and os.path.realpath(p) != os.path.realpath(ROOT)])
        mon = ros.spawn(["setpriv", "--reuid=nobody", "--regid=nogroup", "--clear-groups", "--inh-caps=-all",
                         PY, os.path.join(home, "scripts", "monitor"), "__name:=rubass", f"_spec:={path}",
                         "_nice:=-5", f"_state_file:={os.path.join(home, 'latches.json')}"], "monitor-nobody", env=env)
        ros.wait_service("/rubass/reset", mon)
        values = monitor_values(ros)
        assert values["nice"] == "0 (~nice -5 was not permitted)", values
        assert thread_nice_values(mon.pid) == {0}
        assert "~nice -5: not permitted" in ros.log(mon) and "Traceback" not in ros.log(mon)
        assert brake_after(ros, 2.0), ros.log(mon)  # still enforcing
    finally:
        if mon is not None and mon.poll() is None:  # before its folder goes
            mon.terminate()
            mon.wait(15)
        shutil.rmtree(home, ignore_errors=True)
