"""Issue 18, monitor side: several agents claiming one host, invalid entries, leaving agents,
and replay applying the live rule (rubass/ros/agentbook.py, rubass/replay/agents.py)."""
import json

import pytest

from rubass.engine.values import UNKNOWN
from rubass.replay.agents import SAMPLES, agent_samples
from rubass.ros.agentbook import COVERED_DROP_AFTER, AgentBook, decode, encode, node_entry

HOST = "10.218.0.2"


def report(agent="/rubass_agent_b", nodes=(("/hog", 42, 0.84, 1e6),), period=0.1, leaving=False, host=HOST):
    entries = [node_entry(n, 0.0, True, cpu, mem, pid, f"http://{host}:40123/", "alive") for n, pid, cpu, mem in nodes]
    return decode(encode(agent, host, [host], 0.0, period, 1, entries, leaving=leaving))


def fake(nodes):
    """The acceptance tester's fake agent /g (no pid, no addresses, no uri)."""
    return decode(json.dumps({"agent": "/g", "host": HOST, "period": 0.1, "time": 0, "nodes": nodes}))


def alternate(book, other, t0=10.0):
    """The real agent and `other` alternating at 10 Hz each; the cpu read after each report."""
    read = []
    for i in range(10):
        t = t0 + i * 0.1
        book.update(report(), t)
        read.append(book.lookup("/hog", HOST, 42, t + 0.01)[0])
        book.update(other, t + 0.05)
        read.append(book.lookup("/hog", HOST, 42, t + 0.06)[0])
    return read


@pytest.mark.parametrize("entry", [
    {"node": "/hog", "alive": True, "cpu": -7, "memory": -1},
    {"node": "/hog", "alive": True, "cpu": float("nan"), "memory": 1.0},
    {"node": "/hog", "alive": True, "cpu": "0.1", "memory": 1.0},
    {"node": "/hog", "alive": True, "cpu": 0.1, "memory": True},
    {"node": "/hog", "alive": True, "cpu": float("inf"), "memory": 1.0},
])
def test_an_out_of_range_entry_is_no_value_and_the_real_agent_keeps_its_node(entry):
    warned = []
    book = AgentBook(warn=warned.append)
    assert alternate(book, fake([entry])) == [0.84] * 20
    assert len(warned) == 1 and "/g" in warned[0] and "node /hog" in warned[0]  # throttled: one per 10 s


def test_the_invalid_entry_warning_comes_again_after_ten_seconds():
    warned = []
    book = AgentBook(warn=warned.append)
    bad = fake([{"node": "/hog", "cpu": -7, "memory": -1}])
    for t in (0.0, 5.0, 9.9, 10.0, 15.0, 20.5):
        book.update(bad, t)
    assert len(warned) == 3


def test_a_report_without_the_node_does_not_hide_the_agent_that_has_it():
    book = AgentBook(warn=lambda text: None)
    assert alternate(book, fake([])) == [0.84] * 20


def test_two_live_agents_on_one_host_warn_in_the_status():
    book = AgentBook(warn=lambda text: None)
    book.update(report(), 10.0)
    assert book.silent(10.05) == []
    book.update(fake([]), 10.02)
    assert book.conflicts(10.05) == [f"agents /g and /rubass_agent_b both report host {HOST}"]
    assert book.silent(10.05) == []
    assert book.conflicts(10.5) == []  # /g fell silent: one agent again


def test_among_several_fresh_reports_with_the_node_the_freshest_with_its_pid_wins():
    book = AgentBook(warn=lambda text: None)
    book.update(report("/a", (("/hog", 42, 0.5, 1.0),)), 10.0)
    book.update(report("/b", (("/hog", 42, 0.7, 1.0),)), 10.05)
    assert book.lookup("/hog", HOST, 42, 10.1)[0] == 0.7
    book.update(report("/c", (("/hog", 99, 0.1, 1.0),)), 10.08)  # measured another process
    assert book.lookup("/hog", HOST, 42, 10.1)[0] == 0.7


def test_a_leaving_agent_is_dropped_at_once_and_another_fresh_agent_covers_its_nodes():
    book = AgentBook(warn=lambda text: None)
    book.update(report("/a", (("/hog", 42, 0.5, 1.0),)), 10.0)
    book.update(report("/b", (("/hog", 42, 0.9, 1.0),)), 10.05)
    book.update(report("/b", (), leaving=True), 10.06)
    assert book.lookup("/hog", HOST, 42, 10.07)[0] == 0.5
    assert book.silent(12.0) == ["/a on 10.218.0.2 for 2.0 s"]  # no SILENT for /b, which left
    assert "/b: left" in book.summary(12.0) and "SILENT" not in book.summary(12.0).split("/b")[1]


def test_the_last_agent_of_a_host_leaving_makes_its_nodes_unknown_with_the_reason():
    book = AgentBook(warn=lambda text: None)
    book.update(report("/a"), 10.0)
    book.update(report("/a", (), leaving=True), 10.1)
    cpu, memory, why = book.lookup("/hog", HOST, 42, 10.11)
    assert cpu is UNKNOWN and memory is UNKNOWN and "agent /a left" in why
    assert book.silent(10.11) == [] and book.silent(100.0) == []
    book.update(report("/a2"), 11.0)  # a new agent on the host
    assert book.lookup("/hog", HOST, 42, 11.01)[0] == 0.84


def test_a_silent_agent_whose_host_another_agent_covers_is_said_then_dropped():
    warned = []
    book = AgentBook(warn=warned.append)
    book.update(report("/rubass_agent_b_1"), 10.0)  # relaunched under a new anonymous name
    for i in range(1, 400):
        book.update(report("/rubass_agent_b_2"), 10.0 + i * 0.1)
    now = 10.0 + 399 * 0.1
    assert book.lookup("/hog", HOST, 42, now)[0] == 0.84
    said = book.silent(10.5)
    assert len(said) == 1 and said[0].startswith("/rubass_agent_b_1 on 10.218.0.2") and "/rubass_agent_b_2" in said[0]
    assert book.silent(now) == [] and "_b_1" not in book.summary(now)
    assert len(warned) == 1 and "agent /rubass_agent_b_1 on 10.218.0.2 has been silent" in warned[0]
    assert "/rubass_agent_b_2 reports its host: dropped" in warned[0]
    assert now >= 10.3 + COVERED_DROP_AFTER


def test_a_silent_agent_alone_on_its_host_stays_listed():
    book = AgentBook(warn=lambda text: None)
    book.update(report("/a"), 10.0)
    assert book.silent(1000.0) == ["/a on 10.218.0.2 for 990.0 s"]


class Msg:
    def __init__(self, data):
        self.data = data


def replay(stream, end):
    out = agent_samples(stream, {"/rubass/agent_samples"}, {"/hog": "hog"}, set(), end)
    return [(t, json.loads(m.data)["cpu"]) for t, topic, m in out if topic == SAMPLES]


def live(stream, end, step=0.01):
    """What the live book gives the monitor, sampled every `step` over the same reports."""
    book, out, reports, t = AgentBook(warn=lambda text: None), [], list(stream), 0.0
    while t < end:
        while reports and reports[0][0] <= t:
            stamp, _, msg = reports.pop(0)
            book.update(decode(msg.data), stamp)
        cpu = book.lookup("/hog", HOST, 42, t)[0]
        out.append((round(t, 2), None if cpu is UNKNOWN else cpu))
        t = round(t + step, 2)
    return out


def two_agents_one_killed():
    """Agents /b and /extra on host b; /extra is SIGKILLed at 1 s, /b goes on."""
    stream = []
    for i in range(30):
        stream.append((round(i * 0.1, 3), "/rubass/agent_samples", Msg(encode(
            "/b", HOST, [HOST], 0, 0.1, i, [node_entry("/hog", 0, True, 0.84, 1e6, 42, "", "alive")]))))
        if i < 10:
            stream.append((round(i * 0.1 + 0.05, 3), "/rubass/agent_samples", Msg(encode(
                "/extra", HOST, [HOST], 0, 0.1, i, [node_entry("/hog", 0, True, 0.8, 1e6, 42, "", "alive")]))))
    return stream


def test_replay_keeps_a_node_another_agent_still_reports_when_one_falls_silent():
    samples = replay(two_agents_one_killed(), end=5.0)
    assert all(cpu is not None for t, cpu in samples if t < 2.9 + 0.3)  # /b reports until 2.9
    assert samples[-1] == (pytest.approx(3.2), None)  # then /b falls silent too


def test_replay_follows_the_live_rule():
    stream = two_agents_one_killed()
    stream.append((3.5, "/rubass/agent_samples", Msg(encode("/b", HOST, [HOST], 0, 0.1, 99, [], leaving=True))))
    given = replay(stream, end=5.0)

    def at(t):  # the replayed value in force at t
        last = [cpu for s, cpu in given if s <= t + 1e-9]
        return last[-1] if last else None

    for t, cpu in live(stream, 5.0):
        assert at(t) == cpu, (t, cpu, at(t))


def test_replay_after_a_leaving_report_reads_unknown_at_once():
    stream = [(0.0, "/rubass/agent_samples", Msg(encode("/b", HOST, [HOST], 0, 1.0, 1,
                                                        [node_entry("/hog", 0, True, 0.5, 1.0, 42, "", "")]))),
              (0.5, "/rubass/agent_samples", Msg(encode("/b", HOST, [HOST], 0, 1.0, 2, [], leaving=True)))]
    assert replay(stream, end=10.0) == [(0.0, 0.5), (0.5, None)]


def test_a_report_published_by_another_node_than_the_agent_it_names_is_ignored():
    """The acceptance re-sweep: a leaving report forged in the real agent's name dropped it (the stop
    released for 1 s); a plausible fake with no pid beat the agent that measured the answering pid."""
    warned = []
    book = AgentBook(warn=warned.append)
    assert book.update(report(), 10.0, caller="/rubass_agent_b")
    forged_leaving = report(nodes=(), leaving=True)
    assert not book.update(forged_leaving, 10.02, caller="/g")
    assert book.lookup("/hog", HOST, 42, 10.05)[0] == 0.84  # the real agent is still heard
    assert len(warned) == 1 and "published by /g in the name of agent /rubass_agent_b" in warned[0]
    assert book.update(forged_leaving, 10.06, caller=None)  # who published it is not known (a tool's bag)


def test_a_fake_without_a_pid_does_not_beat_the_agent_that_measured_the_answering_pid():
    book = AgentBook(warn=lambda text: None)
    low = fake([{"node": "/hog", "time": 0, "alive": True, "cpu": 0.0, "memory": 1000.0}])
    assert alternate(book, low) == [0.84] * 20


def test_three_agents_on_one_host_all_report_it():
    book = AgentBook(warn=lambda text: None)
    for i, name in enumerate(("/a", "/b", "/c")):
        book.update(report(agent=name), 10.0 + i * 0.01)
    assert book.conflicts(10.05) == [f"agents /a, /b and /c all report host {HOST}"]
