"""The replay loop (rubass/replay/run.py, made shorter per message for issue 17) gives the events
of the straightforward loop it replaced, on random recordings with shared stamps, node samples,
gaps longer than a tick and messages before the start."""
import json
import os
import random

from rubass.engine import Engine
from rubass.lang import check_text
from rubass.replay.run import _node_sample, replay

from conftest import ROOT

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")
SPEC = """action primitive stop, warn;
entity r: /p; { rules:
  a: topic /x.v > 1;
  c: (topic /x.v > 2) for 0.2 s;
  g: age(topic /y) > 0.3 s;
  n: cpu(node /p) > 0.5 and topic /y.v > 0;
  f: frequency(topic /y) < 20 Hz;
}
if (r.a and not r.c) then { warn; }
if (r.g or r.n) then { stop; }
if (r.f) then { warn; }
"""


class Sample:
    def __init__(self, data):
        self.data = data


def reference(spec, messages, start, end, rate=50.0, node_topics=()):
    """The loop before issue 17's rewrite, kept as the reference."""
    node_topics = set(node_topics)
    engine = Engine(spec, 0.0, origin=start)
    events = engine.evaluate_all(0.0)
    period = 1.0 / rate
    state = {"next_tick": period, "batch_time": 0.0}
    batch = []

    def flush():
        if batch:
            events.extend(engine.on_messages(state["batch_time"], batch))
            batch.clear()

    def ticks_until(t, inclusive):
        while state["next_tick"] < t or (inclusive and state["next_tick"] == t):
            events.extend(engine.on_tick(state["next_tick"]))
            state["next_tick"] = round((state["next_tick"] + period) / period) * period

    for stamp, topic, msg in messages:
        t = stamp - start
        if topic in node_topics:
            flush()
            ticks_until(t, inclusive=False)
            sample = _node_sample(msg)
            if sample is not None:
                at = max(min(t, sample[4] - start), engine.store.now) if sample[4] is not None else t
                events.extend(engine.on_node_sample(sample[0], at, *sample[1:4]))
            continue
        if batch and (t != state["batch_time"] or any(name == topic for name, _ in batch)):
            flush()
        if not batch:
            ticks_until(t, inclusive=False)
            state["batch_time"] = t
        batch.append((topic, msg))
    flush()
    ticks_until(end - start, inclusive=True)
    events.extend(engine.advance(end - start))
    return engine, events


def _events(result):
    return [(e.time, e.kind, e.behaviour, e.rule, e.value) for e in result[1]]


def test_the_loop_gives_the_events_of_the_reference_loop():
    rnd = random.Random(17)
    spec = check_text(SPEC, os.path.join(ROOT, "x.rbs"), [LIB])
    start = 1700000000.0
    shared = 0  # messages of one topic at one instant: each is evaluated (docs/replay.md)
    for case in range(25):
        t, seq = start + rnd.choice([0.0, -0.05, 0.02]), []
        for _ in range(250):
            step = rnd.choice([0.0, 0.0, 0.004, 0.02, 0.05, 0.4])
            t += step
            kind = rnd.random()
            if kind < 0.4:
                shared += bool(seq) and step == 0.0 and seq[-1][1] == "/x"
                seq.append((t, "/x", {"v": rnd.choice([0, 1.5, 2.2, 3])}))
            elif kind < 0.8:
                seq.append((t, "/y", {"v": rnd.choice([-0.5, 0, 0.5])}))
            else:
                at = rnd.choice([None, t - 0.01, t + 0.01])
                seq.append((t, "/mon/node_samples", Sample(json.dumps(
                    {"node": "/p", "alive": True, "cpu": rnd.choice([0.2, 0.7]), "time": at}))))
        end = t + rnd.choice([0.0, 0.5])
        rate = rnd.choice([50.0, 7.0, 200.0])
        got = replay(spec, iter(seq), start, end, rate, ["/mon/node_samples"])
        want = reference(spec, iter(seq), start, end, rate, ["/mon/node_samples"])
        assert _events(got) == _events(want), case
        assert got[0].store.rules == want[0].store.rules
    assert any(e[1] == "start" for e in _events(got))
    assert shared > 50
