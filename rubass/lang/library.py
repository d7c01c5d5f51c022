"""Action libraries (LANGUAGE.md §8): YAML files validated key by key, errors with places."""
from __future__ import annotations

import dataclasses
import re
import weakref
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, Iterable, List, Optional, Tuple

import yaml

from .errors import Diagnostic, a_noun, did_you_mean
from .grammar import KEYWORDS
from .libtopics import topic_conflicts
from .source import Source, SourceSet, Span
from .stdlib import is_standard_library
from .topicnames import resolve as resolve_topic
from .units import FREQUENCY, SPEED, TIME, Dimension, dim, dimension_name, parse_quantity
from .yamltags import duplicate_keys, foreign_tags, plain_value, resolve_merges

BUILTIN_PLUGINS = ("publish", "serial", "service", "log", "limit")
CUSTOM_PLUGIN_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*:[A-Za-z_][A-Za-z0-9_]*")
MSG_TYPE_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*/[A-Za-z_][A-Za-z0-9_]*")
LOG_LEVELS = ("debug", "info", "warn", "error")
PHASES = ("start", "hold", "release")
ANGULAR_SPEED = dim(rad=1, s=-1)
LIMIT_AXES: Dict[str, Tuple[Dimension, str]] = {  # axis -> (dimension, its SI unit)
    **{f"linear_{a}": (SPEED, "m/s") for a in "xyz"},
    **{f"angular_{a}": (ANGULAR_SPEED, "rad/s") for a in "xyz"},
}
_UNITS_OF = {"m/s": "m/s, cm/s or km/h", "rad/s": "rad/s or deg/s"}
TWIST_TYPES = ("geometry_msgs/Twist", "geometry_msgs/TwistStamped")
TOPIC_PLUGINS = ("publish", "limit")  # plugins that publish on `topic`, arbitrated by priority


@dataclass(frozen=True)
class ActionDef:
    """One action of a library: its plugin and its validated, SI-normalised parameters."""

    name: str
    plugin: str
    params: Dict[str, Any] = field(compare=False)
    latch: bool = False
    span: Span = field(default=Span("<none>", 0, 0), compare=False)
    priority: int = 0  # among actions publishing on the same topic, the highest publishes (§16)
    plugin_span: Span = field(default=Span("<none>", 0, 0), compare=False)  # its `plugin:` value
    key_spans: Dict[str, Span] = field(default_factory=dict, compare=False)  # where each key's value is

    @property
    def is_custom(self) -> bool:
        return ":" in self.plugin


class _Node:
    """A composed YAML node with its place, converted to Python on demand."""

    def __init__(self, node: yaml.Node, file: str) -> None:
        self.node, self.file = node, file

    @property
    def span(self) -> Span:
        mark = self.node.start_mark
        return Span(self.file, mark.line + 1, mark.column + 1, mark.index, self.node.end_mark.index)

    def value(self) -> Any:
        return plain_value(self.node)


Checker = Callable[[_Node, str], Tuple[Any, Optional[str]]]


def _string(pattern: Optional["re.Pattern[str]"] = None, what: str = "a string") -> Checker:
    def check(n: _Node, key: str) -> Tuple[Any, Optional[str]]:
        v = n.value()
        if not isinstance(v, str) or (pattern is not None and not pattern.fullmatch(v)):
            return None, f"'{key}' must be {what}, got {v!r}"
        return v, None
    return check


def _choice(options: Tuple[str, ...]) -> Checker:
    def check(n: _Node, key: str) -> Tuple[Any, Optional[str]]:
        v = n.value()
        if v not in options:
            return None, f"'{key}' must be one of {', '.join(options)}, got {v!r}{did_you_mean(str(v), options)}"
        return v, None
    return check


def _phases(n: _Node, key: str) -> Tuple[Any, Optional[str]]:
    v = n.value()
    if isinstance(v, str):
        v = [v]
    if not isinstance(v, list) or not v or any(p not in PHASES for p in v):
        return None, f"'{key}' must be a list of {', '.join(PHASES)}, got {v!r}"
    return tuple(v), None


def _bool(n: _Node, key: str) -> Tuple[Any, Optional[str]]:
    v = n.value()
    if not isinstance(v, bool):
        return None, f"'{key}' must be true or false, got {v!r}"
    return v, None


def _int(n: _Node, key: str) -> Tuple[Any, Optional[str]]:
    v = n.value()
    if isinstance(v, bool) or not isinstance(v, int) or v <= 0:
        return None, f"'{key}' must be a positive integer, got {v!r}"
    return v, None


def _priority(n: _Node, key: str) -> Tuple[Any, Optional[str]]:
    v = n.value()
    if isinstance(v, bool) or not isinstance(v, int):
        return None, f"'{key}' must be an integer (higher wins on a shared topic), got {v!r}"
    return v, None


def _mapping(n: _Node, key: str) -> Tuple[Any, Optional[str]]:
    v = n.value()
    if v is None:
        return {}, None
    if not isinstance(v, dict):
        return None, f"'{key}' must be a mapping of message fields, got {v!r}"
    return v, None


def _quantity(d: Dimension, unit: str, example: str) -> Checker:
    def check(n: _Node, key: str) -> Tuple[Any, Optional[str]]:
        v = n.value()
        q = parse_quantity(str(v)) if isinstance(v, (int, float, str)) and not isinstance(v, bool) else None
        if q is None or (q[1] and q[1] != d) or q[0] <= 0:
            return None, f"'{key}' must be a positive {unit} such as '{example}', got {v!r}"
        return q[0], None
    return check


def _range(d: Dimension, unit: str) -> Checker:
    """[min, max] with units of dimension d (a bare 0 needs none); SI floats, min <= max."""
    units = _UNITS_OF[unit]
    what = a_noun(dimension_name(d))

    def check(n: _Node, key: str) -> Tuple[Any, Optional[str]]:
        v = n.value()
        if not isinstance(v, list) or len(v) != 2:
            return None, f"'{key}' must be a range [min, max] such as [-0.2 {unit}, 0.2 {unit}], got {v!r}"
        out = []
        for item in v:
            q = parse_quantity(item) if isinstance(item, str) else (
                (float(item), ()) if isinstance(item, (int, float)) and not isinstance(item, bool) else None)
            if q is None or q[0] != q[0]:
                return None, f"'{key}': {item!r} is not a quantity; write a number with a unit ({units})"
            if not q[1] and q[0] != 0:
                return None, f"'{key}': {item!r} needs a unit ({units}), such as '{item} {unit}'"
            if q[1] and q[1] != d:
                return None, f"'{key}' takes {what} ({units}), got {item!r} ({a_noun(dimension_name(q[1]))})"
            out.append(q[0])
        if out[0] > out[1]:
            return None, f"'{key}': min {v[0]!r} is greater than max {v[1]!r}"
        return (out[0], out[1]), None
    return check


_COMMON: Dict[str, Checker] = {"latch": _bool, "description": _string(), "priority": _priority}
_TOPIC = _string(re.compile(r"~?/?[A-Za-z_][\w/]*"), "a topic name")

# plugin -> {key: (checker, required, default)}
SCHEMAS: Dict[str, Dict[str, Tuple[Checker, bool, Any]]] = {
    "publish": {
        "topic": (_string(re.compile(r"~?/?[A-Za-z_][\w/]*"), "a topic name"), True, None),
        "type": (_string(MSG_TYPE_RE, "a message type 'package/Type'"), True, None),
        "message": (_mapping, False, {}),
        "on_release": (_mapping, False, None),
        "rate": (_quantity(FREQUENCY, "frequency", "20 Hz"), False, 10.0),
    },
    "serial": {
        "port": (_string(re.compile(r"\S+"), "a device path"), True, None),
        "baud": (_int, False, 115200),
        "on_start": (_string(), False, None),
        "on_hold": (_string(), False, None),
        "on_release": (_string(), False, None),
        "write_timeout": (_quantity(TIME, "time", "0.1 s"), False, 0.1),
    },
    "service": {
        "service": (_string(re.compile(r"~?/?[A-Za-z_][\w/]*"), "a service name"), True, None),
        "type": (_string(MSG_TYPE_RE, "a service type 'package/Type'"), True, None),
        "request": (_mapping, False, {}),
        "timeout": (_quantity(TIME, "time", "1 s"), False, 1.0),
        "call_on": (_phases, False, ("start",)),
    },
    "log": {
        "level": (_choice(LOG_LEVELS), False, "warn"),
        "message": (_string(), False, None),
    },
    "limit": {
        "input": (_TOPIC, True, None),
        "topic": (_TOPIC, True, None),
        "type": (_choice(TWIST_TYPES), False, TWIST_TYPES[0]),
        "timeout": (_quantity(TIME, "time", "0.5 s"), False, 0.5),
        "rate": (_quantity(FREQUENCY, "frequency", "20 Hz"), False, 20.0),
        **{axis: (_range(d, unit), False, None) for axis, (d, unit) in LIMIT_AXES.items()},
    },
}


def load_library(path: str, sources: SourceSet) -> Tuple[Dict[str, ActionDef], List[Diagnostic]]:
    """Read and validate one library file; returns its valid actions and every problem found.

    An action whose definition has errors is left out; its name is still in the diagnostics.
    """
    from .sourcefile import read_source

    src, diag = read_source(path, what="action library")
    if src is None:
        return {}, [diag] if diag else []
    sources.add(src)
    actions, diags = parse_library(src)
    earlier = _LOADED.setdefault(sources, [])
    clashes = _clashes(earlier, actions)
    kept = {k: a for k, a in actions.items() if k not in {d.subject for d in clashes}}
    earlier.extend(a for a in kept.values() if a not in earlier)
    return kept, diags + clashes


# the actions of the libraries already loaded in one run (one SourceSet), for conflicts across them
_LOADED: "weakref.WeakKeyDictionary[SourceSet, List[ActionDef]]" = weakref.WeakKeyDictionary()


def _clashes(earlier: List[ActionDef], actions: Dict[str, ActionDef]) -> List[Diagnostic]:
    """Topic conflicts (type, priority) of a library's actions with those of libraries loaded
    before it (an action of the same name is another error, which the checker reports)."""
    out = []
    for a in actions.values():
        others = [e for e in earlier if e.name != a.name and e.span.file != a.span.file]
        out += [d for d in topic_conflicts(others + [a]) if d.subject == a.name][:1]
    return out


def parse_library(src: Source) -> Tuple[Dict[str, ActionDef], List[Diagnostic]]:
    """Validate library text already read; positions point into src."""
    diags: List[Diagnostic] = []
    try:
        root = yaml.compose(src.text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        problem = getattr(exc, "problem", None) or str(exc)
        span = Span(src.name, mark.line + 1, mark.column + 1) if mark else Span(src.name, 1, 1)
        return {}, [Diagnostic(span, f"invalid YAML: {problem}")]
    except (ValueError, RecursionError) as exc:  # e.g. NUL bytes, absurd nesting
        return {}, [Diagnostic(Span(src.name, 1, 1), f"invalid YAML: {exc}")]
    top = Span(src.name, 1, 1)
    if not isinstance(root, yaml.MappingNode):
        return {}, [Diagnostic(top, "an action library must be a mapping with a key 'actions'")]
    foreign = foreign_tags(root)
    if foreign:
        return {}, [Diagnostic(_Node(n, src.name).span, f"YAML tag '{n.tag}' is not allowed: an action library "
                                                        f"holds plain data only (strings, numbers, booleans, "
                                                        f"lists, mappings)") for n in foreign]
    dups = duplicate_keys(root)  # before merging: a merged key is no duplicate
    try:
        bad_merges = resolve_merges(root)  # `<<: *base` shares keys between actions
    except RecursionError:
        return {}, [Diagnostic(top, "YAML merge keys ('<<') are nested too deeply")]
    if bad_merges:
        return {}, [Diagnostic(_Node(n, src.name).span, "a merge key '<<' takes a mapping (such as '*base') or a "
                                                        "list of them") for n in bad_merges]
    entries = {_key(k): (k, v) for k, v in root.value}
    if "actions" not in entries:
        return {}, [Diagnostic(top, "an action library needs a top-level key 'actions'")]
    for key, (knode, _) in entries.items():
        if key != "actions":
            diags.append(Diagnostic(_Node(knode, src.name).span,
                                    f"unknown top-level key '{key}' (expected 'actions')"))
    actions_node = entries["actions"][1]
    if not isinstance(actions_node, yaml.MappingNode):
        return {}, diags + [Diagnostic(_Node(actions_node, src.name).span,
                                       "'actions' must be a mapping from action names to definitions")]
    broken = _duplicates(dups, actions_node, src.name, diags)
    out: Dict[str, ActionDef] = {}
    for knode, vnode in actions_node.value:
        name, kspan = _key(knode), _Node(knode, src.name).span
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name) or name in KEYWORDS:
            diags.append(Diagnostic(kspan, f"'{name}' is not a valid action name (a RuBaSS identifier)"))
            continue
        if name in out:
            diags.append(Diagnostic(kspan, f"action '{name}' is defined twice in this library"))
            continue
        action, problems = _action(name, kspan, _Node(vnode, src.name), src.name)
        diags.extend(dataclasses.replace(d, subject=name) for d in problems)
        if action is not None and id(vnode) not in broken:
            out[name] = action
    conflicts = priority_conflicts(out.values())
    bad = {d.subject for d in conflicts}
    return {k: v for k, v in out.items() if k not in bad}, diags + conflicts


def _duplicates(dups: List[Tuple[yaml.Node, yaml.Node, yaml.Node]], actions_node: yaml.MappingNode, file: str,
                diags: List[Diagnostic]) -> set:
    """An error at each key written twice in one mapping (YAML would keep the last silently);
    the ids of the action definitions that hold one, which are left out. Action names written
    twice are reported by the caller."""
    broken = set()
    for mapping, second, first in dups:
        if mapping is actions_node:
            continue
        owner = next(((k, v) for k, v in actions_node.value
                      if v.start_mark.index <= second.start_mark.index < v.end_mark.index), None)
        name = _key(owner[0]) if owner else ""
        where = f"action '{name}': " if owner else ""
        if owner:
            broken.add(id(owner[1]))
        diags.append(Diagnostic(_Node(second, file).span, f"{where}key '{_key(second)}' is written twice in one "
                                                          f"mapping (first at {first.start_mark.line + 1}:{first.start_mark.column + 1}); "
                                                          f"YAML would keep only the last: remove one",
                                subject=name))
    return broken


def _key(node: yaml.Node) -> str:
    return str(node.value) if isinstance(node, yaml.ScalarNode) else "<complex key>"


def _action(name: str, span: Span, node: _Node, file: str) -> Tuple[Optional[ActionDef], List[Diagnostic]]:
    where = f"action '{name}'"
    if not isinstance(node.node, yaml.MappingNode):
        return None, [Diagnostic(node.span, f"{where}: its definition must be a mapping with a 'plugin' key")]
    fields = {_key(k): (_Node(k, file), _Node(v, file)) for k, v in node.node.value}
    if "plugin" not in fields:
        return None, [Diagnostic(span, f"{where}: missing key 'plugin' (one of {', '.join(BUILTIN_PLUGINS)}, "
                                       "or 'package.module:Class')")]
    pnode = fields["plugin"][1]
    plugin = pnode.value()
    if not isinstance(plugin, str) or (plugin not in BUILTIN_PLUGINS and not CUSTOM_PLUGIN_RE.fullmatch(plugin)):
        hint = did_you_mean(str(plugin), BUILTIN_PLUGINS)
        return None, [Diagnostic(pnode.span, f"{where}: unknown plugin {plugin!r} (built-ins: "
                                             f"{', '.join(BUILTIN_PLUGINS)}; custom: 'package.module:Class'){hint}")]
    if ":" in plugin and is_standard_library(plugin.partition(":")[0]):
        # as the monitor refuses it (actions/base.py), before anything is imported
        return None, [Diagnostic(pnode.span, f"{where}: plugin module '{plugin.partition(':')[0]}' is part of "
                                             f"Python's standard library; a custom plugin must be a class in the "
                                             f"robot's own package")]
    diags: List[Diagnostic] = []
    params: Dict[str, Any] = {}
    schema = SCHEMAS.get(plugin, {})
    for key, (knode, vnode) in fields.items():
        if key == "plugin":
            continue
        checker = _COMMON.get(key) or (schema[key][0] if key in schema else None)
        if checker is None:
            if ":" in plugin:  # a custom plugin takes any parameters
                params[key] = vnode.value()
                continue
            known = list(schema) + list(_COMMON)
            diags.append(Diagnostic(knode.span, f"{where}: unknown key '{key}' for plugin '{plugin}'"
                                                f"{did_you_mean(key, known)}"))
            continue
        value, problem = checker(vnode, key)
        if problem:
            diags.append(Diagnostic(vnode.span, f"{where}: {problem}"))
        else:
            params[key] = value
    for key, (_, required, default) in schema.items():
        if key not in fields:
            if required:
                diags.append(Diagnostic(span, f"{where}: missing key '{key}' (plugin '{plugin}' needs it)"))
            else:
                params[key] = default
    if plugin == "serial" and not any(params.get(k) for k in ("on_start", "on_hold", "on_release")):
        diags.append(Diagnostic(span, f"{where}: a serial action needs at least one of on_start, on_hold, on_release"))
    if plugin == "limit" and not diags:
        diags += _limit_problems(where, span, params, fields)
    if diags:
        return None, diags
    latch = bool(params.pop("latch", False))
    priority = int(params.pop("priority", 0))
    spans = {k: vnode.span for k, (_, vnode) in fields.items()}
    return ActionDef(name, plugin, params, latch, span, priority, pnode.span, spans), []


def _limit_problems(where: str, span: Span, params: Dict[str, Any], fields: Dict[str, Any]) -> List[Diagnostic]:
    out = []
    if not any(params.get(axis) for axis in LIMIT_AXES):
        out.append(Diagnostic(span, f"{where}: a limit action needs at least one axis range "
                                    f"({', '.join(LIMIT_AXES)}), such as 'linear_x: [-0.1 m/s, 0.2 m/s]'"))
    if resolve_topic(params["input"]) == resolve_topic(params["topic"]):  # spellings of one topic too
        out.append(Diagnostic(fields["topic"][1].span, f"{where}: 'topic' must differ from 'input' "
                                                       f"({params['input']}): it would filter its own output"))
    return out


def priority_conflicts(actions: Iterable[ActionDef], resolve: Callable[[str], str] = resolve_topic) -> List[Diagnostic]:
    """Actions on one topic (§16) with different message types or the same priority: one error
    each after the first in file order, at its place (libtopics.topic_conflicts). `resolve` maps
    topic names (the monitor resolves them as its node; by default as a node at the root)."""
    return topic_conflicts(sorted(actions, key=lambda a: (a.span.file, a.span.line, a.span.col, a.name)), resolve)
