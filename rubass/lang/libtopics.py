"""Actions that publish on one topic (LANGUAGE.md §16): they must agree on its message type
(ROS keeps one publisher per topic in a process, of the first action's type: a second type's
messages would go out as the first's, garbage on the wire), and differ in priority. They must
not publish on the monitor's own topics, nor feed a limit's input (a loop), nor, at a reload,
change the type of a topic the running monitor publishes."""
from __future__ import annotations

from typing import TYPE_CHECKING, Callable, Dict, Iterable, List, Optional, Tuple

from .errors import Diagnostic
from .source import Span
from .topicnames import resolve as resolve_topic

if TYPE_CHECKING:
    from .library import ActionDef

# plugin -> (the key of the topic it publishes on, the key of its message type)
PUBLISHERS: Dict[str, Tuple[str, str]] = {"publish": ("topic", "type"), "limit": ("topic", "type")}

# The monitor's own topics, as its node names them (rubass/ros/outputs.py, agentbook.py; rospy's
# log): what each carries. An action there would feed a watchdog or a status reader with its own
# messages, of another type garbage (a heartbeat stamped 2027).
MONITOR_TOPICS: Dict[str, str] = {
    "/diagnostics": "its status (diagnostic_msgs/DiagnosticArray)",
    "/rosout": "the log of every node (rosgraph_msgs/Log)",
    "~events": "its behaviour events (std_msgs/String, JSON)",
    "~heartbeat": "its heartbeat (std_msgs/Header), which a hardware watchdog may be fed",
    "~node_samples": "its node samples (std_msgs/String, JSON)",
    "/rubass/agent_samples": "the agents' reports it reads (std_msgs/String, JSON)",
}


def _place(first: "ActionDef", a: "ActionDef") -> str:
    return f"line {first.span.line}" if first.span.file == a.span.file else str(first.span)


def key_span(a: "ActionDef", *keys: str) -> Span:
    """Where the first of these keys' values is written in the action's YAML (else the action's name)."""
    for key in keys:
        span = a.key_spans.get(key)
        if span is not None:
            return span
    return a.span


def _type(a: "ActionDef") -> str:
    return str(a.params[PUBLISHERS[a.plugin][1]])


def own_topic(a: "ActionDef", resolve: Callable[[str], str] = resolve_topic) -> Optional[Diagnostic]:
    """An error for an action that publishes on (or a limit that reads) one of the monitor's own
    topics, names resolved by `resolve` (the monitor's own at start and reload)."""
    own = {resolve(name): (name, what) for name, what in MONITOR_TOPICS.items()}
    keys = PUBLISHERS.get(a.plugin)
    if keys is None:
        return None
    for key in (keys[0], "input") if a.plugin == "limit" else (keys[0],):
        written = str(a.params[key])
        topic = resolve(written)
        if topic not in own:
            continue
        name, what = own[topic]
        spelt = f" ({name})" if name != topic else ""
        if written.startswith("~"):  # said as written: `rubass check` does not know the monitor's name
            topic, spelt = written, ""
        doing = f"reads its input from {topic}" if key == "input" else f"publishes {_type(a)} on {topic}"
        return Diagnostic(key_span(a, key), f"action '{a.name}': {doing}, the monitor's own topic{spelt}: "
                                            f"{what}; an action must not use the monitor's topics "
                                            f"({', '.join(MONITOR_TOPICS)}): give it another topic",
                          subject=a.name)
    return None


def _loop(a: "ActionDef", topic: str, source: Optional[str], outputs: Dict[str, List["ActionDef"]],
          inputs: Dict[str, List["ActionDef"]]) -> Optional[Diagnostic]:
    """An error when a limit's input is another action's output, either way round (a limit fed by
    an action's output filters rubass's own commands; two such limits loop forever)."""
    if source is not None and outputs.get(source):
        other = outputs[source][0]
        return Diagnostic(key_span(a, "input"), f"action '{a.name}': its input {source} is where action "
                                                f"'{other.name}' ({_place(other, a)}) publishes: a limit must read "
                                                f"the robot's own commands (the planner's topic), not an action's "
                                                f"output (limits feeding each other loop forever)", subject=a.name)
    if inputs.get(topic):
        other = inputs[topic][0]
        return Diagnostic(key_span(a, "topic"), f"action '{a.name}': publishes on {topic}, the input of limit "
                                                f"'{other.name}' ({_place(other, a)}): a limit must read the robot's "
                                                f"own commands (the planner's topic), not an action's output (limits "
                                                f"feeding each other loop forever)", subject=a.name)
    return None


def topic_conflicts(actions: Iterable["ActionDef"], resolve: Callable[[str], str] = resolve_topic) -> List[Diagnostic]:
    """One error for each action, in the given order, that publishes on a topic an earlier one
    publishes on with another message type, or with the same priority; that publishes on the
    monitor's own topics; or whose output is an earlier limit's input (or whose input, as a limit,
    an earlier action's output). Each names its action (`subject`); topic names are compared
    resolved (`cmd_vel` is `/cmd_vel` at the root)."""
    by_topic: Dict[str, List["ActionDef"]] = {}
    inputs: Dict[str, List["ActionDef"]] = {}  # limits by their resolved input
    out: List[Diagnostic] = []
    for a in actions:
        keys = PUBLISHERS.get(a.plugin)
        if keys is None:
            continue
        topic = resolve(str(a.params[keys[0]]))
        source = resolve(str(a.params["input"])) if a.plugin == "limit" else None
        wrong = own_topic(a, resolve) or _loop(a, topic, source, by_topic, inputs)
        if wrong is not None:
            out.append(wrong)
            continue
        earlier = by_topic.setdefault(topic, [])
        mine = _type(a)
        other = next((e for e in earlier if _type(e) != mine), None)
        if other is not None:
            out.append(Diagnostic(key_span(a, keys[1], keys[0]),
                                  f"action '{a.name}': publishes {mine} on {topic}, but action '{other.name}' "
                                  f"({_place(other, a)}) publishes {_type(other)} there: one topic carries one message "
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
        if source is not None:
            inputs.setdefault(source, []).append(a)
    return out


def running_type_changes(running: Iterable["ActionDef"], new: Iterable["ActionDef"],
                         resolve: Callable[[str], str] = resolve_topic) -> List[Diagnostic]:
    """Errors for a reload: each new action that publishes on a topic the running monitor publishes
    on with another message type. One process keeps one publisher per topic, and the old one is
    still registered while the new actions are built: the new messages would go out as the old
    type (garbage), so such a change needs a restart."""
    live: Dict[str, "ActionDef"] = {}
    for r in running:
        if r.plugin in PUBLISHERS:
            live.setdefault(resolve(str(r.params[PUBLISHERS[r.plugin][0]])), r)
    out: List[Diagnostic] = []
    for a in new:
        keys = PUBLISHERS.get(a.plugin)
        if keys is None:
            continue
        topic = resolve(str(a.params[keys[0]]))
        old = live.get(topic)
        if old is None or _type(old) == _type(a):
            continue
        out.append(Diagnostic(key_span(a, keys[1], keys[0]),
                              f"action '{a.name}': publishes {_type(a)} on {topic}, but the running monitor publishes "
                              f"{_type(old)} there (action '{old.name}', {old.span}): a ROS node keeps one publisher "
                              f"per topic, of its first type, so these messages would go out as {_type(old)}, garbage "
                              f"to every subscriber; restart the monitor to change the type of {topic} (or give the "
                              f"action another topic)", subject=a.name))
    return out
