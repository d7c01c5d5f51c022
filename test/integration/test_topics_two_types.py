"""Two publishers of two types on one topic (acceptance: a std_msgs/String and a std_msgs/Float64
on /speed gave 58 start/release events of the data-error fail-safe in 5 s, 4 log lines per
message, /diagnostics OK, and the behaviour itself flapping). It is one data error for as long
as both publish: ERROR naming the topic and both types, ~error_actions held, logged once; the
Float64 messages are still evaluated, so a real violation is still stopped."""
import json

import pytest

from rosharness import TWIST, first, records, spec, wait_log

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def test_two_types_on_one_topic_are_one_held_data_error_and_a_real_violation_still_stops(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, "entity s { rules: fast: topic /speed.data > 1; }\nif (s.fast) then { stop; }\n"),
                      error_actions="brake", diagnostics_rate=5)
    strings = ros.probe_bg({"advertise": [{"topic": "/speed", "type": "std_msgs/String"}],
                            "steps": [{"wait_subscribers": "/speed"}, {"mark": "ready"},
                                      {"publish": "/speed", "msg": {"data": "hello"}, "repeat": 30, "period": 0.2}]},
                           name="strings")
    assert '"ready"' in strings.stdout.readline(), ros.log(strings)
    rec = ros.probe({"listen": [{"topic": "/rubass/events", "type": "std_msgs/String"},
                                {"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"},
                                {"topic": "/safety_cmd", "type": TWIST}],
                     "advertise": [{"topic": "/speed", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/speed"}, {"wait_publishers": "/safety_cmd"}, {"sleep": 0.3},
                               {"mark": "both"},
                               {"publish": "/speed", "msg": {"data": 0.5}, "repeat": 15, "period": 0.2},
                               {"mark": "violate"}, {"publish": "/speed", "msg": {"data": 2.0}},
                               {"wait": "/safety_cmd", "timeout": 3}, {"sleep": 0.5}]}, timeout=60)
    both = next(r["wall"] for r in rec if r.get("name") == "both")
    violate = next(r["wall"] for r in rec if r.get("name") == "violate")
    events = [json.loads(r["msg"]["data"]) for r in rec if r["kind"] == "recv" and r["topic"] == "/rubass/events"]
    failsafe = [e["event"] for e in events if e.get("cause") == "data error"]
    # held while both publish, no flapping (it started with the String alone, before this probe listened)
    assert "release" not in failsafe and len(failsafe) <= 1, (failsafe, ros.log(mon))
    # the behaviour: no start before the real violation, then the stop at once
    stop = first(rec, "recv", "/safety_cmd")
    sent = [r for r in rec if r["kind"] == "sent" and r["msg"] == {"data": 2.0}][0]
    assert stop is not None and stop["wall"] > violate, ros.log(mon)
    assert stop["wall"] - sent["wall"] < 0.1
    starts = [e for e in events if e["event"] == "start" and e.get("cause") != "data error"]
    assert len(starts) == 1, starts
    # /diagnostics: ERROR naming the topic and both types, from a little after both publish
    monitor = [s for r in rec if r["kind"] == "recv" and r["topic"] == "/diagnostics" and r["wall"] > both + 0.5
               for s in r["msg"]["status"] if s["name"] == "rubass: monitor"]
    assert monitor and all(s["level"] == 2 for s in monitor), [s["message"] for s in monitor]
    text = monitor[-1]["message"]
    assert "/speed" in text and "std_msgs/String" in text and "std_msgs/Float64" in text, text
    # the Float64 publisher gone (the probe ended): the conflict is over, the String alone is its own error
    wait_log(mon, ros, "topic /speed: only std_msgs/String is published now: its data error of two types at once "
                       "is over", timeout=5)
    log = ros.log(mon).split("only std_msgs/String is published now")[0]
    assert log.count("publishers of 2 types at once") == 1 and "changed type" not in log, log
    assert log.count("running brake (~error_actions)") == 1 and "the data error is gone" not in log, log
    strings.kill()
    records(strings)
