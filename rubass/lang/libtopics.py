"""Actions that publish on one topic (LANGUAGE.md §16): they must agree on its message type
(ROS keeps one publisher per topic in a process, of the first action's type: a second type's
messages would go out as the first's, garbage on the wire), and differ in priority."""
from __future__ import annotations

from typing import TYPE_CHECKING, Callable, Dict, Iterable, List, Tuple

from .errors import Diagnostic
from .source import Span
from .topicnames import resolve as resolve_topic

if TYPE_CHECKING:
    from .library import ActionDef

# plugin -> (the key of the topic it publishes on, the key of its message type)
PUBLISHERS: Dict[str, Tuple[str, str]] = {"publish": ("topic", "type"), "limit": ("topic", "type")}


def _place(first: "ActionDef", a: "ActionDef") -> str:
    return f"line {first.span.line}" if first.span.file == a.span.file else str(first.span)


def key_span(a: "ActionDef", *keys: str) -> Span:
    """Where the first of these keys' values is written in the action's YAML (else the action's name)."""
    for key in keys:
        span = a.key_spans.get(key)
        if span is not None:
            return span
    return a.span


def topic_conflicts(actions: Iterable["ActionDef"], resolve: Callable[[str], str] = resolve_topic) -> List[Diagnostic]:
    """One error for each action, in the given order, that publishes on a topic an earlier one
    publishes on with another message type, or with the same priority. Each names its action
    (`subject`); topic names are compared resolved (`cmd_vel` is `/cmd_vel` at the root)."""
    by_topic: Dict[str, List["ActionDef"]] = {}
    out: List[Diagnostic] = []
    for a in actions:
        keys = PUBLISHERS.get(a.plugin)
        if keys is None:
            continue
        topic = resolve(str(a.params[keys[0]]))
        earlier = by_topic.setdefault(topic, [])
        mine = str(a.params[keys[1]])
        other = next((e for e in earlier if str(e.params[PUBLISHERS[e.plugin][1]]) != mine), None)
        if other is not None:
            theirs = other.params[PUBLISHERS[other.plugin][1]]
            out.append(Diagnostic(key_span(a, keys[1], keys[0]),
                                  f"action '{a.name}': publishes {mine} on {topic}, but action '{other.name}' "
                                  f"({_place(other, a)}) publishes {theirs} there: one topic carries one message "
                                  f"type (ROS would send one action's messages as the other's type, garbage to "
                                  f"every subscriber); give one of them another topic or the same type",
                                  subject=a.name))
            continue
        same = next((e for e in earlier if e.priority == a.priority), None)
        if same is not None:
            out.append(Diagnostic(a.span, f"action '{a.name}': same priority ({a.priority}) as action "
                                          f"'{same.name}' ({_place(same, a)}), and both publish on {topic}; "
                                          f"which one publishes must not be left to chance: give one a higher "
                                          f"'priority'", subject=a.name))
            continue
        earlier.append(a)
    return out
