"""Why a published action reached no one: the nodes that subscribe to its topic, and the type each
subscribes with. rospy refuses a connection whose type differs (a WARN "topic types do not match"
in the subscriber), so "no node subscribes" would be false there and would send the engineer
looking for a dead base when the library names the wrong type.

Asked only when a start reached no subscriber, with a timeout on every call (a hung master or node
must not hold the action's runner), and kept a few seconds: the runner retries every second."""
from __future__ import annotations

import time
import xmlrpc.client
from typing import Dict, List, Optional, Tuple

import rosgraph
import rospy

from ..actions.status import topic_shown
from . import rpc

BUDGET = 0.5  # seconds for all the calls of one explanation (the runner's periodic output waits for it)
KEEP = 5.0  # seconds an answer is reused
MAX_NODES = 5  # subscribers asked for their type


def _subscribers(caller: rpc.Caller, me: str, topic: str) -> List[str]:
    code, _, state = caller.call("getSystemState", me)
    if code != 1:
        return []
    return [n for name, nodes in state[1] if name == topic for n in nodes if n != me]


def _subscribed_type(master_uri: str, me: str, node: str, topic: str, end: float) -> Optional[str]:
    """The type `node` subscribes to `topic` with (None when it cannot be asked before `end`)."""
    try:
        code, _, uri = rpc.Caller(master_uri, max(0.01, end - time.monotonic()), keep_alive=False).call(
            "lookupNode", me, node)
        if code != 1 or time.monotonic() >= end:
            return None
        code, _, subs = rpc.Caller(uri, max(0.01, end - time.monotonic()), keep_alive=False).call(
            "getSubscriptions", me)
    except (OSError, xmlrpc.client.Error, ValueError):
        return None
    return dict((t, ty) for t, ty in subs).get(topic) if code == 1 else None


def explain(topic: str, published: str) -> str:
    """The reason a message of type `published` on `topic` reached no subscriber, as a sentence."""
    resolved, me, uri = rospy.resolve_name(topic), rospy.get_name(), rosgraph.get_master_uri()
    topic = topic_shown(topic, resolved, "the action library")  # a namespace or a remap moves it
    end = time.monotonic() + BUDGET
    try:
        nodes = _subscribers(rpc.Caller(uri, BUDGET, keep_alive=False), me, resolved)
    except (OSError, xmlrpc.client.Error, ValueError):
        return f"no subscriber of {topic} is connected (the master did not answer to say more)"
    if not nodes:
        return f"no node subscribes to {topic}"
    types: Dict[str, Optional[str]] = {n: _subscribed_type(uri, me, n, resolved, end) for n in nodes[:MAX_NODES]}
    other = {n: t for n, t in types.items() if t not in (None, published, "*")}
    if other:
        said = ", ".join(f"{n} as {t}" for n, t in sorted(other.items()))
        return (f"{topic} has subscribers of another type ({said}; this action publishes {published}, and "
                f"rospy refuses a connection whose type differs)")
    return f"{', '.join(sorted(nodes))} subscribe{'s' * (len(nodes) == 1)} to {topic} but {'is' if len(nodes) == 1 else 'are'} not connected yet"


class Reach:
    """explain(), kept KEEP seconds per topic and type (the runner retries every second)."""

    def __init__(self) -> None:
        self._kept: Dict[Tuple[str, str], Tuple[float, str]] = {}

    def why(self, topic: str, published: str) -> str:
        now = time.monotonic()
        at, text = self._kept.get((topic, published), (-KEEP, ""))
        if now - at >= KEEP:
            text = explain(topic, published)
            self._kept[(topic, published)] = (now, text)
        return text
