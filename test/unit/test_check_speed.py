"""The checker's speed work (issue 17) kept its behaviour: the rule and evaluation orders, the
cycle messages and the expression walk are pinned here, and the check is linear in the number
of rules (counted in function calls, not wall time, so that a loaded machine cannot flake it)."""
import cProfile
import dataclasses
import os
import pstats

import pytest

from rubass.lang import SpecError, ast, check_text
from rubass.lang.checker import _walk, check
from rubass.lang.grammar import parse_source
from rubass.lang.source import Source, SourceSet

from conftest import ROOT

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")  # defines stop and warn


def checked(text):
    return check_text(text, "s.rbs", [LIB])


def errors(text):
    with pytest.raises(SpecError) as info:
        checked(text)
    return [(d.span.line, d.span.col, d.message) for d in info.value.diagnostics]


def generate(n_rules, per_entity=10):
    """Like bench/parse_check.py: entities of 10 rules mixing fields, units, for, age, nodes and
    references to other rules, and one behaviour per entity."""
    out = ["action primitive stop, warn;", "const MAX = 0.5 m/s;"]
    for e in range(0, n_rules, per_entity):
        ent = f"e{e // per_entity}"
        out.append(f"entity {ent}: driver_{ent} {{ rules:")
        for i in range(min(per_entity, n_rules - e)):
            t = f"/robot_{e // per_entity}/wheel_{i}"
            body = [f"(abs(topic {t}/cmd.linear.x) > MAX and topic {t}/enc.data == 0) for 0.4 s",
                    f"age(topic {t}/enc) > 500 ms or frequency(topic {t}/cmd) < 5 Hz",
                    f"(cpu(node driver_{ent}) > 90 %) for 1.5 s",
                    f"hypot(topic {t}/odom.x, topic {t}/odom.y) > 3 m",
                    f"r{i - 4} and not alive(node driver_{ent})"][i % 5]
            out.append(f"  r{i}: {body};")
        out.append("}")
        out.append(f"if ({ent}.r0 or {ent}.r1 for 1 s) then {{ stop; warn(\"{ent}\"); }}")
    return "\n".join(out) + "\n"


ORDER_SPEC = """action primitive stop, warn;
entity a { rules:
  x: b or topic /t.v > 1;
  b: topic /t.w > 2;
  c: active(warn) and x;
}
entity z { rules:
  y: a.c or a.b;
}
if (z.y) then { stop; }
if (a.b) then { warn; }
"""


def test_rules_come_after_the_rules_they_use_and_behaviours_before_active_of_their_actions():
    spec = checked(ORDER_SPEC)
    assert [r.key for r in spec.rules] == ["a.b", "a.x", "a.c", "z.y"]
    assert spec.evaluation == ["a.b", "a.x", "b:2", "a.c", "z.y", "b:1"]


def test_a_long_chain_declared_backwards_is_ordered_from_its_end():
    n = 300
    lines = [f"  r{i}: r{i + 1} or topic /t{i}.v > {i};" for i in range(n - 1)] + [f"  r{n - 1}: topic /t.v > 0;"]
    spec = checked("action primitive stop;\nentity c { rules:\n" + "\n".join(lines) + "\n}\n"
                   "if (c.r0) then { stop; }\n")
    keys = [f"c.r{i}" for i in reversed(range(n))]
    assert [r.key for r in spec.rules] == keys
    assert spec.evaluation == keys + ["b:1"]
    assert spec.rules[-1].rule_deps == frozenset({"c.r1"})


def test_every_rule_of_a_large_spec_comes_after_its_dependencies():
    spec = checked(generate(600))
    seen = set()
    for key in spec.evaluation:
        deps = spec.rule(key).rule_deps if not key.startswith("b:") else set()
        assert deps <= seen, key
        seen.add(key)
    assert len(spec.evaluation) == 600 + 60


def test_a_long_cycle_is_reported_once_with_its_whole_path():
    n = 40
    lines = [f"  r{i}: r{(i + 1) % n} and topic /t.v > {i};" for i in range(n)]
    found = errors("action primitive stop;\nentity c { rules:\n" + "\n".join(lines) + "\n}\n"
                   "if (c.r5) then { stop; }\n")
    path = " -> ".join(f"c.r{i}" for i in range(n)) + " -> c.r0"
    assert found == [(3, 3, f"cyclic rule reference: {path}")]


def test_two_cycles_and_an_active_loop_keep_their_messages_and_order():
    found = errors("""action primitive stop, warn;
entity c { rules:
  a: b;
  b: a;
  p: q or topic /t.v > 1;
  q: p;
  h: active(warn);
}
if (c.h) then { warn; }
if (c.a) then { stop; }
""")
    assert found == [
        (3, 3, "cyclic rule reference: c.a -> c.b -> c.a"),
        (5, 3, "cyclic rule reference: c.p -> c.q -> c.p"),
        (9, 1, "behaviour 1 depends on active() of one of its own actions, so it could hold itself on: "
               "behaviour 1 -> c.h -> active(warn) -> behaviour 1"),
    ]


def test_a_rule_named_without_its_entity_names_the_first_entity_that_has_it():
    found = errors("""action primitive stop;
entity a { rules: s: topic /t.v > 1; }
entity b { rules: s: topic /t.v > 2; r: topic /t.v > 3; }
if (s or r) then { stop; }
""")
    assert found == [(4, 5, "'s' is a rule of entity 'a': write 'a.s'"),
                     (4, 10, "'r' is a rule of entity 'b': write 'b.r'")]


RICH = """action primitive stop, warn;
const AREA = polygon((0 m, 0 m), (4 m, 0 m), (4 m, 3 m));
entity e: /n; { rules:
  a: any(topic /d.status[*].level >= 2) or count(topic /s.r[0:9] < 1 m) > 2;
  b: max(topic /s.r[0:90]) < 0.5 m and len(topic /s.r) > 3;
  c: latch(rate(topic /o.x) > 1 m/s, (topic /o.x < 0.4 m) for 1 s) within 2 s;
  d: inside(topic /o.x, topic /o.y, AREA) and distance(topic /o.x, topic /o.y, AREA) < 1 m;
  f: -sqrt(topic /o.z) < -1 and stamp_age(topic /imu) > 1 s and memory(node /n) > 1 MB;
  g: active(warn) and not a;
}
if (e.a or e.b or e.c or e.d or e.f) then { stop; }
if (e.g) then { stop; }
"""


def test_the_checker_walk_is_ast_walk():
    spec = checked(RICH)
    exprs = [r.expr for r in spec.rules] + [b.cond for b in spec.behaviours]
    kinds = set()
    for e in exprs:
        assert _walk(e) == list(ast.walk(e))
        kinds |= {type(x).__name__ for x in _walk(e)}
    assert {"Quant", "ArrayFn", "Latch", "Rate", "Within", "Zone", "Unary", "Call", "Elem", "StampAge",
            "NodeStat", "Active", "For"} <= kinds
    assert set(spec.topics) == {"/d", "/s", "/o", "/imu"}
    assert spec.nodes == frozenset({"/n"})


def test_the_checker_walk_knows_every_node_type_that_ast_walk_knows():
    """A node type added to ast.children must be added to the checker's walk too."""
    for cls in vars(ast).values():
        if not (isinstance(cls, type) and dataclasses.is_dataclass(cls)):
            continue
        values = {f.name: (ast.Lit(1.0), ast.Lit(2.0)) if f.name == "args" else ast.Lit(float(i))
                  for i, f in enumerate(dataclasses.fields(cls)) if f.name != "span"}
        node = cls(**values)
        assert _walk(node) == list(ast.walk(node)), cls.__name__


def _check_calls(text):
    """Function calls made by one check of a parsed spec."""
    src = Source("s.rbs", text)
    spec = parse_source(src)
    prof = cProfile.Profile()
    sources = SourceSet()
    sources.add(src)
    prof.enable()
    result, errs, _ = check(spec, sources, [LIB])
    prof.disable()
    assert result is not None, errs
    return pstats.Stats(prof).total_calls


def test_the_check_is_linear_in_the_number_of_rules():
    small, large = _check_calls(generate(150)), _check_calls(generate(600))
    assert large < 4.5 * small, (small, large)


def test_the_check_of_a_chain_of_rules_is_linear_in_its_length():
    def chain(n):
        lines = [f"  r{i}: r{i - 1} or topic /t.v > {i};" for i in range(1, n)]
        return ("action primitive stop;\nentity c { rules:\n  r0: topic /t.v > 0;\n" + "\n".join(lines) +
                f"\n}}\nif (c.r{n - 1}) then {{ stop; }}\n")
    small, large = _check_calls(chain(50)), _check_calls(chain(200))
    assert large < 4.5 * small, (small, large)
