"""Acceptance fix: two limits of different types on one input. A Twist limit whose input carries
TwistStamped commands must count them as no command (zero after `timeout`), never read the bytes
that the TwistStamped limit beside it took from the same input as a Twist (garbage, clamped to its
maximum: /outA got x=0.15, y=8.8e-314 at 20 Hz)."""
import pytest

from rosharness import TWIST

pytestmark = [pytest.mark.ros, pytest.mark.slow]

STAMPED = "geometry_msgs/TwistStamped"
LIB = ("actions:\n"
       "  la: {plugin: limit, input: /nav_s, topic: /outA, linear_x: [-0.1 m/s, 0.15 m/s]}\n"
       f"  lb: {{plugin: limit, input: /nav_s, topic: /outB, type: {STAMPED}, linear_x: [-0.1 m/s, 0.15 m/s]}}\n")


def test_a_limit_never_reads_the_commands_of_another_type_taken_by_a_limit_beside_it(ros, tmp_path):
    (tmp_path / "lib.yaml").write_text(LIB)
    path = tmp_path / "s.rbs"
    path.write_text('import "lib.yaml";\naction primitive la, lb;\nentity t { rules: on: topic /trig.data > 0; }\n'
                    "if (t.on) then { la; lb; }\n")
    mon = ros.monitor(str(path))
    rec = ros.probe({
        "listen": [{"topic": "/outA", "type": TWIST}, {"topic": "/outB", "type": STAMPED}],
        "advertise": [{"topic": "/nav_s", "type": STAMPED}, {"topic": "/trig", "type": "std_msgs/Float64"}],
        "steps": [{"wait_subscribers": "/nav_s"}, {"wait_subscribers": "/trig"}, {"wait_publishers": "/outA"},
                  {"wait_publishers": "/outB"}, {"sleep": 0.5},
                  {"publish": "/trig", "msg": {"data": 1.0}}, {"sleep": 0.2},
                  {"publish": "/nav_s", "msg": {"twist": {"linear": {"x": 0.0}}}, "repeat": 20, "period": 0.05},
                  {"publish": "/nav_s", "msg": {"twist": {"linear": {"x": 1.0}}}, "repeat": 10, "period": 0.05},
                  {"sleep": 0.3}],
        "linger": 0.1})
    outa = [r["msg"] for r in rec if r["kind"] == "recv" and r["topic"] == "/outA"]
    outb = [r["msg"]["twist"] for r in rec if r["kind"] == "recv" and r["topic"] == "/outB"]
    zero = {"x": 0.0, "y": 0.0, "z": 0.0}
    assert len(outa) >= 20, outa
    assert all(m == {"linear": zero, "angular": zero} for m in outa), [m for m in outa if m["linear"] != zero][:3]
    # the stamped limit beside it reads them: clamped to its maximum once they ask for 1 m/s
    assert outb and outb[-1]["linear"]["x"] == pytest.approx(0.15), outb[-3:]
    assert "carries geometry_msgs/TwistStamped, not geometry_msgs/Twist" in ros.log(mon)


def test_a_limit_released_with_the_stop_above_it_is_never_handed_the_topic(ros, tmp_path):
    """An acceptance sweep: `then { crawl; stop; }` released together sent a creep command after the
    stop's on_release in 10 of 20 cycles: the stop's seat went before the crawl's release had run on
    its thread, so the arbiter handed the crawl the topic for one planner command."""
    (tmp_path / "lib.yaml").write_text(
        "actions:\n"
        "  stop: {plugin: publish, topic: /base, type: geometry_msgs/Twist, message: {}, rate: 20 Hz,\n"
        "         on_release: {linear: {y: 9.0}}, priority: 3}\n"
        "  crawl: {plugin: limit, input: /nav, topic: /base, linear_x: [-0.1 m/s, 0.1 m/s], priority: 1}\n")
    path = tmp_path / "s.rbs"
    path.write_text('import "lib.yaml";\naction primitive stop, crawl;\nentity s { rules: both: topic /b.data > 1; }\n'
                    "together: if (s.both) then { crawl; stop; }\n")
    ros.monitor(str(path))
    cycle = [{"publish": "/b", "msg": {"data": 2.0}},
             {"publish": "/nav", "msg": {"linear": {"x": 0.5}}, "repeat": 15, "period": 0.01},
             {"publish": "/b", "msg": {"data": 0.0}},
             {"publish": "/nav", "msg": {"linear": {"x": 0.5}}, "repeat": 15, "period": 0.01}]
    rec = ros.probe({
        "listen": [{"topic": "/base", "type": TWIST}],
        "advertise": [{"topic": "/nav", "type": TWIST}, {"topic": "/b", "type": "std_msgs/Float64"}],
        "steps": [{"wait_subscribers": "/nav"}, {"wait_subscribers": "/b"}, {"wait_publishers": "/base"},
                  {"sleep": 0.5}] + cycle * 12 + [{"sleep": 0.2}],
        "linger": 0.1})
    base = [r["msg"]["linear"] for r in rec if r["kind"] == "recv" and r["topic"] == "/base"]
    assert sum(m["y"] == 9.0 for m in base) == 12, "one on_release per cycle"
    assert not [m for m in base if m["x"] != 0.0], "the crawl published though the stop was always above it"
