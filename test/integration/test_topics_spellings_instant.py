"""Every spelling of one topic in the spec sees one message at one instant (acceptance: with
`age(topic cmd_vel) > 0.5 s and topic /cmd_vel.linear.x > -100`, one message after 2.4 s of
silence started the behaviour with the new value beside the old age, released 0.2 ms later)."""
import json

import pytest

from rosharness import TWIST, spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

RULE = ("entity a { rules: r: age(topic cmd_vel) > 0.5 s and topic /cmd_vel.linear.x > -100; }\n"
        "if (a.r) then { brake; }\n")


def test_one_message_under_two_spellings_is_one_instant_and_starts_nothing(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, RULE))
    rec = ros.probe({"listen": [{"topic": "/rubass/events", "type": "std_msgs/String"}],
                     "advertise": [{"topic": "/cmd_vel", "type": TWIST}],
                     "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_publishers": "/rubass/events"},
                               {"sleep": 2.4}, {"mark": "go"}, {"publish": "/cmd_vel", "msg": {"linear": {"x": 0.1}}},
                               {"sleep": 1.0}, {"publish": "/cmd_vel", "msg": {"linear": {"x": 0.1}}},
                               {"sleep": 0.3}]}, timeout=60)
    go = next(r["wall"] for r in rec if r.get("name") == "go")
    events = [json.loads(r["msg"]["data"]) for r in rec if r["kind"] == "recv" and r["topic"] == "/rubass/events"]
    starts = [e for e in events if e["event"] == "start"]
    # at the message its age is 0: the rule is false then, and true 0.5 s later (no message since),
    # until the next message; a start at the message itself mixes the new value with the old age
    after = [e["time"] - go for e in starts]
    assert len(after) == 1 and 0.45 < after[0] < 0.8, (after, starts, ros.log(mon))
