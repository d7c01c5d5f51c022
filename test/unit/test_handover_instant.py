"""An action one behaviour hands to another in one instant stays on.

Acceptance finding: `near: if (0 < x < 5) then { a; }` and `very_near: if (x >= 5) then { a; }`:
x going 3 → 6 released `a` (its on_release went out: RELEASED, brakes off) and started it again,
because the engine emitted near's release before very_near's start (file order). Within one
instant its starts now come before its releases."""
import pytest

from rubass.cli import main

LIB = "actions:\n  a: {plugin: log}\n"
SPEC = """import "lib.yaml";
action primitive a;
entity e { rules: near: topic /x.data > 0 and topic /x.data < 5; very_near: topic /x.data >= 5; }
{first}
{second}
"""
NEAR = "near: if (e.near) then { a; }"
VERY = "very_near: if (e.very_near) then { a; }"
TESTS = """spec: s.rbs
tests:
  - name: hand-over
    duration: 5 s
    topics:
      /x: {type: std_msgs/Float64, rate: 1 Hz, field: data, values: "0 3 6 3 0"}
    expect:
      - {at: 1 s, start: a}
      - {at: 4 s, release: a}
      - {active: a, from: 1 s, to: 4 s}
"""


@pytest.mark.parametrize("order", ["near first", "very_near first"])
def test_a_shared_action_is_not_released_at_a_hand_over(tmp_path, capsys, order):
    first, second = (NEAR, VERY) if order == "near first" else (VERY, NEAR)
    (tmp_path / "lib.yaml").write_text(LIB)
    (tmp_path / "s.rbs").write_text(SPEC.replace("{first}", first).replace("{second}", second))
    (tmp_path / "s.test.yaml").write_text(TESTS)
    assert main(["test", str(tmp_path / "s.test.yaml")]) == 0, capsys.readouterr()


def test_the_engine_orders_an_instants_starts_before_its_releases():
    from rubass.engine import Engine
    from rubass.lang import check_text
    import os
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        lib = os.path.join(d, "lib.yaml")
        open(lib, "w").write(LIB)
        spec = check_text(SPEC.replace('import "lib.yaml";\n', "").replace("{first}", NEAR).replace("{second}", VERY),
                          extra_libraries=[lib])
    from types import SimpleNamespace
    eng = Engine(spec, 0.0)
    eng.on_message("/x", 1.0, SimpleNamespace(data=3.0))
    events = [(e.kind, e.behaviour) for e in eng.on_message("/x", 2.0, SimpleNamespace(data=6.0))
              if e.kind in ("start", "release")]
    assert events == [("start", 2), ("release", 1)]
