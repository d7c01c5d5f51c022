"""Parts of the ROS shell checked directly: the node sampler's verdicts and the topic watcher."""
import pytest

pytest.importorskip("rospy")

from rubass.engine.values import UNKNOWN  # noqa: E402
from rubass.lang import check_text  # noqa: E402
from rubass.ros.nodes import NodeSampler, NodeStatus  # noqa: E402

pytestmark = pytest.mark.ros


def test_a_node_on_another_host_is_alive_but_unmeasurable_and_says_why():
    got = []
    sampler = NodeSampler([("driver", "/driver")], lambda *a: got.append(a), lambda: 1.0, 0.1, "/rubass")
    sampler._ask = lambda name: (True, 4242, "alive")
    sampler._uris["/driver"] = "http://robot-arm-pc.invalid:40000/"
    st = NodeStatus("driver", "/driver")
    sampler.sample(st)
    assert got == [("driver", 1.0, True, UNKNOWN, UNKNOWN)]
    assert st.why == "on host robot-arm-pc.invalid, not this one: cpu and memory are unknown"


def test_a_local_node_is_measured_from_the_second_sample(tmp_path):
    import os


    import socket

    got = []
    sampler = NodeSampler([("me", "/me")], lambda *a: got.append(a), lambda: 1.0, 0.1, "/rubass")
    sampler._ask = lambda name: (True, os.getpid(), "alive")
    with socket.socket() as port:  # the pid a node gives must listen on its URI's port (pidcheck.py)
        port.bind(("127.0.0.1", 0))
        port.listen()
        sampler._uris["/me"] = f"http://127.0.0.1:{port.getsockname()[1]}/"
        st = NodeStatus("me", "/me")
        sampler.sample(st)
        sampler.sample(st)
    assert got[0][3] is UNKNOWN and got[0][4] > 1e6  # the first CPU reading only starts the count
    assert isinstance(got[1][3], float) and got[1][4] > 1e6


class _FakeCaller:
    """Stands for rpc.Caller: answers from a table, counts the calls."""

    def __init__(self, answers, calls, uri):
        self.answers, self.calls, self.uri = answers, calls, uri

    def call(self, method, *params):
        self.calls.append((self.uri, method))
        answer = self.answers[(self.uri, method)]
        if isinstance(answer, Exception):
            raise answer
        return answer

    def close(self):
        pass


def _fake_sampler(answers, calls, monkeypatch):
    from rubass.ros import nodes

    monkeypatch.setattr(nodes.rpc, "Caller", lambda uri, timeout, keep_alive=True: _FakeCaller(answers, calls, uri))
    sampler = NodeSampler([("driver", "/driver")], lambda *a: None, lambda: 1.0, 0.1, "/rubass")
    sampler.master_uri = "http://master:11311/"
    sampler._is_local = lambda host: False
    return sampler


def test_a_node_is_asked_at_its_uri_and_the_master_where_it_is_at_most_once_a_second(monkeypatch):
    import time

    calls, clock = [], [100.0]
    answers = {("http://master:11311/", "lookupNode"): [1, "", "http://pc:4000/"],
               ("http://pc:4000/", "getPid"): [1, "", 77]}
    sampler = _fake_sampler(answers, calls, monkeypatch)
    monkeypatch.setattr(time, "monotonic", lambda: clock[0])
    st = NodeStatus("driver", "/driver")
    for _ in range(10):  # a second of samples at 10 Hz
        sampler.sample(st)
        assert st.alive is True and st.pid == 77
        clock[0] += 0.099
    assert calls.count(("http://master:11311/", "lookupNode")) == 1
    assert calls.count(("http://pc:4000/", "getPid")) == 10
    clock[0] += 0.02
    sampler.sample(st)  # over a second since the master was asked: asked again
    assert calls.count(("http://master:11311/", "lookupNode")) == 2


def test_a_node_that_stops_answering_at_its_uri_is_looked_up_again_in_the_same_sample(monkeypatch):
    calls = []
    answers = {("http://master:11311/", "lookupNode"): [1, "", "http://pc:4000/"],
               ("http://pc:4000/", "getPid"): [1, "", 77]}
    sampler = _fake_sampler(answers, calls, monkeypatch)
    st = NodeStatus("driver", "/driver")
    sampler.sample(st)
    # the node restarted elsewhere: the old URI refuses, the master knows the new one
    answers[("http://pc:4000/", "getPid")] = ConnectionRefusedError("refused")
    answers[("http://master:11311/", "lookupNode")] = [1, "", "http://pc:4100/"]
    answers[("http://pc:4100/", "getPid")] = [1, "", 88]
    calls.clear()
    sampler.sample(st)
    assert st.alive is True and st.pid == 88
    assert calls == [("http://pc:4000/", "getPid"), ("http://master:11311/", "lookupNode"),
                     ("http://pc:4100/", "getPid")]
    # killed for good: the master still names the dead URI (it never forgets), nobody answers
    answers[("http://pc:4100/", "getPid")] = ConnectionRefusedError("refused")
    sampler.sample(st)
    assert st.alive is False and "does not answer" in st.why


def test_another_process_answering_at_the_uri_is_checked_with_the_master(monkeypatch):
    calls = []
    answers = {("http://master:11311/", "lookupNode"): [1, "", "http://pc:4000/"],
               ("http://pc:4000/", "getPid"): [1, "", 77]}
    sampler = _fake_sampler(answers, calls, monkeypatch)
    st = NodeStatus("driver", "/driver")
    sampler.sample(st)
    answers[("http://pc:4000/", "getPid")] = [1, "", 99]  # the port reused by another process
    answers[("http://master:11311/", "lookupNode")] = [-1, "unknown node", ""]  # the node is gone
    sampler.sample(st)
    assert st.alive is False and "another process (pid 99)" in st.why


def test_a_hung_node_reads_dead_after_one_timeout_not_two(monkeypatch):
    import socket

    calls = []
    answers = {("http://master:11311/", "lookupNode"): [1, "", "http://pc:4000/"],
               ("http://pc:4000/", "getPid"): [1, "", 77]}
    sampler = _fake_sampler(answers, calls, monkeypatch)
    st = NodeStatus("driver", "/driver")
    sampler.sample(st)
    answers[("http://pc:4000/", "getPid")] = socket.timeout("timed out")  # SIGSTOPped
    calls.clear()
    sampler.sample(st)
    assert st.alive is False and "did not answer getPid within 100 ms" in st.why
    assert calls == [("http://pc:4000/", "getPid"), ("http://master:11311/", "lookupNode")]


def test_every_getpid_is_asked_on_a_connection_of_its_own():
    # a node that shut down closes its listening socket, but a connection it had accepted may
    # still be answered by its threads: liveness must never ride on a kept connection
    import threading
    from xmlrpc.server import SimpleXMLRPCRequestHandler, SimpleXMLRPCServer

    class Http11(SimpleXMLRPCRequestHandler):
        protocol_version = "HTTP/1.1"

    accepted = []

    class Server(SimpleXMLRPCServer):
        def process_request(self, request, client_address):
            accepted.append(client_address)
            super().process_request(request, client_address)

    srv = Server(("127.0.0.1", 0), Http11, logRequests=False)
    srv.register_function(lambda caller: [1, "", 4242], "getPid")
    thread = threading.Thread(target=srv.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True)
    thread.start()
    try:
        sampler = NodeSampler([("n", "/n")], lambda *a: None, lambda: 1.0, 0.1, "/rubass")
        uri = f"http://127.0.0.1:{srv.server_address[1]}/"
        assert [sampler._pid_at(uri) for _ in range(3)] == [(4242, "")] * 3
        assert len(accepted) == 3
    finally:
        srv.shutdown()
        srv.server_close()


def test_run_times_keep_their_proc_files_within_the_budget_and_close_them(monkeypatch):
    import os
    import threading

    from rubass.ros import nodes

    stop = threading.Event()
    workers = [threading.Thread(target=stop.wait) for _ in range(6)]  # this process: 7+ threads
    for w in workers:
        w.start()
    try:
        monkeypatch.setattr(nodes, "KEPT_FILES", nodes._KeptFiles(3))
        before = len(os.listdir("/proc/self/fd"))
        reader = nodes.RunTime(os.getpid())
        first = reader.seconds()
        assert nodes.KEPT_FILES.held == 3 and len(os.listdir("/proc/self/fd")) == before + 3
        second = reader.seconds()  # the kept files read again, the others opened and closed
        assert second >= first > 0
        assert abs(second - nodes._schedstat_seconds(os.getpid())) < 0.05
        reader.close()
        assert nodes.KEPT_FILES.held == 0 and len(os.listdir("/proc/self/fd")) == before
    finally:
        stop.set()
        for w in workers:
            w.join()


def test_cpu_of_a_busy_process_is_not_quantized_to_ten_percent_steps():
    import subprocess
    import sys
    import time

    busy = subprocess.Popen([sys.executable, "-c", "import socket\ns = socket.socket()\ns.bind(('127.0.0.1', 0))\n"
                             "s.listen()\nprint(s.getsockname()[1], flush=True)\nwhile True: pass"],
                            stdout=subprocess.PIPE, text=True)  # it listens on its URI's port, as a node does
    try:
        from rubass.ros.nodes import _schedstat_seconds

        port = int(busy.stdout.readline())
        got = []
        sampler = NodeSampler([("b", "/b")], lambda *a: got.append(a[3]), lambda: 1.0, 0.1, "/rubass")
        sampler._ask = lambda name: (True, busy.pid, "alive")
        sampler._uris["/b"] = f"http://127.0.0.1:{port}/"
        st = NodeStatus("b", "/b")
        sampler.sample(st)  # the first reading only starts the count
        used0, t0 = _schedstat_seconds(busy.pid), time.monotonic()
        for _ in range(11):
            time.sleep(0.1)
            sampler.sample(st)
        overall = (_schedstat_seconds(busy.pid) - used0) / (time.monotonic() - t0)
        shares = got[1:]
        # the share it had (a whole core on an idle machine, less when others run), sample by sample
        assert overall > 0.2 and abs(sum(shares) / len(shares) - overall) < 0.1 * overall + 0.02, (shares, overall)
        sampler.stop()

        runs = [_schedstat_seconds(busy.pid) for _ in range(3)]  # nanoseconds, not 10 ms clock ticks
        assert any(abs(r * 100 - round(r * 100)) > 1e-6 for r in runs), runs
    finally:
        busy.kill()
        busy.wait()
        busy.stdout.close()


def test_topics_read_only_by_age_are_never_deserialised():
    import rospy

    from rubass.ros.topics import TopicWatcher

    rospy.rostime.set_rostime_initialized(True)
    spec = check_text("entity a { rules: r: age(topic /blob) > 1 s; }\n", "/tmp/x.rbs")
    got = []
    watcher = TopicWatcher(lambda *a: got.append(a), lambda level, text: got.append(("log", text)))
    watcher.topics["/blob"] = state = __import__("rubass.ros.topics", fromlist=["TopicState"]).TopicState(
        "/blob", "/blob", {})
    assert spec.topics["/blob"].needs_data is False

    class Raw:
        _buff = b"\xff\x00 not a message at all"
        _connection_header = {"type": "weird/Type", "md5sum": "0" * 32, "message_definition": "garbage !!"}

    watcher._callback(Raw(), state)
    assert len(got) == 1 and got[0][0] == "/blob" and got[0][2] is None and state.cls is None


def _watch(topic="/x", body="entity a { rules: r: topic /x.data > 1; }\n"):
    """A TopicWatcher on one topic of a spec, fed by hand: (watcher, state, submitted, logs)."""
    import rospy

    from rubass.ros.topics import TopicState, TopicWatcher

    rospy.rostime.set_rostime_initialized(True)
    spec = check_text(body, "/tmp/x.rbs")
    got, logs = [], []
    watcher = TopicWatcher(lambda *a: got.append(a), lambda level, text: logs.append(text))
    return watcher, TopicState(topic, topic, spec.field_readers()[topic]), got, logs


def _raw(buff, type_name, md5, definition):
    r = type("Raw", (), {})()
    r._buff, r._connection_header = buff, {"type": type_name, "md5sum": md5, "message_definition": definition}
    return r


def _raw_of(msg):
    """What rospy.AnyMsg hands the callback for msg: its bytes and its connection header."""
    import io

    buf = io.BytesIO()
    msg.serialize(buf)
    return _raw(buf.getvalue(), msg._type, msg._md5sum, msg._full_text)


def test_a_topic_that_changes_type_is_reported_and_its_fields_rechecked():
    from std_msgs.msg import Float64, String

    watcher, state, got, logs = _watch()
    watcher._callback(_raw_of(Float64(5.0)), state)
    watcher._callback(_raw_of(String("five")), state)
    assert got[0][2].data == 5.0 and got[1][2].data == "five"
    assert "topic /x changed type from std_msgs/Float64 to std_msgs/String" in logs
    assert state.type == "std_msgs/String" and "changed type from std_msgs/Float64 to std_msgs/String" in state.errors


def test_a_publisher_with_another_definition_under_a_known_name_is_read_by_its_own_definition():
    import genpy.dynamic

    watcher, state, got, logs = _watch()
    # an old or forked std_msgs/Float64 whose data is a float32: another md5 than the installed one
    fake = genpy.dynamic.generate_dynamic("std_msgs/Float64", "float32 data\n")["std_msgs/Float64"]
    watcher._callback(_raw_of(fake(data=2.5)), state)
    assert got[-1][2].data == 2.5 and state.errors == [], logs
    # the same name with a definition that lacks the field: unknown, and said why
    other = genpy.dynamic.generate_dynamic("std_msgs/Float64", "int32 value\n")["std_msgs/Float64"]
    watcher._callback(_raw_of(other(value=7)), state)
    assert any("reads /x.data, but in std_msgs/Float64: std_msgs/Float64 has no field 'data'" in e
               for e in state.errors), state.errors


def test_a_payload_that_does_not_match_its_type_is_unknown_and_logged_once():
    from std_msgs.msg import Float64

    from rubass.engine import UNKNOWN

    watcher, state, got, logs = _watch()
    for _ in range(1000):  # 3 bytes where a float64 needs 8
        watcher._callback(_raw(b"\x01\x02\x03", "std_msgs/Float64", Float64._md5sum, Float64._full_text), state)
    assert all(g[2] is UNKNOWN for g in got) and len(got) == 1000
    assert len([t for t in logs if "cannot deserialise" in t]) == 1, "logged once, not once per message"


def test_a_node_the_master_did_not_know_stays_dead_while_the_master_cannot_be_reached(monkeypatch):
    """`not alive(node /lidar)` for a lidar that never registered: a master that went away turned it
    unknown, which released the stop for the whole outage (an acceptance sweep; docs/monitor.md says
    such a node is false). No node registers without the master, so its last answer still holds."""
    calls = []
    answers = {("http://master:11311/", "lookupNode"): [-1, "unknown node [/driver]", ""]}
    sampler = _fake_sampler(answers, calls, monkeypatch)
    st = NodeStatus("driver", "/driver")
    sampler.sample(st)
    assert st.alive is False and st.why == "not registered with the master"
    answers[("http://master:11311/", "lookupNode")] = ConnectionRefusedError("refused")
    sampler.sample(st)
    assert st.alive is False and "not registered with the master at its last answer" in st.why
    answers[("http://master:11311/", "lookupNode")] = [1, "", "http://pc:4000/"]  # back; the node registered
    answers[("http://pc:4000/", "getPid")] = [1, "", 77]
    sampler.sample(st)
    assert st.alive is True


def test_a_node_never_asked_about_is_unknown_while_the_master_cannot_be_reached(monkeypatch):
    answers = {("http://master:11311/", "lookupNode"): ConnectionRefusedError("refused")}
    sampler = _fake_sampler(answers, [], monkeypatch)
    st = NodeStatus("driver", "/driver")
    sampler.sample(st)
    assert st.alive is UNKNOWN and "never seen" in st.why


def test_a_reload_that_changes_the_nodes_keeps_what_the_sampler_knew(monkeypatch):
    """The review: a reload adding a node while the master was away built a new sampler that knew
    nothing, and the never-registered lidar read unknown again, releasing its stop."""
    calls = []
    answers = {("http://master:11311/", "lookupNode"): [-1, "unknown node [/driver]", ""]}
    old = _fake_sampler(answers, calls, monkeypatch)
    old.sample(old.status["/driver"])
    answers[("http://master:11311/", "lookupNode")] = ConnectionRefusedError("refused")  # the master goes away
    new = NodeSampler([("driver", "/driver"), ("camera", "/camera")], lambda *a: None, lambda: 1.0, 0.1, "/rubass")
    new.master_uri, new._is_local = old.master_uri, old._is_local
    new.carry(old)
    new.sample(new.status["/driver"])
    new.sample(new.status["/camera"])
    assert new.status["/driver"].alive is False, new.status["/driver"].why
    assert new.status["/camera"].alive is UNKNOWN  # never asked about: unknown, as before
