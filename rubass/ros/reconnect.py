"""Connecting again to publishers whose connection ended while the master still lists them.

rospy connects a subscription to a publisher when the master says the publisher is there (at
subscription, and at each `publisherUpdate` the master sends when the topic's publishers
change), and never again by itself: a connection that ends while the publisher stays registered
(TCP's keepalive giving up after a link cut longer than ~2.5 min: 60 s idle, then 9 probes 10 s
apart; a publisher that closed it) leaves the topic unread for good, though the publisher goes
on publishing, and rules without an `age()` guard miss every later violation (an acceptance
tester's three-host run, with either receiver). Every `PERIOD` the monitor compares, for each
subscription of its process, the publishers the master lists (`getSystemState`, one call) with
its live connections, and, for a publisher missing two checks in a row (a new one is still
being connected), hands rospy the master's list, as a `publisherUpdate` would: rospy connects to
each listed publisher it has no connection to, retrying as it does at subscription.

The other way round, the robot's nodes' subscriptions to what the monitor publishes (its stops,
`~heartbeat`) end the same way, and their rospy or roscpp does not connect again either: the
monitor cannot make them, but a `registerPublisher` of that topic makes the master send every
subscriber a `publisherUpdate`, at which each connects to a publisher it has no connection to.
So a subscriber that was connected, lost, and is still listed by the master two checks in a row
gets that, again after 4, 8, … up to 60 s while it stays lost (a node killed without
unregistering stays listed until `rosnode cleanup`: the master then calls it in vain, once a
minute at most).
"""
from __future__ import annotations

import socket
import time
import xmlrpc.client
from typing import Any, Callable, Dict, List, Set, Tuple

from rospy.impl.registration import get_topic_manager

from . import rpc

Log = Callable[[str, str], None]
PERIOD = 2.0  # s between checks


class LostConnections:
    """Run `check()` every PERIOD (the master watch does, while the master answers)."""

    def __init__(self, caller_id: str, master_uri: str, log: Log, timeout: float = 0.5, node_uri: str = "") -> None:
        self.caller_id, self.log, self.node_uri = caller_id, log, node_uri
        self.reconnected = 0  # connections handed back to rospy to connect again, since start
        self.reannounced = 0  # publications registered again for a subscriber that lost its connection
        self._subscribers: Dict[str, Set[str]] = {}  # our topic -> subscriber nodes connected at some check
        self._lost_subs: Dict[Tuple[str, str], Tuple[int, float]] = {}  # (topic, node) -> (checks lost, next try)
        self._caller = rpc.Caller(master_uri, timeout)
        self._uris: Dict[str, str] = {}  # publisher node -> its XML-RPC URI, as the master last said
        self._missing: Set[Tuple[str, str]] = set()  # (topic, uri) missing at the last check

    def close(self) -> None:
        self._caller.close()

    def check(self, update: Callable[[str, List[str]], None]) -> int:
        """One comparison; `update(topic, uris)`: rospy's RegManager.publisher_update. How many
        connections it asked rospy to make again."""
        tm = get_topic_manager()
        topics = [name for name, _ in tm.get_subscriptions()]
        publications = tm.get_publications()
        if not topics and not publications:
            return 0
        try:
            state = self._caller.call("getSystemState", self.caller_id)[2]
            publishers, subscribers = dict(state[0]), dict(state[1])
        except (OSError, socket.error, xmlrpc.client.Error, IndexError, TypeError, ValueError):
            return 0  # the master watch says when the master cannot be reached
        self._announce(tm, publications, subscribers)
        missing: Set[Tuple[str, str]] = set()
        asked = 0
        for topic in topics:
            impl = tm.get_subscriber_impl(topic)
            nodes = publishers.get(topic, [])
            if impl is None or not nodes:
                continue
            have = {c.endpoint_id for c in list(impl.connections) if not c.done}
            uris = [self._uri(node, have) for node in nodes]
            lost = [(u, n) for u, n in zip(uris, nodes) if u and u not in have]
            now = {(topic, u) for u, _ in lost}
            missing |= now
            again = [(u, n) for u, n in lost if (topic, u) in self._missing]  # missing two checks in a row
            if again:
                update(topic, [u for u in uris if u])
                asked += len(again)
                names = ", ".join(f"{n} ({u})" for u, n in again)
                self.log("warn", f"topic {topic}: the connection to its publisher {names} had ended while the "
                                 f"master still lists it (a link cut longer than TCP's keepalive, ~2.5 min, or the "
                                 f"publisher closed it); rospy does not connect again by itself: connecting again")
                missing -= {(topic, u) for u, _ in again}  # asked: counted again only if still missing after
        self._missing = missing
        self.reconnected += asked
        return asked

    def _announce(self, tm: Any, publications: List[Tuple[str, str]], listed: Dict[str, List[str]]) -> None:
        """Register again a publication a listed subscriber has lost its connection to (see above)."""
        now = time.monotonic()
        lost: Dict[Tuple[str, str], Tuple[int, float]] = {}
        for topic, type_name in publications:
            impl = tm.get_publisher_impl(topic)
            if impl is None:
                continue
            have = {c.endpoint_id for c in list(impl.connections) if not getattr(c, "done", False)}
            seen = self._subscribers.setdefault(topic, set())
            seen |= have
            gone = [n for n in listed.get(topic, []) if n in seen and n not in have and n != self.caller_id]
            due = []
            for node in gone:
                checks, at = self._lost_subs.get((topic, node), (0, 0.0))
                checks += 1
                if checks >= 2 and now >= at:
                    due.append(node)
                    at = now + min(60.0, 4.0 * 2 ** min(checks - 2, 4))
                lost[(topic, node)] = (checks, at)
            if due and self.node_uri:
                try:
                    self._caller.call("registerPublisher", self.caller_id, topic, type_name, self.node_uri)
                except (OSError, socket.error, xmlrpc.client.Error, ValueError):
                    continue
                self.reannounced += 1
                self.log("warn", f"topic {topic}: subscriber {', '.join(due)} lost its connection to the monitor while "
                                 f"the master still lists it (a link cut longer than TCP's keepalive?); its rospy does "
                                 f"not connect again by itself: registered the publication again, so that the master "
                                 f"tells it to")
        self._lost_subs = lost

    def _uri(self, node: str, have: Set[str]) -> str:
        """The node's URI: the one known, if a connection to it is live; else asked of the master."""
        uri = self._uris.get(node, "")
        if uri and uri in have:
            return uri
        try:
            code, _, uri = self._caller.call("lookupNode", self.caller_id, node)
        except (OSError, socket.error, xmlrpc.client.Error, ValueError):
            return ""
        if code != 1 or not isinstance(uri, str):
            return ""
        self._uris[node] = uri
        return uri

