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
"""
from __future__ import annotations

import socket
import xmlrpc.client
from typing import Callable, Dict, List, Set, Tuple

from rospy.impl.registration import get_topic_manager

from . import rpc

Log = Callable[[str, str], None]
PERIOD = 2.0  # s between checks


class LostConnections:
    """Run `check()` every PERIOD (the master watch does, while the master answers)."""

    def __init__(self, caller_id: str, master_uri: str, log: Log, timeout: float = 0.5) -> None:
        self.caller_id, self.log = caller_id, log
        self.reconnected = 0  # connections handed back to rospy to connect again, since start
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
        if not topics:
            return 0
        try:
            publishers = dict(self._caller.call("getSystemState", self.caller_id)[2][0])
        except (OSError, socket.error, xmlrpc.client.Error, IndexError, TypeError, ValueError):
            return 0  # the master watch says when the master cannot be reached
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

