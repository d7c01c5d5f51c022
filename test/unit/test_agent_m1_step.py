"""Agent.step (rubass/ros/agent.py) with a scripted sampler: a report never waits for a node whose
sample hangs, carries each node's latest completed sample, reads a node unknown once its sample
has been under way longer than the monitor accepts, and never starts a second sample of it."""
import json
import threading
import time

import pytest

pytest.importorskip("rosgraph")
pytest.importorskip("psutil")

from rubass.ros.agent import Agent  # noqa: E402
from rubass.ros.nodes import NodeStatus  # noqa: E402

pytestmark = pytest.mark.ros

PERIOD = 0.02


@pytest.fixture
def agent():
    a = Agent("/agent", "10.0.0.2", "http://127.0.0.1:1/", PERIOD, lambda level, text: None)
    a.sampler.status = {n: NodeStatus(n, n) for n in ("/healthy", "/frozen")}
    release, calls = threading.Event(), {"/healthy": 0, "/frozen": 0}

    def sample(st):
        calls[st.resolved] += 1
        if st.resolved == "/frozen" and not release.wait(5.0):
            raise AssertionError("never released")
        st.alive, st.cpu, st.memory, st.pid, st.why = True, 0.25, 1000.0, 7, "alive"

    a.sampler.sample = sample
    yield a, release, calls
    release.set()
    a.close()


def nodes(text):
    return {n["node"]: n for n in json.loads(text)["nodes"]}


def test_a_hung_sample_delays_no_report_and_reads_unknown_after_three_periods_beyond_the_timeout(agent):
    a, release, calls = agent  # 3 periods (60 ms) + the getPid timeout (100 ms)
    took, reports = [], []
    for _ in range(15):
        t0 = time.monotonic()
        reports.append(nodes(a.step(100.0)))
        took.append(time.monotonic() - t0)
        time.sleep(PERIOD)
    assert max(took) < 0.5, took  # about half a period at most; not for the hung node (5 s)
    assert all(r["/healthy"]["cpu"] == 0.25 and r["/healthy"]["alive"] is True for r in reports)
    assert reports[0]["/frozen"]["why"] == "not sampled yet" and reports[0]["/frozen"]["alive"] is None
    last = reports[-1]["/frozen"]
    assert last["alive"] is None and last["cpu"] is None and last["memory"] is None
    assert last["why"].startswith("no answer from the node for ") and last["why"].endswith(" s (hung?)")
    assert calls["/frozen"] == 1 and calls["/healthy"] == 15  # no second sample while one is under way
    assert reports[1]["/frozen"]["why"] == "not sampled yet"  # 20-30 ms under way: not yet given up
    release.set()
    time.sleep(0.1)
    after = nodes(a.step(101.0))["/frozen"]
    assert after["alive"] is True and after["cpu"] == 0.25 and after["time"] == 101.0  # a new sample, done in time
    assert calls["/frozen"] == 2


def test_a_sample_under_way_for_less_than_three_periods_keeps_the_previous_one(agent):
    a, release, calls = agent
    a.sampler.timeout = 0.5  # 3 periods + 0.5 s: the 80 ms below stay within it on a loaded machine
    release.set()
    a.step(100.0)
    time.sleep(0.05)
    assert nodes(a.step(100.1))["/frozen"]["cpu"] == 0.25
    release.clear()
    a.step(100.2)  # starts a sample that hangs
    time.sleep(0.08)
    report = nodes(a.step(100.21))  # beyond 3 periods, within the getPid timeout: a busy node, not a hung one
    assert report["/frozen"]["cpu"] == 0.25 and report["/frozen"]["time"] == 100.1


def test_the_leaving_report_has_the_keys_of_a_report_and_no_nodes(agent):
    a, release, _ = agent
    release.set()
    first = json.loads(a.step(100.0))
    last = json.loads(a.leaving(100.5))
    assert last["leaving"] is True and last["nodes"] == [] and last["seq"] == first["seq"] + 1
    assert set(last) == set(first) | {"leaving"}
