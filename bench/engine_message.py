#!/usr/bin/python3
"""Engine time per message with 10, 100 and 1,000 rules, of which 5 depend on the topic.

It must stay flat as rules are added (a message re-evaluates only its dependents);
target <= 20 us per message. Prints one JSON object per rule count.
Usage: bench/engine_message.py [--messages N]
"""
import argparse
import json
import random
import time

import _common  # noqa: F401  (sys.path)
from rubass.engine import Engine  # noqa: E402
from rubass.lang import check_text  # noqa: E402


class Float64:
    """Shaped like a deserialised std_msgs/Float64."""

    __slots__ = ("data",)

    def __init__(self, data):
        self.data = data


def spec_text(n_rules):
    lines = ["action primitive warn;", "entity hot { rules:",
             "  fast: (topic /hot.data > 0.8 m/s) for 0.5 s;",
             "  slow: topic /hot.data < 0.1 m/s;",
             "  band: abs(topic /hot.data - 0.5) < 0.05 and not slow;",
             "  jump: topic /hot.data * 2 > 1.9 or fast;",
             "  combo: (band or jump) for 0.2 s;", "}"]
    for e in range(0, n_rules - 5, 10):
        lines.append(f"entity c{e} {{ rules:")
        for i in range(min(10, n_rules - 5 - e)):
            lines.append(f"  r{i}: (topic /cold{e + i}.data > {i}) for 1 s;")
        lines.append("}")
    lines.append("if (hot.fast or hot.combo) then { warn; }")
    return "\n".join(lines) + "\n"


def measure(n_rules, n_messages):
    spec = check_text(spec_text(n_rules), _common.os.path.join(_common.ROOT, "bench.rbs"), [_common.LIB])
    engine = Engine(spec, 0.0)
    engine.evaluate_all(0.0)
    rng = random.Random(1)
    msgs = [Float64(rng.random()) for _ in range(n_messages)]
    costs = []
    clock = time.perf_counter
    t = 0.0
    for m in msgs:
        t += 0.001
        t0 = clock()
        engine.on_message("/hot", t, m)
        costs.append(clock() - t0)
    return {
        "benchmark": "engine_message", "rules": len(spec.rules), "dependent_rules": 5,
        "messages": n_messages,
        "mean_us": round(sum(costs) / len(costs) * 1e6, 2),
        "p50_us": round(_common.percentile(costs, 50) * 1e6, 2),
        "p99_us": round(_common.percentile(costs, 99) * 1e6, 2),
        "target_us": 20, "met": sum(costs) / len(costs) * 1e6 <= 20,
        **_common.machine(),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--messages", type=_common.above_zero(int), default=50000, help="messages per case (default 50000)")
    args = ap.parse_args()
    for n in (10, 100, 1000):
        print(json.dumps(measure(n, args.messages)), flush=True)


if __name__ == "__main__":
    main()
