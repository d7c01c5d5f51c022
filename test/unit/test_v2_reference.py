"""hypothesis: `within` and `latch` (LANGUAGE.md §10) in the engine against brute-force
references on random piecewise-constant signals with unknowns, as test_for_reference does for
`for`. Times are whole seconds; values are compared half-way between them, where every change
of the engine (messages, and `within`'s own deadlines) has happened."""
import math
import os

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rubass.engine import UNKNOWN, Engine
from rubass.engine.values import k_and, k_not, k_or
from rubass.lang import check_text

from conftest import ROOT

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")
HORIZON = 14
VALUES = st.sampled_from([0.0, 2.0, math.nan])
SIGNAL = st.dictionaries(st.integers(0, HORIZON), VALUES, max_size=8)


def value_at(signal, t):
    """The latest value at or before t (UNKNOWN before the first message or for NaN)."""
    times = [s for s in signal if s <= t]
    if not times:
        return UNKNOWN
    v = signal[max(times)]
    return UNKNOWN if v != v else v > 1


def engine_values(spec_text, signals, rule):
    spec = check_text("action primitive warn;\n" + spec_text, os.path.join(ROOT, "p.rbs"), [LIB])
    engine = Engine(spec, 0.0)
    engine.evaluate_all(0.0)
    out = []
    for k in range(HORIZON + 1):
        for topic, signal in signals.items():
            if k in signal:
                engine.on_message(topic, float(k), {"data": signal[k]})
        engine.advance(k + 0.5)
        v = engine.rule_value(rule)
        out.append(None if v is UNKNOWN else v)
    return out


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(signal=SIGNAL, T=st.integers(0, 4))
def test_within_matches_its_definition(signal, T):
    got = engine_values(f"entity e {{ rules: w: topic /a.data > 1 within {T} s; }}\nif (e.w) then {{ warn; }}\n",
                        {"/a": signal}, "e.w")
    for n in range(HORIZON + 1):
        # (t - T, t] with t = n + 0.5 meets the pieces [k, k + 1) for k = n - T … n; before 0 is unknown
        seen = [value_at(signal, k) if k >= 0 else UNKNOWN for k in range(n - T, n + 1)]
        want = True if True in seen else (None if any(v is UNKNOWN for v in seen) else False)
        assert got[n] == want, (n, got, signal)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(a=SIGNAL, b=SIGNAL)
def test_latch_matches_its_definition(a, b):
    got = engine_values("entity e { rules: l: latch(topic /a.data > 1, topic /b.data > 1); }\n"
                        "if (e.l) then { warn; }\n", {"/a": a, "/b": b}, "e.l")
    prev = False
    want = []
    changes = set(a) | set(b) | {0}
    for n in range(HORIZON + 1):
        if n in changes:
            prev = k_or(value_at(a, n), k_and(prev, k_not(value_at(b, n))))
        want.append(None if prev is UNKNOWN else prev)
    assert got == want, (got, want, a, b)
