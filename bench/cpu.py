#!/usr/bin/python3
"""CPU per message of the monitor beside a bare rospy subscriber, on the same topics in one run.

Both are started the same way (a /usr/bin/python3 process on the same master) and subscribe to
the same publishers; each one's CPU (the run time of all its threads, /proc schedstat) over the
publishing window is divided by the messages published in it. Cases:
(a) 20 topics x 100 Hz (std_msgs/Float64), 100 rules, one behaviour over all of them, a third
    of the rules with `for 0.5 s`;
(b) a robot: /scan 40 Hz (1,081 ranges), /imu 200 Hz, /odom 50 Hz, /joint_states 100 Hz,
    /tf 120 Hz; 50 rules (laser sectors, speed limits with `for`, `age` on every topic,
    `frequency` on /scan, a node's cpu);
(c) a rate ramp of (a) and (b): every rate x1, x2, x4, ... until both lose messages (or the
    publisher cannot go faster); the highest rate each keeps without losing any.
Targets: ratio <= 1.5 in (a) and (b); in (c) the monitor keeps up to >= 80 % of the bare rate.
(c) publishes from up to 5 processes, all of them on the same machine as the subscribers.
Prints one JSON object per case. Usage: bench/cpu.py [--seconds S] [--cases abc] [--smoke]
[--receiver one_thread|rospy] (the monitor's ~receiver, to compare its two ways of reading)
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import psutil

import _common
from _rosbench import PY, PrivateMaster, start_monitor, stop_processes

from rubass.ros.nodes import _schedstat_seconds  # noqa: E402

PEER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "_cpu_peer.py")
HEAD = 'import "lib.yaml";\naction primitive stop;\n'


def spec_a(topics=20, rules=100):
    """(a): `rules` rules over the topics, a third with `for 0.5 s`, one behaviour over all."""
    body = []
    for i in range(rules):
        cond = f"topic /bench/load_{i % topics}.data > {2.5 + i % 5}"
        body.append(f"  l{i}: ({cond}) for 0.5 s;" if i % 3 == 0 else f"  l{i}: {cond};")
    anyof = " or ".join(f"load.l{i}" for i in range(rules))
    return HEAD + "entity load { rules:\n" + "\n".join(body) + f"\n}}\nif ({anyof}) then {{ stop; }}\n"


def spec_b():
    """(b): 50 rules of a mobile robot over its sensors."""
    r = [
        # laser sectors
        "front: min(topic /scan.ranges[360:720]) < 0.3 m;",
        "left: min(topic /scan.ranges[720:1081]) < 0.2 m;",
        "right: min(topic /scan.ranges[0:360]) < 0.2 m;",
        "front_near: (min(topic /scan.ranges[450:630]) < 0.5 m) for 0.2 s;",
        "scan_short: len(topic /scan.ranges) < 1000;",
        # speed limits, with `for`
        "too_fast: (abs(topic /odom.twist.twist.linear.x) > 0.8 m/s) for 0.5 s;",
        "too_fast_back: (topic /odom.twist.twist.linear.x < -0.3 m/s) for 0.5 s;",
        "spin: (abs(topic /odom.twist.twist.angular.z) > 1.0 rad/s) for 0.5 s;",
        "fast_near: too_fast and front_near;",
        "lateral: abs(topic /odom.twist.twist.linear.y) > 0.1 m/s;",
        "yaw_rate: (abs(topic /imu.angular_velocity.z) > 2.0 rad/s) for 0.3 s;",
        "bump_x: abs(topic /imu.linear_acceleration.x) > 8 m/s^2;",
        "bump_y: abs(topic /imu.linear_acceleration.y) > 8 m/s^2;",
        "tilt: (abs(topic /imu.orientation.x) > 0.2) for 1 s;",
        "falling: (topic /imu.linear_acceleration.z < 4 m/s^2) for 0.2 s;",
        # joints
        "j0_fast: abs(topic /joint_states.velocity[0]) > 3 rad/s;",
        "j1_fast: abs(topic /joint_states.velocity[1]) > 3 rad/s;",
        "j2_fast: (abs(topic /joint_states.velocity[2]) > 2 rad/s) for 0.5 s;",
        "j3_far: abs(topic /joint_states.position[3]) > 3 rad;",
        "j_effort: (topic /joint_states.effort[4] > 50) for 0.5 s;",
        "joints_short: len(topic /joint_states.position) < 12;",
        # tf
        "tf_jump: any(topic /tf.transforms[*].transform.translation.z > 1 m);",
        "tf_far: (topic /tf.transforms[0].transform.translation.x > 100 m) for 1 s;",
        # age of every topic, frequency of /scan, node cpu
        "scan_old: age(topic /scan) > 0.2 s;",
        "imu_old: age(topic /imu) > 50 ms;",
        "odom_old: age(topic /odom) > 0.1 s;",
        "joints_old: age(topic /joint_states) > 0.1 s;",
        "tf_old: age(topic /tf) > 0.1 s;",
        "scan_slow: frequency(topic /scan) < 30;",
        "pub_busy: cpu(node /bench_cpu_pub) > 95 %;",
        "odom_stale: stamp_age(topic /odom) > 0.5 s;",
        "sensors_old: scan_old or imu_old or odom_old;",
    ]
    for i in range(50 - len(r)):  # more speed and distance limits, as a real spec grows
        r.append(f"lim{i}: (abs(topic /odom.twist.twist.linear.x) > {1.0 + i / 10} m/s and "
                 f"min(topic /scan.ranges[{i * 50}:{i * 50 + 60}]) < {0.2 + i / 50} m) for 0.3 s;"
                 if i % 2 else f"lim{i}: abs(topic /imu.angular_velocity.{'xyz'[i % 3]}) > {3 + i / 10} rad/s;")
    names = [x.split(":")[0] for x in r]
    return (HEAD + "entity robot: /bench_cpu_pub; { rules:\n  " + "\n  ".join(r) + "\n}\n"
            "if (robot.front or robot.fast_near or robot.too_fast) then { stop; }\n"
            f"if ({' or '.join('robot.' + n for n in names if n.startswith('lim'))}) then {{ stop; }}\n"
            "if (robot.sensors_old or robot.tf_old or robot.joints_old or robot.scan_slow) then { stop; }\n")


def _cpu(pid):
    v = _schedstat_seconds(pid)
    return 0.0 if v is None else v


def _detail(pid):
    """(user s, system s, context switches) of a process, all its threads."""
    t = psutil.Process(pid).cpu_times()
    switches = 0
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/status") as fh:
                switches += sum(int(line.split()[1]) for line in fh if "ctxt_switches" in line)
        except (OSError, ValueError, IndexError):
            continue  # a thread that just exited
    return t.user, t.system, switches


def run_case(master, tmp, profile, spec, scale, seconds, parts=1, receiver="one_thread"):
    """One run: monitor and bare subscriber together, publishing at `scale` x the profile's rates
    from `parts` publisher processes (one Python publisher tops out at about 6,000 messages/s)."""
    bare = mon = None
    pubs = []
    try:
        bare = subprocess.Popen([PY, PEER, "bare", profile], env=master.env, stdout=subprocess.PIPE,
                                stderr=subprocess.DEVNULL, text=True, start_new_session=True)
        mon, _ = start_monitor(master, tmp, spec, receiver=receiver)
        for part in range(parts):
            pubs.append(subprocess.Popen([PY, PEER, "pub", profile, str(scale), str(seconds), "2", str(part), str(parts)],
                                         env=master.env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                         stderr=open(os.path.join(tmp, f"pub{part}.log"), "w"), text=True,
                                         start_new_session=True))
        if not all(p.stdout.readline().startswith("ready") for p in pubs):
            raise SystemExit("a publisher did not start: " + open(os.path.join(tmp, "pub0.log")).read()[-2000:])
        t0, c0 = time.monotonic(), (_cpu(mon.pid), _cpu(bare.pid))
        d0 = (_detail(mon.pid), _detail(bare.pid))
        for p in pubs:
            p.stdin.write("go\n")
            p.stdin.flush()
        outs = [json.loads(p.stdout.readline()) for p in pubs]
        time.sleep(0.3)  # what is still queued is handled (its CPU belongs to the window)
        t1, c1 = time.monotonic(), (_cpu(mon.pid), _cpu(bare.pid))
        d1 = (_detail(mon.pid), _detail(bare.pid))
        for p in pubs:
            p.wait(10)
    finally:
        stop_processes([p for p in pubs + [mon] if p is not None])
        if bare is not None:
            stop_processes([bare])
    done = {"published": sum(o["published"] for o in outs), "seconds": max(o["seconds"] for o in outs)}
    bare_out = [json.loads(x) for x in bare.stdout.read().splitlines() if x.startswith("{")]
    log = open(os.path.join(tmp, "monitor.log")).read()
    m = re.search(r"stopped after (\d+) messages? \((\d+) dropped", log)
    n = done["published"]
    mon_cpu, bare_cpu = c1[0] - c0[0], c1[1] - c0[1]
    mon_rx, mon_drop = (int(m.group(1)), int(m.group(2))) if m else (None, None)
    bare_rx = bare_out[0]["received"] if bare_out else None
    return {
        "published": n, "rate_msgs_per_s": round(n / done["seconds"], 1), "window_s": round(t1 - t0, 2),
        "monitor_cpu_us_per_msg": round(mon_cpu / n * 1e6, 1), "bare_cpu_us_per_msg": round(bare_cpu / n * 1e6, 1),
        "ratio": round(mon_cpu / bare_cpu, 2) if bare_cpu > 0 else None,
        "monitor_cpu_share": round(mon_cpu / (t1 - t0), 3), "bare_cpu_share": round(bare_cpu / (t1 - t0), 3),
        "monitor_received": mon_rx, "monitor_dropped": mon_drop, "bare_received": bare_rx,
        # where the CPU goes: user and system time (syscalls, wake-ups), and context switches, per message
        **{f"{who}_{what}_per_msg": round((d1[k][j] - d0[k][j]) / n * (1e6 if j < 2 else 1), 1 if j < 2 else 2)
           for k, who in enumerate(("monitor", "bare")) for j, what in enumerate(("user_us", "system_us", "ctx_switches"))},
        "monitor_lost": None if mon_rx is None else n - mon_rx + mon_drop,
        "bare_lost": None if bare_rx is None else n - bare_rx,
    }


def ramp(master, tmp, profile, spec, seconds, scales, parts, receiver):
    """Each scale in turn until both lose messages or the publisher falls behind its schedule."""
    steps, kept = [], {"monitor": 0.0, "bare": 0.0}
    for scale in scales:
        r = run_case(master, tmp, profile, spec, scale, seconds, parts, receiver)
        r["scale"] = scale
        steps.append(r)
        for who in kept:
            if r[f"{who}_lost"] == 0:
                kept[who] = max(kept[who], r["rate_msgs_per_s"])
        behind = r["rate_msgs_per_s"] < 0.8 * base_rate(profile) * scale  # the publisher is the limit
        r["publishers_behind"] = behind
        if (r["monitor_lost"] and r["bare_lost"]) or behind:
            break
    return steps, kept


def _topics(profile):
    sys.path.insert(0, os.path.dirname(PEER))
    from _cpu_peer import profile as topics_of
    return topics_of(profile)


def base_rate(profile):
    return sum(hz for _, _, hz in _topics(profile))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=_common.above_zero(float), default=10.0,
                    help="publishing window per run (default 10)")
    ap.add_argument("--cases", default="abc", help="which of a, b, c (default abc)")
    ap.add_argument("--smoke", action="store_true", help="tiny sizes, to check it works")
    _common.receiver_option(ap)
    args = ap.parse_args()
    if not args.cases or set(args.cases) - set("abc"):
        ap.error(f"argument --cases: letters of a, b and c (e.g. ab), not {args.cases!r}")
    seconds = 1.0 if args.smoke else args.seconds
    a_profile, a_spec = ("a2", spec_a(2, 6)) if args.smoke else ("a", spec_a())
    with tempfile.TemporaryDirectory() as tmp:
        master = PrivateMaster(os.path.join(tmp, "home"))
        try:
            cases = [("a", a_profile, a_spec), ("b", "b", spec_b())]
            for name, profile, spec in cases:
                if name in args.cases:
                    r = run_case(master, tmp, profile, spec, 1.0, seconds, receiver=args.receiver)
                    print(json.dumps({"benchmark": "cpu", "case": name, "receiver": args.receiver, **r,
                                      "target_ratio_le_1.5": r["ratio"] is not None and r["ratio"] <= 1.5,
                                      **_common.machine()}), flush=True)
            if "c" in args.cases:
                for name, profile, spec in cases:
                    scales = [1.0] if args.smoke else [1, 2, 4, 8, 16, 32]
                    parts = 1 if args.smoke else len(_topics(profile))
                    steps, kept = ramp(master, tmp, profile, spec, min(seconds, 5.0), scales, min(parts, 5),
                                       args.receiver)
                    ok = kept["bare"] > 0 and kept["monitor"] >= 0.8 * kept["bare"]
                    print(json.dumps({"benchmark": "cpu", "case": "c", "profile": name, "receiver": args.receiver,
                                      "monitor_kept_msgs_per_s": kept["monitor"], "bare_kept_msgs_per_s": kept["bare"],
                                      "target_monitor_ge_0.8_bare": ok, "steps": steps, **_common.machine()}), flush=True)
        finally:
            master.stop()


if __name__ == "__main__":
    sys.exit(main())
