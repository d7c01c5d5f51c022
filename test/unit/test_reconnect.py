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
        self.uris = {"/driver": "http://robot:4000/"}
        self.lookups = 0

    def call(self, method, *args):
        if method == "getSystemState":
            return 1, "", [list(self.publishers.items()), [], []]
        self.lookups += 1
        return 1, "", self.uris[args[1]]

    def close(self):
        pass


def watcher(monkeypatch, connections):
    impl = SimpleNamespace(connections=connections)
    tm = SimpleNamespace(get_subscriptions=lambda: [("/cmd_vel", "geometry_msgs/Twist")],
                         get_subscriber_impl=lambda topic: impl)
    monkeypatch.setattr(reconnect, "get_topic_manager", lambda: tm)
    logs = []
    lost = reconnect.LostConnections("/rubass", "http://master:11311/", lambda level, text: logs.append((level, text)))
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
