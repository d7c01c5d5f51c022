"""What the ROS benchmarks share: a monitor on a generated spec, peers, load publishers."""
import json
import os
import subprocess
import sys

import _common
from rubass_experiments.master import PrivateMaster, stop_processes, wait_for_service
from rubass_experiments.procs import supervise_script

# a benchmark is a command that starts processes: SIGINT/SIGTERM/SIGHUP run its `finally` blocks and
# exit 128+n, and whatever it started dies with it even when it is SIGKILLed (issue 19)
supervise_script(os.path.basename(sys.argv[0]) or "bench")

__all__ = ["PEER", "PY", "LIB", "PrivateMaster", "stop_processes", "spec_text", "start_monitor", "start_load", "run_peer"]

PEER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "_peer.py")
PY = "/usr/bin/python3"
# one stop per start: the action's periodic re-publication (every 10,000 s) never falls in a run, soak included
LIB = "actions:\n  stop: {plugin: publish, topic: /bench/stop, type: std_msgs/Header, message: {}, rate: 0.0001 Hz}\n"


def spec_text(load_topics, load_rules, hit="topic /bench/cmd.point.x > 1"):
    """The benchmark spec: the measured rule, and `load_rules` others over the load topics."""
    rules = [f"  hit: {hit};"]
    for i in range(load_rules):
        rules.append(f"  l{i}: (topic /bench/load_{i % load_topics}.data > {10 + i % 5}) for 1 s;")
    return ('import "lib.yaml";\naction primitive stop;\nentity bench { rules:\n' + "\n".join(rules) +
            "\n}\nif (bench.hit) then { stop; }\n")


def start_monitor(master, tmp, spec, name="rubass", **params):
    with open(os.path.join(tmp, "lib.yaml"), "w") as fh:
        fh.write(LIB)
    path = os.path.join(tmp, "bench.rbs")
    with open(path, "w") as fh:
        fh.write(spec)
    args = [PY, os.path.join(_common.ROOT, "scripts", "monitor"), f"__name:={name}", f"_spec:={path}"]
    args += [f"_{k}:={v}" for k, v in params.items()]
    mon = master.spawn(args, log=os.path.join(tmp, "monitor.log"))
    try:
        wait_for_service(f"/{name}/reset", mon, master.uri, 60)
    except BaseException:  # a stop signal (Interrupted) or a monitor that did not start: the caller never has it
        stop_processes([mon])
        raise
    return mon, path


def start_load(master, topics, hz, per_process=50):
    """Load publishers: `topics` topics at `hz`, at most `per_process` topics per process."""
    return [master.spawn([PY, PEER, "load", str(min(per_process, topics - first)), str(hz), str(first)])
            for first in range(0, topics, per_process)]


def run_peer(master, args, timeout):
    out = subprocess.run([PY, PEER] + args, env=master.env, capture_output=True, text=True, timeout=timeout)
    if out.returncode != 0:
        raise SystemExit(out.stderr)
    return json.loads(out.stdout.strip().splitlines()[-1])
