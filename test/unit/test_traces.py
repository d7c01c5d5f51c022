"""Trace tests: a spec, inputs at explicit times, and the exact events expected.

Each test/traces/*.yaml holds a list of cases:

    - name: what it shows
      spec: |                      # actions stop (latched) and warn are declared for you
        entity a { rules: r: (topic /x.data > 1) for 1 s; }
        if (a.r) then { warn; }
      start: 0                     # optional, the engine's start time
      steps:                       # in time order
        - {t: 0.0, topic: /x, msg: {data: 2}}     # a message (msg omitted: arrival only)
        - {t: 1.0, tick: true}                    # a scheduler tick
        - {t: 1.2, node: /n, alive: true, cpu: 0.5, memory: 1000}
        - {t: 2.0, reset: true}                   # the reset service
      end: 5                       # deadlines up to here are fired at the end
      expect:                      # every start and release, in order
        - {t: 1.0, start: 1}
      rules:                       # optional: every change of these rules' values
        a.r: [[0, null], [1.0, true]]
"""
import glob
import math
import os

import pytest
import yaml

from rubass.engine import Engine
from rubass.lang import check_text

from conftest import ROOT

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")


def load_cases():
    cases = []
    for path in sorted(glob.glob(os.path.join(ROOT, "test", "traces", "*.yaml"))):
        with open(path) as fh:
            for case in yaml.safe_load(fh):
                cases.append(pytest.param(case, id=f"{os.path.basename(path)[:-5]}: {case['name']}"))
    return cases


def _msg(value):
    """YAML has no NaN literal in flow style we want to rely on: 'nan' strings become floats."""
    if isinstance(value, dict):
        return {k: _msg(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_msg(v) for v in value]
    if value in ("nan", "inf", "-inf"):
        return float(value)
    return value


def run(case):
    spec = check_text("action primitive stop, warn;\n" + case["spec"], os.path.join(ROOT, "trace.rbs"), [LIB])
    start = float(case.get("start", 0.0))
    engine = Engine(spec, start)
    events = engine.evaluate_all(start)
    for step in case["steps"]:
        t = float(step["t"])
        if "topic" in step:
            events += engine.on_message(step["topic"], t, _msg(step.get("msg")))
        elif "node" in step:
            events += engine.on_node_sample(step["node"], t, step.get("alive"), _num(step.get("cpu")),
                                            _num(step.get("memory")))
        elif step.get("tick"):
            events += engine.on_tick(t)
        elif step.get("reset"):
            events += engine.reset(t)
        else:
            raise ValueError(f"bad step {step}")
    events += engine.advance(float(case.get("end", 0.0)))
    return events


def _num(v):
    from rubass.engine import UNKNOWN

    return UNKNOWN if v is None else float(v)


def _close(a, b):
    return math.isclose(a, b, abs_tol=1e-9)


@pytest.mark.parametrize("case", load_cases())
def test_trace(case):
    events = run(case)
    got = [(e.time, e.kind, e.behaviour) for e in events if e.kind in ("start", "release")]
    want = [(float(x["t"]), "start" if "start" in x else "release", x.get("start", x.get("release")))
            for x in case.get("expect", [])]
    assert len(got) == len(want) and all(_close(g[0], w[0]) and g[1:] == w[1:] for g, w in zip(got, want)), \
        f"got {got}, want {want}"
    for key, changes in (case.get("rules") or {}).items():
        seen = [(e.time, e.value) for e in events if e.kind == "rule" and e.rule == key]
        assert len(seen) == len(changes) and all(
            _close(s[0], float(c[0])) and s[1] == c[1] for s, c in zip(seen, changes)), f"{key}: got {seen}, want {changes}"
