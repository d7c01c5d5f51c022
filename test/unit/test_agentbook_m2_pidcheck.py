"""Issue 18: a node in its own PID namespace gives a pid that is not its process here; the
sampler checks that the pid owns the node's XML-RPC port before measuring (fake psutil)."""
import collections
import types

import pytest

pytest.importorskip("rosgraph")
from rubass.engine.values import UNKNOWN  # noqa: E402
from rubass.ros import pidcheck  # noqa: E402
from rubass.ros.nodes import NodeSampler  # noqa: E402

Conn = collections.namedtuple("Conn", "laddr status pid")
URI = "http://127.0.0.1:40123/"


class NoSuchProcess(Exception):
    pass


class AccessDenied(Exception):
    pass


def fake_psutil(listening, denied=(), system=None):
    """listening: pid -> ports it listens on; denied: pids whose sockets may not be read;
    system: what net_connections sees ({port: pid or None}), None: as `listening` says."""
    calls = collections.Counter()

    class Process:
        def __init__(self, pid):
            if pid not in listening:
                raise NoSuchProcess(pid)
            self.pid = pid

        def connections(self, kind):
            calls["process"] += 1
            if self.pid in denied:
                raise AccessDenied(self.pid)
            return [Conn(("0.0.0.0", p), "LISTEN", None) for p in listening[self.pid]] + \
                [Conn(("127.0.0.1", 5555), "ESTABLISHED", None)]

    def net_connections(kind):
        calls["system"] += 1
        seen = system if system is not None else {p: pid for pid, ports in listening.items() for p in ports}
        return [Conn(("0.0.0.0", port), "LISTEN", pid) for port, pid in seen.items()]

    return types.SimpleNamespace(Process=Process, net_connections=net_connections, NoSuchProcess=NoSuchProcess,
                                 ZombieProcess=NoSuchProcess, AccessDenied=AccessDenied, CONN_LISTEN="LISTEN"), calls


def test_the_pid_that_owns_the_port_may_be_measured_once_checked(monkeypatch):
    fake, calls = fake_psutil({4242: [40123]})
    monkeypatch.setattr(pidcheck, "psutil", fake)
    owners = pidcheck.PortOwners()
    assert owners.why_not("/hog", URI, 4242) is None
    assert owners.why_not("/hog", URI, 4242) is None
    assert calls["process"] == 1  # the verdict is kept per (URI, pid)


def test_pid_one_of_a_container_does_not_listen_on_the_nodes_port(monkeypatch):
    fake, calls = fake_psutil({1: [], 4242: [40123]})
    monkeypatch.setattr(pidcheck, "psutil", fake)
    why = pidcheck.PortOwners().why_not("/hog", URI, 1)
    assert why == ("pid 1 that /hog reports does not listen on its port 40123: the node runs in another PID "
                   "namespace (a container?); cannot measure it")


def test_a_pid_that_is_no_process_here_is_not_measured_and_checked_again(monkeypatch):
    fake, _ = fake_psutil({4242: [40123]})
    monkeypatch.setattr(pidcheck, "psutil", fake)
    owners = pidcheck.PortOwners()
    assert "pid 7 that /hog reports is no process of this host" in owners.why_not("/hog", URI, 7)
    assert (URI, 7) not in owners._verdicts  # the node may just have exited: not kept


def test_access_denied_asks_every_processs_sockets(monkeypatch):
    fake, calls = fake_psutil({1: [], 4242: [40123]}, denied={1})
    monkeypatch.setattr(pidcheck, "psutil", fake)
    why = pidcheck.PortOwners().why_not("/hog", URI, 1)
    assert "does not listen on its port 40123 (pid 4242 does)" in why and calls["system"] == 1


def test_access_denied_everywhere_measures_as_before(monkeypatch):
    fake, _ = fake_psutil({1: [], 4242: [40123]}, denied={1}, system={40123: None})
    monkeypatch.setattr(pidcheck, "psutil", fake)
    assert pidcheck.PortOwners().why_not("/hog", URI, 1) is None
    fake, _ = fake_psutil({1: [40123]}, denied={1})
    monkeypatch.setattr(pidcheck, "psutil", fake)
    assert pidcheck.PortOwners().why_not("/hog", URI, 1) is None  # it is the owner


def sampler_with(monkeypatch, fake, pid):
    submitted = []
    sampler = NodeSampler([("hog", "/hog")], lambda *a: submitted.append(a), lambda: 5.0, 0.1, "/test")
    monkeypatch.setattr(pidcheck, "psutil", fake)
    sampler._uris["/hog"] = URI
    sampler._ask = lambda st: (True, pid, "alive")
    measured = []
    sampler._measure = lambda p: measured.append(p) or (0.84, 1e6, "alive")
    return sampler, submitted, measured


def test_the_sampler_reads_a_container_nodes_cpu_unknown_and_says_why(monkeypatch):
    fake, _ = fake_psutil({1: [], 4242: [40123]})
    sampler, submitted, measured = sampler_with(monkeypatch, fake, 1)
    st = sampler.status["/hog"]
    sampler.sample(st)
    assert measured == [] and st.alive is True and st.cpu is UNKNOWN and st.memory is UNKNOWN
    assert "another PID namespace" in st.why and "pid 1 that /hog reports" in st.why
    assert submitted == [("hog", 5.0, True, UNKNOWN, UNKNOWN)]
    sampler._pool.shutdown(wait=False)


def test_the_sampler_measures_a_node_that_owns_its_port(monkeypatch):
    fake, _ = fake_psutil({4242: [40123]})
    sampler, submitted, measured = sampler_with(monkeypatch, fake, 4242)
    sampler.sample(sampler.status["/hog"])
    assert measured == [4242] and submitted == [("hog", 5.0, True, 0.84, 1e6)]
    sampler._pool.shutdown(wait=False)
