"""The agents' report format, the monitor's book of reports and their replay (pure)."""
import json

import pytest

from rubass.engine.values import UNKNOWN
from rubass.replay.agents import SAMPLES, agent_samples
from rubass.ros.agentbook import AgentBook, decode, encode, node_entry


def report(agent="/rubass_agent_b", host="10.200.1.2", period=0.1, nodes=(("/ctrl", 42, 0.5, 1e6),), t=100.0):
    entries = [node_entry(n, t, True, cpu, mem, pid, f"http://{host}:4000/", "alive") for n, pid, cpu, mem in nodes]
    return encode(agent, host, ["127.0.0.1", "hostb", host], t, period, 1, entries)


def test_encode_decode_round_trip_drops_loopback_and_keeps_samples():
    r = decode(report())
    assert r.agent == "/rubass_agent_b" and r.period == 0.1
    assert "127.0.0.1" not in r.addresses and "10.200.1.2" in r.addresses and "hostb" in r.addresses
    n = r.nodes["/ctrl"]
    assert (n.alive, n.cpu, n.memory, n.pid) == (True, 0.5, 1e6, 42)
    entry = json.loads(report())["nodes"][0]
    assert {"node", "time", "alive", "cpu", "memory"} <= set(entry)  # the ~node_samples keys


@pytest.mark.parametrize("text, words", [
    ("not json", "not JSON"), ("[1]", "not a JSON object"), ('{"period": 0.1, "nodes": []}', "'agent'"),
    ('{"agent": "/a", "period": 0, "nodes": []}', "'period'"),
    ('{"agent": "/a", "period": "fast", "nodes": []}', "'period'"),
    ('{"agent": "/a", "period": 0.1, "nodes": {}}', "'nodes' must be a list"),
    ('{"agent": "/a", "period": 0.1, "nodes": [{"cpu": 1}]}', "'node' name"),
])
def test_bad_reports_say_what_is_wrong(text, words):
    with pytest.raises(ValueError, match=words):
        decode(text)


def test_unknown_values_are_unknown_and_nan_makes_the_entry_invalid():
    r = decode(json.dumps({"agent": "/a", "period": 0.1, "nodes": [
        {"node": "/n", "alive": "yes", "cpu": None, "memory": None, "pid": True},
        {"node": "/m", "alive": True, "cpu": float("nan"), "memory": 1.0}]}))
    n = r.nodes["/n"]
    assert n.alive is None and n.cpu is None and n.memory is None and n.pid is None
    assert "/m" not in r.nodes and "node /m" in r.invalid[0]  # NaN is no value (test_agentbook_m2_*)


def test_lookup_uses_a_fresh_report_of_the_nodes_host():
    book = AgentBook()
    book.update(decode(report()), at=10.0)
    assert book.lookup("/ctrl", "10.200.1.2", 42, at=10.25) == (0.5, 1e6, "alive")
    assert book.silent(10.25) == []
    assert "ok, 1 node," in book.summary(10.25)


def test_a_report_older_than_three_periods_is_unknown_and_names_the_silent_agent():
    book = AgentBook()
    book.update(decode(report()), at=10.0)
    cpu, mem, why = book.lookup("/ctrl", "10.200.1.2", 42, at=10.31)
    assert cpu is UNKNOWN and mem is UNKNOWN
    assert "agent /rubass_agent_b on host 10.200.1.2 is silent" in why
    assert book.silent(10.31) == ["/rubass_agent_b on 10.200.1.2 for 0.3 s"]
    assert "SILENT" in book.summary(10.31)


def test_no_agent_for_the_host_says_so():
    book = AgentBook()
    book.update(decode(report()), at=10.0)
    cpu, _, why = book.lookup("/other", "10.200.9.9", 7, at=10.0)
    assert cpu is UNKNOWN and "no rubass agent reports" in why and "10.200.9.9" in why


def test_node_not_in_the_report_or_another_pid_is_unknown():
    book = AgentBook()
    book.update(decode(report()), at=10.0)
    assert "does not report this node" in book.lookup("/late", "10.200.1.2", 9, at=10.0)[2]
    cpu, _, why = book.lookup("/ctrl", "10.200.1.2", 43, at=10.0)
    assert cpu is UNKNOWN and "pid 42" in why and "restarted" in why


def test_a_node_is_found_by_name_when_its_host_is_named_differently():
    book = AgentBook()
    book.update(decode(report()), at=10.0)
    assert book.lookup("/ctrl", "hostb.example.org", 42, at=10.0)[0] == 0.5


def samples_of(records):
    return [(t, json.loads(m.data)) for t, topic, m in records if topic == SAMPLES]


class Msg:
    def __init__(self, data):
        self.data = data


def test_replay_expands_reports_and_expires_a_silent_agent():
    stream = [(1.0, "/rubass/agent_samples", Msg(report())), (1.05, "/cmd", "m1"),
              (1.1, "/rubass/agent_samples", Msg(report())), (2.0, "/cmd", "m2")]
    out = list(agent_samples(stream, {"/rubass/agent_samples"}, {"/ctrl": "ctrl"}, set(), end=3.0))
    assert [(t, topic) for t, topic, _ in out if topic == "/cmd"] == [(1.05, "/cmd"), (2.0, "/cmd")]
    s = samples_of(out)
    assert s[0] == (1.0, {"node": "ctrl", "alive": True, "cpu": 0.5, "memory": 1e6})
    assert s[-1][0] == pytest.approx(1.4) and s[-1][1]["cpu"] is None and s[-1][1]["alive"] is None
    assert len(s) == 3
    assert [t for t, _, _ in out] == sorted(t for t, _, _ in out)


def test_replay_leaves_nodes_the_monitor_sampled_and_unknown_names_alone():
    stream = [(1.0, "/rubass/agent_samples", Msg(report(nodes=(("/ctrl", 1, 0.1, 1.0), ("/x", 2, 0.2, 2.0)))))]
    out = list(agent_samples(stream, {"/rubass/agent_samples"}, {"/ctrl": "ctrl", "/x": "x"}, {"ctrl"}, end=1.2))
    assert [d["node"] for _, d in samples_of(out)] == ["x"]  # no expiry before the end


def test_replay_skips_a_broken_report():
    stream = [(1.0, "/rubass/agent_samples", Msg("{")), (1.1, "/cmd", "m")]
    assert list(agent_samples(stream, {"/rubass/agent_samples"}, {}, set(), end=2.0)) == [(1.1, "/cmd", "m")]


def test_diagnostics_warn_while_an_agent_is_silent_and_say_why_the_rule_is_unknown():
    from rubass.lang import check_text
    from rubass.actions import status

    spec = check_text("entity arm: hog { rules: busy: cpu(node hog) > 50 %; }\n")
    why = "agent /rubass_agent_b on host 10.200.1.2 is silent: its last report came 0.5 s ago"
    entries = status.build(spec, {"arm.busy": UNKNOWN}, [], {}, {"hog": {"why": why}}, {},
                           {"master": "connected", "silent agents": "/rubass_agent_b on 10.200.1.2 for 0.5 s"})
    arm, mon = entries
    assert dict(arm.values)["busy unknown because"] == f"node hog: {why}"
    assert mon.level == status.WARN and "agent silent: /rubass_agent_b on 10.200.1.2 for 0.5 s" in mon.message
    ok = status.build(spec, {"arm.busy": False}, [], {}, {}, {}, {"master": "connected", "silent agents": "none"})
    assert ok[-1].level == status.OK and "agent" not in ok[-1].message
