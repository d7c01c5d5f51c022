#!/usr/bin/python3
"""Engine cost of language version 2 (docs/spec/LANGUAGE.md §10–15); prints one JSON object per figure.

(a) engine CPU per message with v2 operators in the mix (within, latch, rate, stamp_age, a
    sector, a zone, active()) at 10, 100 and 1,000 rules: target <= 10 us and flat;
(b) a 1,081-beam LaserScan (with inf and NaN) watched by three sector rules: target <= 50 us;
(c) parse + check of 1,000 v2 rules: target < 1 s.
Targets are met on CPU time (time.process_time), which other load on the machine barely
changes; wall-clock p50/p99 per message are printed too.
Usage: bench/engine_v2.py [--messages N] [--scans N] [--rules N] [--repeat K]
"""
import argparse
import json
import math
import os
import random
import statistics
import time

import _common  # noqa: F401  (sys.path)
from rubass.engine import UNKNOWN, Engine  # noqa: E402
from rubass.lang import check_text  # noqa: E402
from rubass.lang.grammar import parse_source  # noqa: E402
from rubass.lang.source import Source  # noqa: E402

SPEC_PATH = os.path.join(_common.ROOT, "bench_v2.rbs")


# Shaped like deserialised rospy messages (attributes with __slots__, Time with to_sec()).
class Time:
    __slots__ = ("secs", "nsecs")

    def __init__(self, t: float) -> None:
        self.secs, self.nsecs = int(t), int(round((t - int(t)) * 1e9))

    def to_sec(self) -> float:
        return self.secs + self.nsecs * 1e-9


class Header:
    __slots__ = ("seq", "stamp", "frame_id")

    def __init__(self, t: float) -> None:
        self.seq, self.stamp, self.frame_id = 0, Time(t), "base_link"


class Vector3:
    __slots__ = ("x", "y", "z")

    def __init__(self, x: float = 0.0, y: float = 0.0, z: float = 0.0) -> None:
        self.x, self.y, self.z = x, y, z


class Twist:
    __slots__ = ("linear", "angular")

    def __init__(self, vx: float, wz: float) -> None:
        self.linear, self.angular = Vector3(vx), Vector3(0.0, 0.0, wz)


class TwistHolder:
    __slots__ = ("twist",)

    def __init__(self, vx: float, wz: float) -> None:
        self.twist = Twist(vx, wz)


class Pose:
    __slots__ = ("position",)

    def __init__(self, x: float, y: float) -> None:
        self.position = Vector3(x, y)


class PoseHolder:
    __slots__ = ("pose",)

    def __init__(self, x: float, y: float) -> None:
        self.pose = Pose(x, y)


class Odometry:
    __slots__ = ("header", "pose", "twist")

    def __init__(self, t: float, x: float, y: float, vx: float, wz: float) -> None:
        self.header, self.pose, self.twist = Header(t), PoseHolder(x, y), TwistHolder(vx, wz)


class LaserScan:
    __slots__ = ("header", "angle_min", "angle_max", "angle_increment", "range_min", "range_max", "ranges")

    def __init__(self, t: float, ranges: tuple) -> None:
        self.header = Header(t)
        self.angle_min, self.angle_max = -math.radians(135), math.radians(135)
        self.angle_increment = math.radians(0.25)
        self.range_min, self.range_max = 0.05, 30.0
        self.ranges = ranges  # rospy deserialises float32[] into a tuple


HOT = """const AREA = polygon((0 m, 0 m), (8 m, 0 m), (8 m, 5 m), (3 m, 5 m), (3 m, 3 m), (0 m, 3 m));
entity hot { rules:
  fast: latch(abs(topic /odom.twist.twist.linear.x) > 0.5 m/s,
              (abs(topic /odom.twist.twist.linear.x) < 0.4 m/s) for 0.5 s);
  bump: topic /odom.twist.twist.linear.x > 0.9 m/s within 1 s;
  spin_up: abs(rate(topic /odom.twist.twist.angular.z)) > 3 rad/s^2;
  stale: stamp_age(topic /odom) > 200 ms;
  outside: not inside(topic /odom.pose.pose.position.x, topic /odom.pose.pose.position.y, AREA);
  margin: distance(topic /odom.pose.pose.position.x, topic /odom.pose.pose.position.y, AREA) < 0.5 m;
  front: min(topic /scan.ranges[0:8]) < 0.4 m;
}
overspeed: if (hot.fast or hot.bump or hot.stale) then { warn; }
zone: if (hot.outside or hot.margin) then { slow_down; }
escalate: if ((active(warn) for 0.5 s) and (hot.spin_up or hot.front)) then { board_stop; }
"""
HOT_RULES = 7


def cold_rule(e: int, i: int) -> str:
    """One of the v2 rule shapes, on a topic of its own that gets no message in the run."""
    t = f"/cold{e + i}"
    return [f"(topic {t}.data > {i}) within 1 s",
            f"latch(topic {t}.data > {i}, (topic {t}.data < 0) for 1 s)",
            f"abs(rate(topic {t}.data)) > {i + 1}",
            f"stamp_age(topic {t}) > 500 ms",
            f"any(topic {t}.status[*].level >= 2)"][i % 5]


def spec_text(n_rules: int) -> str:
    lines = ["action primitive warn, slow_down, board_stop;", HOT]
    n_cold = n_rules - HOT_RULES
    for e in range(0, n_cold, 10):
        lines.append(f"entity c{e} {{ rules:")
        lines += [f"  r{i}: {cold_rule(e, i)};" for i in range(min(10, n_cold - e))]
        lines.append("}")
        lines.append(f"if (c{e}.r0 or c{e}.r1) then {{ warn; }}")
    return "\n".join(lines) + "\n"


def _cpu_us(make_engine, items) -> float:
    """CPU time of the engine per item, on a fresh engine (process time: robust to other load)."""
    engine = make_engine()
    cpu = time.process_time
    t0 = cpu()
    for topic, now, msg in items:
        engine.on_message(topic, now, msg)
    return round((cpu() - t0) / len(items) * 1e6, 2)


def _engine(spec):
    def make():
        engine = Engine(spec, 0.0)
        engine.evaluate_all(0.0)
        return engine
    return make


def _machine() -> dict:
    """Machine facts, with the load average: the machine may be shared while this runs."""
    return _common.machine()


def _figures(costs):
    return {"mean_us": round(sum(costs) / len(costs) * 1e6, 2),
            "p50_us": round(_common.percentile(costs, 50) * 1e6, 2),
            "p99_us": round(_common.percentile(costs, 99) * 1e6, 2)}


def engine_per_message(n_rules: int, n_messages: int) -> dict:
    """(a): messages alternate between /odom (a stamped Odometry) and /scan (8 beams)."""
    spec = check_text(spec_text(n_rules), SPEC_PATH, [_common.LIB])
    rng = random.Random(1)
    t, msgs = 0.0, []
    v, w, x, y, d = 0.3, 0.0, 4.0, 2.0, 2.0
    for k in range(n_messages):
        t += 0.005  # /odom and /scan at 100 Hz each
        if k % 2:  # an obstacle drifting nearer and farther
            d = min(3.0, max(0.2, d + rng.gauss(0, 0.02)))
            msgs.append(("/scan", t, LaserScan(t, tuple(d + rng.uniform(0.0, 0.3) for _ in range(8)))))
        else:  # a robot driving about: speed drifts across the limits, position across the margin
            v = min(1.0, max(0.0, v + rng.gauss(0, 0.01)))
            w = min(1.0, max(-1.0, w + rng.gauss(0, 0.01)))
            x, y = min(9.0, max(3.5, x + rng.gauss(0, 0.02))), min(4.5, max(0.5, y + rng.gauss(0, 0.02)))
            msgs.append(("/odom", t, Odometry(t - rng.uniform(0.01, 0.05), x, y, v, w)))
    cpu_us = _cpu_us(_engine(spec), msgs)
    engine = _engine(spec)()
    costs = []
    clock = time.perf_counter
    events = 0
    for topic, now, msg in msgs:
        t0 = clock()
        events += len(engine.on_message(topic, now, msg))
        costs.append(clock() - t0)
    # every rule the messages feed must have a value by the end, or the run measured nothing
    unknown = [r.key for r in spec.rules if r.key.startswith("hot.") and engine.rule_value(r.key) is UNKNOWN]
    return {"benchmark": "engine_v2", "figure": "per_message", "rules": len(spec.rules),
            "dependent_rules": HOT_RULES, "behaviours": len(spec.behaviours), "messages": n_messages,
            "events": events, "unknown_at_end": unknown, "cpu_us": cpu_us, **_figures(costs),
            "target_us": 10, "met": cpu_us <= 10, **_machine()}


LASER = """entity laser { rules:
  right: min(topic /scan.ranges[0:360]) < 0.5 m;
  front: min(topic /scan.ranges[360:720]) < 0.5 m;
  left: min(topic /scan.ranges[720:1081]) < 0.5 m;
}
if (laser.front) then { board_stop; }
if (laser.left or laser.right) then { slow_down; }
"""


def laser_scan(n_scans: int) -> dict:
    """(b): 1,081 beams, about 5 % +inf (no return) and 2 % NaN, as a real 270° scanner sends."""
    spec = check_text("action primitive slow_down, board_stop;\n" + LASER, SPEC_PATH, [_common.LIB])
    rng = random.Random(2)
    scans = []
    for k in range(n_scans):
        r = [rng.uniform(0.3, 25.0) for _ in range(1081)]
        for i in rng.sample(range(1081), 54):
            r[i] = math.inf
        for i in rng.sample(range(1081), 22):
            r[i] = math.nan
        scans.append(LaserScan(0.025 * (k + 1), tuple(r)))
    items = [("/scan", 0.025 * (k + 1), scan) for k, scan in enumerate(scans)]
    cpu_us = _cpu_us(_engine(spec), items)
    engine = _engine(spec)()
    costs = []
    clock = time.perf_counter
    for topic, now, scan in items:
        t0 = clock()
        engine.on_message(topic, now, scan)
        costs.append(clock() - t0)
    unknown = [r.key for r in spec.rules if engine.rule_value(r.key) is UNKNOWN]
    return {"benchmark": "engine_v2", "figure": "laser_scan", "beams": 1081, "sector_rules": 3,
            "scans": n_scans, "unknown_at_end": unknown, "cpu_us": cpu_us, **_figures(costs),
            "target_us": 50, "met": cpu_us <= 50, **_machine()}


def parse_and_check(n_rules: int, repeat: int) -> dict:
    """(c): the spec of (a) with n_rules rules, parsed and checked against the example library."""
    text = spec_text(n_rules)
    parse_times, total_times, cpu_times = [], [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        parse_source(Source(SPEC_PATH, text))
        parse_times.append(time.perf_counter() - t0)
        t0, c0 = time.perf_counter(), time.process_time()
        spec = check_text(text, SPEC_PATH, [_common.LIB])
        total_times.append(time.perf_counter() - t0)
        cpu_times.append(time.process_time() - c0)
    median = statistics.median(cpu_times)
    return {"benchmark": "engine_v2", "figure": "parse_check", "rules": len(spec.rules),
            "spec_bytes": len(text.encode()), "parse_s_median": round(statistics.median(parse_times), 4),
            "parse_and_check_cpu_s_median": round(median, 4),
            "parse_and_check_s_median": round(statistics.median(total_times), 4),
            "parse_and_check_s_max": round(max(total_times), 4),
            "target_s": 1.0, "met": median < 1.0, **_machine()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--messages", type=_common.above_zero(int), default=50000, help="messages per rule count in (a)")
    ap.add_argument("--scans", type=_common.above_zero(int), default=5000, help="LaserScans in (b)")
    ap.add_argument("--rules", type=_common.above_zero(int), default=1000, help="rules to parse and check in (c)")
    ap.add_argument("--repeat", type=_common.above_zero(int), default=5, help="parse + check runs in (c)")
    args = ap.parse_args()
    for n in (10, 100, 1000):
        print(json.dumps(engine_per_message(n, args.messages)), flush=True)
    print(json.dumps(laser_scan(args.scans)), flush=True)
    print(json.dumps(parse_and_check(args.rules, args.repeat)), flush=True)


if __name__ == "__main__":
    main()
