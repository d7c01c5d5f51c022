"""LostConnections (rubass/ros/reconnect.py): a node the master still lists, once connected and
without a live connection two checks in a row, is one episode: for a publisher of the monitor's
subscription rospy is asked once to connect again; for a subscriber of the monitor's publication
the publication is registered again if the node answers, with backoff. Nodes never connected
(stale registrations) are not chased, and episodes that end are counted."""
from types import SimpleNamespace

import pytest

pytest.importorskip("rospy")

from rubass.ros import reconnect  # noqa: E402


class Master:
    def __init__(self):
        self.publishers = {"/cmd_vel": ["/driver", "/ghost"]}  # /ghost: killed long ago, never connected
        self.subscribers = {"/stop": ["/base", "/ghost"]}
        self.uris = {"/driver": "http://robot:4000/", "/base": "http://base:4001/", "/ghost": "http://gone:1/"}
        self.calls = []

    def call(self, method, *args):
        self.calls.append(method)
        if method == "getSystemState":
            return 1, "", [list(self.publishers.items()), list(self.subscribers.items()), []]
        if method == "registerPublisher":
            return 1, "", []
        return 1, "", self.uris[args[1]]

    def close(self):
        pass


def sub_conn(node, done=False):
    return SimpleNamespace(header={"callerid": node}, endpoint_id="http://x/", done=done)


def make(monkeypatch, answers=True):
    sub = SimpleNamespace(connections=[sub_conn("/driver")])
    pub = SimpleNamespace(connections=[SimpleNamespace(endpoint_id="/base", done=False)])
    tm = SimpleNamespace(get_subscriptions=lambda: [("/cmd_vel", "geometry_msgs/Twist")],
                         get_subscriber_impl=lambda topic: sub,
                         get_publications=lambda: [("/stop", "geometry_msgs/Twist")],
                         get_publisher_impl=lambda topic: pub)
    monkeypatch.setattr(reconnect, "get_topic_manager", lambda: tm)
    probes = []

    def proxy(uri, timeout):
        def get_pid(caller):
            probes.append(uri)
            if not answers:
                raise OSError("timed out")
            return 1, "", 42
        return SimpleNamespace(getPid=get_pid)
    monkeypatch.setattr(reconnect.rpc, "proxy", proxy)
    logs = []
    lost = reconnect.LostConnections("/rubass", "http://master:11311/", lambda level, text: logs.append((level, text)),
                                     node_uri="http://monitor:5000/")
    lost._caller = Master()
    return lost, sub, pub, logs, probes


def test_a_publisher_whose_connection_ended_is_asked_for_once_and_counted_when_back(monkeypatch):
    lost, sub, _, logs, _ = make(monkeypatch)
    asked = []
    update = lambda topic, uris: asked.append((topic, uris))  # noqa: E731
    lost.check(update)  # /driver connected: seen
    sub.connections = []  # its connection ended; the master still lists it
    lost.check(update)
    assert asked == []  # one check: it may be a moment's
    lost.check(update)
    assert asked == [("/cmd_vel", ["http://robot:4000/", "http://gone:1/"])]  # the master's whole list, as its update
    assert "topic /cmd_vel: the connection from its publisher /driver had ended" in logs[-1][1]
    for _ in range(3):
        lost.check(update)
    assert len(asked) == 1 and len(logs) == 1  # once an episode: rospy retries on its own thread
    sub.connections = [sub_conn("/driver")]
    lost.check(update)
    assert lost.reconnected == 1 and logs[-1] == ("info", "topic /cmd_vel: publisher /driver is connected again")


def test_a_node_never_connected_is_not_chased(monkeypatch):
    lost, sub, pub, logs, probes = make(monkeypatch)
    for _ in range(5):
        assert lost.check(lambda topic, uris: pytest.fail("nothing to connect")) == 0
    assert logs == [] and probes == [] and "registerPublisher" not in lost._caller.calls


def test_a_lost_subscriber_that_answers_gets_the_publication_registered_again_with_backoff(monkeypatch):
    lost, _, pub, logs, probes = make(monkeypatch)
    clock = [1000.0]
    monkeypatch.setattr(reconnect.time, "monotonic", lambda: clock[0])
    noop = lambda topic, uris: None  # noqa: E731
    lost.check(noop)
    pub.connections = []
    lost.check(noop)
    lost.check(noop)
    assert lost._caller.calls.count("registerPublisher") == 1 and probes == ["http://base:4001/"]
    assert "topic /stop: subscriber /base lost its connection to the monitor" in logs[-1][1]
    clock[0] += 2.0
    lost.check(noop)
    assert lost._caller.calls.count("registerPublisher") == 1  # not again before 8 s
    clock[0] += 8.0
    lost.check(noop)
    assert lost._caller.calls.count("registerPublisher") == 2
    pub.connections = [SimpleNamespace(endpoint_id="/base", done=False)]
    lost.check(noop)
    assert lost.reconnected == 1


def test_a_lost_subscriber_that_does_not_answer_costs_the_master_nothing(monkeypatch):
    lost, _, pub, logs, probes = make(monkeypatch, answers=False)
    lost.check(lambda topic, uris: None)
    pub.connections = []
    for _ in range(4):
        lost.check(lambda topic, uris: None)
    assert len(probes) == 3 and "registerPublisher" not in lost._caller.calls and logs == []


def test_rospys_tables_changing_while_read_skip_a_check(monkeypatch):
    lost, *_ = make(monkeypatch)
    tm = SimpleNamespace(get_subscriptions=lambda: (_ for _ in ()).throw(RuntimeError("changed size")),
                         get_publications=lambda: [])
    monkeypatch.setattr(reconnect, "get_topic_manager", lambda: tm)
    assert lost.check(lambda topic, uris: None) == 0
