"""Action libraries checked against message and service definitions: every publish type and
service type exists, and every field of `message:`, `on_release:` and `request:` exists with a
value of a fitting type. Errors point at the YAML file and line."""
from __future__ import annotations

import struct
from typing import Any, Callable, Dict, Iterable, List, Optional, Set, Tuple

import yaml

from .errors import Diagnostic, a_noun, did_you_mean
from .library import TWIST_TYPES, ActionDef
from .msgdef import INTEGERS, FieldDef, MsgSpec, Registry
from .source import SourceSet, Span
from .yamltags import plain_value

_FLOATS = ("float32", "float64")
_MERGE = "tag:yaml.org,2002:merge"
# what genpy serialises: a time's secs and nsecs are uint32, a duration's int32; a whole number of
# nanoseconds becomes those (a time's must not be negative)
_TIME_PARTS = {"time": "uint32", "duration": "int32"}
_TIME_NS = {"time": (0, 4294967295 * 10 ** 9), "duration": (-2147483648 * 10 ** 9, 2147483647 * 10 ** 9)}


def _span(node: yaml.Node, file: str) -> Span:
    m = node.start_mark
    return Span(file, m.line + 1, m.column + 1, m.index, node.end_mark.index)


def _entries(node: Optional[yaml.Node], seen: Optional[Set[int]] = None) -> Dict[str, Tuple[yaml.Node, yaml.Node]]:
    """A mapping's keys -> (key node, value node), with what it takes from others by merge keys
    (`<<: *base`, as the library's loader does: its own keys win, then the first merged)."""
    if not isinstance(node, yaml.MappingNode):
        return {}
    seen = (seen or set()) | {id(node)}
    own: Dict[str, Tuple[yaml.Node, yaml.Node]] = {}
    merged: Dict[str, Tuple[yaml.Node, yaml.Node]] = {}
    for k, v in node.value:
        if not isinstance(k, yaml.ScalarNode):
            continue
        if k.tag == _MERGE:
            for m in (v.value if isinstance(v, yaml.SequenceNode) else [v]):
                if id(m) not in seen:
                    for key, pair in _entries(m, seen).items():
                        merged.setdefault(key, pair)
        else:
            own[str(k.value)] = (k, v)
    return {**merged, **own}


def _action_nodes(sources: SourceSet, act: ActionDef) -> Dict[str, Tuple[yaml.Node, yaml.Node]]:
    """The YAML key/value nodes of one action's definition ({} when the text is not at hand)."""
    src = sources.get(act.span.file)
    if src is None:
        return {}
    try:
        root = yaml.compose(src.text, Loader=yaml.SafeLoader)
    except (yaml.YAMLError, ValueError, RecursionError):
        return {}
    actions = _entries(root).get("actions")
    entry = _entries(actions[1] if actions else None).get(act.name)
    return _entries(entry[1] if entry else None)


class _FieldChecker:
    def __init__(self, registry: Registry, file: str, action: str) -> None:
        self.registry, self.file, self.action = registry, file, action
        self.diags: List[Diagnostic] = []

    def error(self, node: yaml.Node, msg: str) -> None:
        self.diags.append(Diagnostic(_span(node, self.file), f"action '{self.action}': {msg}"))

    def message(self, spec: MsgSpec, node: yaml.Node, where: str) -> None:
        if isinstance(node, yaml.ScalarNode) and node.tag.endswith(":null"):
            return
        if isinstance(node, yaml.SequenceNode):  # genpy fills a message from positional values too
            if len(node.value) != len(spec.fields):
                self.error(node, f"'{where}' lists {len(node.value)} values, {spec.type} has {len(spec.fields)} "
                                 f"fields ({', '.join(spec.names)})")
                return
            for f, v in zip(spec.fields, node.value):
                self.field(f, v, f"{where}.{f.name}")
            return
        if not isinstance(node, yaml.MappingNode):
            self.error(node, f"'{where}' must be a mapping of {spec.type} fields ({', '.join(spec.names)})")
            return
        for key, (knode, vnode) in _entries(node).items():
            f = spec.get(key)
            path = f"{where}.{key}"
            if f is None:
                self.error(knode, f"{spec.type} has no field '{key}'{did_you_mean(key, spec.names)} "
                                  f"(its fields: {', '.join(spec.names) or 'none'})")
                continue
            self.field(f, vnode, path)

    def field(self, f: FieldDef, node: yaml.Node, where: str) -> None:
        if f.is_array:
            if f.type in ("uint8", "char") and isinstance(node, yaml.ScalarNode) and node.tag.endswith(":str"):
                return  # bytes given as a string
            if not isinstance(node, yaml.SequenceNode):
                self.error(node, f"'{where}' is an array ({f.type}[]): give a list, got {_show(node)}")
                return
            if f.length is not None and len(node.value) != f.length:
                self.error(node, f"'{where}' is {a_noun(f'{f.type}[{f.length}]')}: give exactly {f.length} values, "
                                 f"got {len(node.value)}")
            for i, v in enumerate(node.value):
                self.field(FieldDef(f.name, f.type), v, f"{where}[{i}]")
            return
        if not f.is_primitive:
            spec = self.registry.get(f.type)
            if spec is not None:
                self.message(spec, node, where)
            return
        if f.type in ("time", "duration") and isinstance(node, yaml.MappingNode):
            part = _TIME_PARTS[f.type]
            for key, (knode, vnode) in _entries(node).items():
                if key not in ("secs", "nsecs"):
                    self.error(knode, f"'{where}' is {a_noun(f.type)}: its fields are secs and nsecs, not '{key}'")
                elif _primitive_problem(part, _scalar(vnode)):
                    lo, hi = INTEGERS[part]
                    self.error(vnode, f"'{where}.{key}' is {a_noun(part)}: give a whole number from {lo} to {hi}, "
                                      f"got {_show(vnode)}")
            return
        value = _scalar(node)
        problem = _primitive_problem(f.type, value)
        if problem:
            self.error(node, f"'{where}' is {a_noun(f.type)}: {problem}, got {_show(node)}")


_NOT_SCALAR = object()


def _scalar(node: yaml.Node) -> Any:
    if not isinstance(node, yaml.ScalarNode):
        return _NOT_SCALAR
    return plain_value(node)


def _show(node: yaml.Node) -> str:
    if isinstance(node, yaml.MappingNode):
        return "a mapping"
    if isinstance(node, yaml.SequenceNode):
        return "a list"
    return repr(_scalar(node))


def _primitive_problem(ftype: str, v: Any) -> Optional[str]:
    if ftype in ("time", "duration"):
        if isinstance(v, bool) or not isinstance(v, int):
            return "give {secs: S, nsecs: N} or a whole number of nanoseconds"
        lo, hi = _TIME_NS[ftype]
        return None if lo <= v <= hi else f"a whole number of nanoseconds must be from {lo} to {hi}"
    if ftype == "bool":
        return None if isinstance(v, bool) or v in (0, 1) and isinstance(v, int) else "give true or false"
    if ftype == "string":
        return None if isinstance(v, str) else "give a string (quote it)"
    if ftype in _FLOATS:
        if isinstance(v, float) and v != v:  # .nan: a stop command of NaN is no command a base can follow
            return "a command must be a number (NaN is not one)"
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            return "give a number"
        try:
            struct.pack("<f" if ftype == "float32" else "<d", v)
        except (OverflowError, struct.error):
            return f"too large for a {ftype} (at most {3.4028234663852886e38 if ftype == 'float32' else 1.7976931348623157e308:.8g})"
        return None
    lo, hi = INTEGERS[ftype]
    if isinstance(v, bool) or not isinstance(v, int):
        return f"give a whole number from {lo} to {hi}"
    return None if lo <= v <= hi else f"the value must be from {lo} to {hi}"


SERIAL_TEXT = ("on_start", "on_hold", "on_release")


def serial_text_problem(text: str) -> Optional[str]:
    """Why a serial action's text cannot be sent as it is written (None when it can): it goes out as
    Latin-1, one byte per character, so a character above U+00FF has no byte."""
    bad = next((c for c in text if ord(c) > 0xFF), None)
    if bad is None:
        return None
    return (f"{bad!r} (U+{ord(bad):04X}) cannot be sent: serial text is sent as Latin-1, one byte per "
            f"character (\\x00 to \\xff); write the bytes the board expects as \\xNN escapes")


def _serial_text(act: ActionDef, sources: SourceSet) -> List[Diagnostic]:
    """Errors at the YAML value of each on_start/on_hold/on_release that has a character with no byte."""
    out: List[Diagnostic] = []
    nodes = _action_nodes(sources, act)
    for key in SERIAL_TEXT:
        text = act.params.get(key)
        problem = serial_text_problem(text) if isinstance(text, str) else None
        if problem:
            node = nodes.get(key, (None, None))[1]
            span = _span(node, act.span.file) if node is not None else act.key_spans.get(key, act.span)
            out.append(Diagnostic(span, f"action '{act.name}': '{key}': {problem}"))
    return out


def check_library_types(actions: Dict[str, ActionDef], sources: SourceSet, registry: Registry,
                        looked_in: str = "installed packages", known: Iterable[str] = (),
                        known_services: Iterable[str] = ()) -> List[Diagnostic]:
    """Errors for publish and service actions whose types or fields do not fit the definitions.

    `looked_in` says where types were looked for, for the message of an unknown type; `known`
    and `known_services` are more names to suggest from (those installed in its package)."""
    diags: List[Diagnostic] = []
    known, known_services = list(known), list(known_services)
    for act in sorted(actions.values(), key=lambda a: (a.span.file, a.span.line)):
        if act.plugin == "serial":
            diags.extend(_serial_text(act, sources))
        if act.plugin not in ("publish", "service"):
            continue
        nodes = _action_nodes(sources, act)
        tnode = nodes.get("type", (None, None))[1]
        type_span = _span(tnode, act.span.file) if tnode is not None else act.span
        c = _FieldChecker(registry, act.span.file, act.name)
        type_name = str(act.params.get("type"))
        if act.plugin == "publish":
            spec = registry.get(type_name)
            if spec is None:
                diags.append(Diagnostic(type_span, f"action '{act.name}': unknown message type '{type_name}' "
                                                   f"(not in {looked_in}){did_you_mean(type_name, list(registry.types) + known)}"))
                continue
            for key in ("message", "on_release"):
                if key in nodes:
                    c.message(spec, nodes[key][1], key)
        else:
            srv = registry.services.get(type_name)
            if srv is None:
                diags.append(Diagnostic(type_span, f"action '{act.name}': unknown service type '{type_name}' "
                                                   f"(not in {looked_in}){did_you_mean(type_name, list(registry.services) + known_services)}"))
                continue
            if "request" in nodes:
                c.message(srv[0], nodes["request"][1], "request")
        diags.extend(c.diags)
    return diags


def library_types(actions: Dict[str, ActionDef]) -> Tuple[List[str], List[str]]:
    """(message types, service types) the publish and service actions name."""
    msgs = sorted({str(a.params.get("type")) for a in actions.values() if a.plugin == "publish"})
    srvs = sorted({str(a.params.get("type")) for a in actions.values() if a.plugin == "service"})
    return msgs, srvs


def check_publish_topics(actions: Dict[str, ActionDef], sources: SourceSet, topics: Dict[str, str],
                         source: str) -> List[Diagnostic]:
    """Errors for actions whose topics carry another type in the system model: a publish
    action's or a limit's output (the robot's subscribers would refuse the connection and the
    message would never arrive), and a limit's input (it would refuse every command)."""
    diags: List[Diagnostic] = []
    for act in sorted(actions.values(), key=lambda a: (a.span.file, a.span.line)):
        if act.plugin not in ("publish", "limit"):
            continue
        want = str(act.params.get("type"))
        for key in ("input", "topic") if act.plugin == "limit" else ("topic",):
            name = str(act.params.get(key, ""))
            if name.startswith("~"):
                continue  # private to the monitor: resolved under its own name
            topic = "/" + name.strip("/")
            have = topics.get(topic)
            if have is None or have == want:
                continue
            if act.plugin == "publish":
                node = _action_nodes(sources, act).get("type", (None, None))[1]
                span = _span(node, act.span.file) if node is not None else act.span
                text = f"publishes {want} on {topic}, which carries {have} in {source}: its subscribers would " \
                       f"refuse the connection"
            else:
                span = act.key_spans.get(key, act.span)
                said = "as its 'type' says" if "type" in act.key_spans else "its default type"
                text = (f"its {key} {topic} carries {have} in {source}, but the limit "
                        f"{'reads' if key == 'input' else 'publishes'} {want} ({said}): "
                        + ("it would refuse every command" if key == "input" else
                           "the robot's subscribers would refuse the connection")
                        + (f"; set 'type: {have}'" if have in TWIST_TYPES else ""))
            diags.append(Diagnostic(span, f"action '{act.name}': {text}"))
    return diags


# Built-in plugins whose phases read a call's arguments (Context.args): a log action's text. A
# custom plugin gets them as ctx.args; every other built-in plugin ignores them.
ARGUMENT_PLUGINS = ("log",)


def argument_problem(action: ActionDef, nargs: int, span: Span) -> Optional[Diagnostic]:
    """An error for a call with arguments (`crawl(0.05 m/s);`) of an action whose plugin ignores
    them: the robot would do what the library says, not what the call seems to ask."""
    if not nargs or action.is_custom or action.plugin in ARGUMENT_PLUGINS:
        return None
    return Diagnostic(span, f"action '{action.name}' takes no arguments: its plugin '{action.plugin}' ignores them "
                            f"(it does what its library entry says, {action.span}); only log actions (the text of "
                            f"their line) and custom plugins (ctx.args) use arguments: write '{action.name};', or "
                            f"change the library")


def plugin_module_warnings(actions: Dict[str, ActionDef], found: Callable[[str], bool]) -> List[Diagnostic]:
    """A warning at the `plugin:` value of each custom plugin whose top-level package `found` does not find
    (it looks the name up, it runs none of it): the monitor imports the module when it starts and refuses
    to start if it cannot. Only a warning: the robot's package may be on the robot's Python path only."""
    diags: List[Diagnostic] = []
    for act in sorted(actions.values(), key=lambda a: (a.span.file, a.span.line)):
        if not act.is_custom:
            continue
        module = act.plugin.partition(":")[0]
        top = module.split(".")[0]
        if found(top):
            continue
        span = act.plugin_span if act.plugin_span.line > 0 else act.span
        diags.append(Diagnostic(span, f"action '{act.name}': plugin module '{module}' cannot be found here "
                                      f"(no package or module '{top}' on this Python's path): the monitor will "
                                      f"refuse to start unless it can import it there (on the robot, with its "
                                      f"package on the Python path: its workspace's setup.bash sourced)",
                                "warning", subject=act.name))
    return diags
