"""Connecting again where a connection ended while the master still lists both ends.

rospy connects a subscription to a publisher when the master says the publisher is there (at
subscription, and at each `publisherUpdate` the master sends when the topic's publishers
change), and never again by itself: a connection that ends while the publisher stays registered
(TCP's keepalive giving up after a link cut longer than ~2.5 min: 60 s idle, then 9 probes 10 s
apart; a publisher that closed it) leaves the topic unread for good, though the publisher goes
on publishing, and rules without an `age()` guard miss every later violation (an acceptance
tester's three-host run, with either receiver).

Every `PERIOD` (the master watch's thread, one `getSystemState`) the monitor compares, for each
subscription of its process, the publisher nodes the master lists with the nodes it has a live
connection from. A node it had a connection from, that is still listed and has none two checks
in a row, is one episode: the monitor hands rospy the master's list of the topic's publishers
once (`RegManager.publisher_update`, as a `publisherUpdate` would: rospy connects to each one it
has no connection to, and retries as it does then), logs it once, and counts the episode when the
node is connected again. A node never connected (a stale registration of a killed node) is not
chased.

The other way round, the robot's nodes' subscriptions to what the monitor publishes (its stops,
`~heartbeat`) end the same way, and their rospy or roscpp does not connect again either. The
monitor cannot make them; a `registerPublisher` of the topic makes the master send each of its
subscribers a `publisherUpdate`, at which each connects to the publishers it has no connection
to. So for a subscriber node that was connected, lost, and is still listed, the monitor first
asks that node itself whether it answers (`getPid`, 0.5 s): only then does it register the
publication again (the master's three notification workers are not spent on a node that cannot
answer), 4 s after the loss, then at most every 8, 16, … 60 s while it stays lost, 10 times at
most.
"""
from __future__ import annotations

import socket
import time
import xmlrpc.client
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Set, Tuple

from rospy.impl.registration import get_topic_manager

from . import rpc

Log = Callable[[str, str], None]
PERIOD = 2.0  # s between checks
TRIES = 10  # registrations of a publication again for one lost subscriber
_ERRORS = (OSError, socket.error, xmlrpc.client.Error, ValueError, TypeError, IndexError)


@dataclass
class _Episode:
    """A node whose connection ended while the master still lists it."""

    checks: int = 0  # checks it has been seen lost
    tries: int = 0  # what was done about it (asked rospy / registered again)
    next_at: float = 0.0  # monotonic: the earliest next try


class LostConnections:
    """`check()` every PERIOD (the master watch does, while the master answers)."""

    def __init__(self, caller_id: str, master_uri: str, log: Log, timeout: float = 0.5, node_uri: str = "") -> None:
        self.caller_id, self.log, self.node_uri, self.timeout = caller_id, log, node_uri, timeout
        self.reconnected = 0  # episodes that ended with the connection live again (both ways), since start
        self._caller = rpc.Caller(master_uri, timeout)
        self._had: Dict[Tuple[str, str], Set[str]] = {}  # ("sub"|"pub", topic) -> nodes it was connected to
        self._lost: Dict[Tuple[str, str, str], _Episode] = {}  # (kind, topic, node) -> its episode

    def close(self) -> None:
        self._caller.close()

    def check(self, update: Callable[[str, List[str]], None]) -> int:
        """One comparison; `update(topic, uris)`: rospy's RegManager.publisher_update. How many
        things it did (rospy asked to connect, publications registered again)."""
        tm = get_topic_manager()
        try:  # rospy's tables, read without its lock (a registration retrying a master that is down holds it)
            subs = [(name, tm.get_subscriber_impl(name)) for name, _ in tm.get_subscriptions()]
            pubs = [(name, type_name, tm.get_publisher_impl(name)) for name, type_name in tm.get_publications()]
        except RuntimeError:  # changed while read (a reload): the next check
            return 0
        if not subs and not pubs:
            return 0
        try:
            state = self._caller.call("getSystemState", self.caller_id)[2]
            publishers, subscribers = dict(state[0]), dict(state[1])
        except _ERRORS:
            return 0  # the master watch says when the master cannot be reached
        now, done, lost = time.monotonic(), 0, {}
        for topic, impl in subs:
            live = _live(impl, by_header=True)
            for node in self._lost_nodes("sub", topic, live, publishers.get(topic, []), lost):
                done += self._ask_rospy(topic, node, publishers.get(topic, []), lost, update)
        probed: Dict[str, bool] = {}
        for topic, type_name, impl in pubs:
            live = _live(impl, by_header=False)
            for node in self._lost_nodes("pub", topic, live, subscribers.get(topic, []), lost):
                done += self._announce(topic, type_name, node, lost, now, probed)
        self._lost = lost
        return done

    def _lost_nodes(self, kind: str, topic: str, live: Set[str], listed: List[str],
                    lost: Dict[Tuple[str, str, str], _Episode]) -> List[str]:
        """The listed nodes of `topic` once connected and not now, each lost two checks in a row;
        the episodes of nodes connected again are counted and logged as over."""
        had = self._had.setdefault((kind, topic), set())
        had |= live
        for node in live:
            if self._lost.get((kind, topic, node)) is not None and self._lost[(kind, topic, node)].tries:
                self.reconnected += 1
                self.log("info", f"topic {topic}: {'publisher' if kind == 'sub' else 'subscriber'} {node} is "
                                 f"connected again")
        out = []
        for node in listed:
            if node in had and node not in live and node != self.caller_id:
                episode = self._lost.get((kind, topic, node)) or _Episode()
                episode.checks += 1
                lost[(kind, topic, node)] = episode
                if episode.checks >= 2:
                    out.append(node)
        return out

    def _ask_rospy(self, topic: str, node: str, listed: List[str], lost: Dict[Tuple[str, str, str], _Episode],
                   update: Callable[[str, List[str]], None]) -> int:
        """Once an episode: the topic's listed publishers' URIs to rospy, which connects to those it has
        no connection to (and retries on its own thread until it can, as at subscription)."""
        episode = lost[("sub", topic, node)]
        if episode.tries:
            return 0
        uris = [u for u in (self._lookup(n) for n in listed) if u]
        if not uris:
            return 0  # the master could not say: the next check
        episode.tries = 1
        update(topic, uris)
        self.log("warn", f"topic {topic}: the connection from its publisher {node} had ended while the master still "
                         f"lists it (a link cut longer than TCP's keepalive, ~2.5 min, or the publisher closed it); "
                         f"rospy does not connect again by itself: connecting again")
        return 1

    def _announce(self, topic: str, type_name: str, node: str, lost: Dict[Tuple[str, str, str], _Episode],
                  now: float, probed: Dict[str, bool]) -> int:
        """Register `topic`'s publication again for a lost subscriber `node`, if it answers (see above)."""
        episode = lost[("pub", topic, node)]
        if episode.tries >= TRIES or now < episode.next_at or not self.node_uri:
            return 0
        if node not in probed:
            probed[node] = self._answers(node)
        if not probed[node]:
            return 0  # unreachable or hung: not worth a master's worker; looked at again next check
        try:
            self._caller.call("registerPublisher", self.caller_id, topic, type_name, self.node_uri)
        except _ERRORS:
            return 0
        episode.tries += 1
        episode.next_at = now + min(60.0, 4.0 * 2 ** episode.tries)
        if episode.tries == 1:
            self.log("warn", f"topic {topic}: subscriber {node} lost its connection to the monitor while the master "
                             f"still lists it (a link cut longer than TCP's keepalive?); its rospy does not connect "
                             f"again by itself: registered the publication again, so that the master tells it to")
        return 1

    def _lookup(self, node: str) -> Optional[str]:
        try:
            code, _, uri = self._caller.call("lookupNode", self.caller_id, node)
        except _ERRORS:
            return None
        return uri if code == 1 and isinstance(uri, str) else None

    def _answers(self, node: str) -> bool:
        """Whether the node's own XML-RPC server answers a getPid within the timeout."""
        uri = self._lookup(node)
        if not uri:
            return False
        try:
            return rpc.proxy(uri, self.timeout).getPid(self.caller_id)[0] == 1
        except _ERRORS:
            return False


def _live(impl: Any, by_header: bool) -> Set[str]:
    """The nodes a topic's live connections are with: a subscription's from the publisher's handshake
    header (`callerid`), a publication's from its endpoint id (the subscriber's callerid)."""
    if impl is None:
        return set()
    out = set()
    for c in list(impl.connections):
        if getattr(c, "done", False):
            continue
        if by_header:
            header = getattr(c, "header", None) or {}
            if header.get("callerid"):
                out.add(header["callerid"])
        elif getattr(c, "endpoint_id", None):
            out.add(c.endpoint_id)
    return out
