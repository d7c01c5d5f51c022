"""LostConnections (rubass/ros/reconnect.py): a publisher the master lists, to which the monitor's
subscription has no live connection two checks in a row, is handed to rospy to connect again;
one being connected, or connected, is left alone."""
from types import SimpleNamespace

import pytest

pytest.importorskip("rospy")

from rubass.ros import reconnect  # noqa: E402


class Master:
    def __init__(self):
        self.publishers = {"/cmd_vel": ["/driver"]}
        self.subscribers = {"/stop": ["/base"]}
        self.uris = {"/driver": "http://robot:4000/"}
        self.lookups = 0
        self.registered = []

    def call(self, method, *args):
        if method == "getSystemState":
            return 1, "", [list(self.publishers.items()), list(self.subscribers.items()), []]
        if method == "registerPublisher":
            self.registered.append(args[1:])
            return 1, "", []
        self.lookups += 1
        return 1, "", self.uris[args[1]]

    def close(self):
        pass


def watcher(monkeypatch, connections, subscribers=()):
    impl = SimpleNamespace(connections=connections)
    pub = SimpleNamespace(connections=list(subscribers))
    tm = SimpleNamespace(get_subscriptions=lambda: [("/cmd_vel", "geometry_msgs/Twist")],
                         get_subscriber_impl=lambda topic: impl,
                         get_publications=lambda: [("/stop", "geometry_msgs/Twist")],
                         get_publisher_impl=lambda topic: pub)
    monkeypatch.setattr(reconnect, "get_topic_manager", lambda: tm)
    logs = []
    lost = reconnect.LostConnections("/rubass", "http://master:11311/", lambda level, text: logs.append((level, text)),
                                     node_uri="http://monitor:5000/")
    lost.pub = pub
    lost._caller = Master()
    return lost, logs


def test_a_lost_connection_is_made_again_after_two_checks_and_logged(monkeypatch):
    lost, logs = watcher(monkeypatch, connections=[])
    asked = []
    assert lost.check(lambda topic, uris: asked.append((topic, uris))) == 0  # maybe being connected: wait
    assert lost.check(lambda topic, uris: asked.append((topic, uris))) == 1
    assert asked == [("/cmd_vel", ["http://robot:4000/"])] and lost.reconnected == 1
    assert logs[0][0] == "warn" and "topic /cmd_vel: the connection to its publisher /driver (http://robot:4000/)" \
        in logs[0][1]


def test_a_live_connection_or_one_being_made_is_left_alone_and_its_node_not_asked_again(monkeypatch):
    live = SimpleNamespace(endpoint_id="http://robot:4000/", done=False)
    lost, logs = watcher(monkeypatch, connections=[live])
    for _ in range(3):
        assert lost.check(lambda topic, uris: pytest.fail("nothing to connect")) == 0
    assert lost._caller.lookups == 1 and logs == []  # the URI known and live: the master not asked again


def test_a_connection_that_ended_counts_as_lost(monkeypatch):
    ended = SimpleNamespace(endpoint_id="http://robot:4000/", done=True)
    lost, _ = watcher(monkeypatch, connections=[ended])
    asked = []
    lost.check(lambda topic, uris: asked.append(uris))
    lost.check(lambda topic, uris: asked.append(uris))
    assert asked == [["http://robot:4000/"]]


def test_a_subscriber_that_lost_its_connection_is_told_again_through_the_master_with_backoff(monkeypatch):
    base = SimpleNamespace(endpoint_id="/base", done=False)
    lost, logs = watcher(monkeypatch, connections=[SimpleNamespace(endpoint_id="http://robot:4000/", done=False)],
                         subscribers=[base])
    master = lost._caller
    lost.check(lambda topic, uris: None)  # /base connected: seen
    lost.pub.connections = []  # its connection ended; the master still lists it
    lost.check(lambda topic, uris: None)
    assert master.registered == []  # one check: it may be a moment's
    lost.check(lambda topic, uris: None)
    assert master.registered == [("/stop", "geometry_msgs/Twist", "http://monitor:5000/")]
    assert lost.reannounced == 1 and "topic /stop: subscriber /base lost its connection" in logs[-1][1]
    lost.check(lambda topic, uris: None)
    assert len(master.registered) == 1  # not again before the backoff (4 s)
    lost.pub.connections = [base]  # it connected again
    lost.check(lambda topic, uris: None)
    assert lost._lost_subs == {}


def test_a_subscriber_never_connected_is_not_announced_to(monkeypatch):
    lost, _ = watcher(monkeypatch, connections=[SimpleNamespace(endpoint_id="http://robot:4000/", done=False)])
    for _ in range(4):
        lost.check(lambda topic, uris: None)
    assert lost._caller.registered == []  # /base listed but never connected: not ours to chase
