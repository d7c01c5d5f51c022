"""The YAML system model file (docs/model.md): read with every error at its line, and written."""
from __future__ import annotations

import re
from typing import Any, Dict, List, Optional, Tuple

import yaml

from .errors import Diagnostic, did_you_mean
from .modelcheck import definition_problems, duplicates, unit_path_problem, version_problem
from .msgdef import TYPE_RE, DefinitionError, parse_msg
from .source import Source, SourceSet, Span
from .sysmodel import SystemModel
from .units import DIMENSIONLESS, UNITS, Dimension, unit_suggestion
from .yamltags import PLAIN_TAGS, foreign_tags, plain_value

KEYS = ("rubass_model", "source", "topics", "nodes", "units", "definitions")
TOPIC_RE = re.compile(r"/?[A-Za-z_][A-Za-z0-9_]*(?:/[A-Za-z_][A-Za-z0-9_]*)*/?")


def _span(node: yaml.Node, file: str) -> Span:
    m = node.start_mark
    return Span(file, m.line + 1, m.column + 1, m.index, node.end_mark.index)


def _plain(node: yaml.Node) -> Any:
    return plain_value(node)


class _Reader:
    def __init__(self, file: str) -> None:
        self.file = file
        self.diags: List[Diagnostic] = []
        self.unit_keys: List[Tuple[str, str, str, yaml.Node]] = []  # ('topic'/'type', its name, path, key)

    def error(self, node: yaml.Node, msg: str) -> None:
        self.diags.append(Diagnostic(_span(node, self.file), msg))

    def mapping(self, node: yaml.Node, what: str) -> List[Tuple[str, yaml.Node, yaml.Node]]:
        if isinstance(node, yaml.ScalarNode) and node.value in ("", "~", "null"):
            return []
        if not isinstance(node, yaml.MappingNode):
            self.error(node, f"{what} must be a mapping")
            return []
        return [(str(k.value) if isinstance(k, yaml.ScalarNode) else "?", k, v) for k, v in node.value]

    def string(self, node: yaml.Node, what: str) -> Optional[str]:
        if not isinstance(node, yaml.ScalarNode) or not isinstance(_plain(node), str):
            self.error(node, f"{what} must be a string")
            return None
        return str(node.value)

    def msg_type(self, node: yaml.Node, what: str) -> Optional[str]:
        text = self.string(node, what)
        if text is not None and not TYPE_RE.fullmatch(text):
            self.error(node, f"{what} must be a message type 'package/Type', got {text!r}")
            return None
        return text

    def units(self, node: yaml.Node, what: str, owner: Tuple[str, str] = ("", "")) -> Dict[str, Dimension]:
        out: Dict[str, Dimension] = {}
        for path, knode, vnode in self.mapping(node, what):
            self.unit_keys.append((owner[0], owner[1], path, knode))
            unit = self.string(vnode, f"the unit of '{path}'")
            if unit is None:
                continue
            if unit == "1":  # a plain number: a ratio, a count
                out[path] = DIMENSIONLESS
                continue
            if unit not in UNITS or UNITS[unit][0] != 1.0:
                si = [u for u, (f, _) in UNITS.items() if f == 1.0] + ["1"]
                hint = unit_suggestion(unit) if unit not in UNITS else ""  # 'km/h' is known, just not SI
                self.error(vnode, f"'{unit}' is not an SI unit rubass knows (ROS messages are SI): one of "
                                  f"{', '.join(si)}{hint}")
                continue
            out[path] = UNITS[unit][1]
        return out


def parse_model(src: Source) -> Tuple[Optional[SystemModel], List[Diagnostic]]:
    """A system model from model file text; None and the errors when it has any."""
    try:
        root = yaml.compose(src.text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        span = Span(src.name, mark.line + 1, mark.column + 1) if mark else Span(src.name, 1, 1)
        return None, [Diagnostic(span, f"invalid YAML: {getattr(exc, 'problem', None) or exc}")]
    except (ValueError, RecursionError) as exc:
        return None, [Diagnostic(Span(src.name, 1, 1), f"invalid YAML: {exc}")]
    r = _Reader(src.name)
    if not isinstance(root, yaml.MappingNode):
        return None, [Diagnostic(Span(src.name, 1, 1), "a system model must be a mapping with a key 'topics'")]
    foreign = foreign_tags(root, PLAIN_TAGS)
    if foreign:
        return None, [Diagnostic(_span(n, src.name), f"YAML tag '{n.tag}' is not allowed: a system model holds "
                                                     "plain data only") for n in foreign]
    for key, why in duplicates(root):
        r.error(key, why)
    entries = {k: (kn, v) for k, kn, v in r.mapping(root, "a system model")}
    if "rubass_model" in entries:
        problem = version_problem(_plain(entries["rubass_model"][1]))
        if problem:
            r.error(entries["rubass_model"][1], problem)
    for key, (knode, _) in entries.items():
        if key not in KEYS:
            r.error(knode, f"unknown key '{key}'{did_you_mean(key, KEYS)} (keys: {', '.join(KEYS)})")
    if "topics" not in entries:
        r.diags.append(Diagnostic(Span(src.name, 1, 1), "a system model needs a key 'topics'"))
    topics: Dict[str, str] = {}
    topic_units: Dict[str, Dict[str, Dimension]] = {}
    for name, knode, vnode in r.mapping(entries["topics"][1], "'topics'") if "topics" in entries else []:
        if not TOPIC_RE.fullmatch(name):
            r.error(knode, f"'{name}' is not a topic name")
            continue
        if isinstance(vnode, yaml.MappingNode):
            fields = {k: v for k, _, v in r.mapping(vnode, f"topic '{name}'")}
            for k, kn, _ in r.mapping(vnode, f"topic '{name}'"):
                if k not in ("type", "units"):
                    r.error(kn, f"topic '{name}': unknown key '{k}' (keys: type, units)")
            if "type" not in fields:
                r.error(vnode, f"topic '{name}' needs a 'type'")
                continue
            ty = r.msg_type(fields["type"], f"the type of topic '{name}'")
            if "units" in fields:
                topic_units[name] = r.units(fields["units"], f"the units of topic '{name}'", ("topic", name))
        else:
            ty = r.msg_type(vnode, f"the type of topic '{name}'")
        if ty is not None:
            topics[name] = ty
    nodes: Optional[List[str]] = None
    if "nodes" in entries:
        node_list = entries["nodes"][1]
        value = _plain(node_list)
        if not isinstance(value, list) or not all(isinstance(n, str) for n in value):
            r.error(node_list, "'nodes' must be a list of node names")
        else:
            bad = [(i, n) for i, n in enumerate(value) if not TOPIC_RE.fullmatch(n)]  # graph names, as topics
            for i, n in bad:
                r.error(node_list.value[i] if isinstance(node_list, yaml.SequenceNode) else node_list,
                        f"'{n}' is not a node name")
            nodes = [n for n in value if TOPIC_RE.fullmatch(n)]
    units = {}
    for ty, knode, vnode in r.mapping(entries["units"][1], "'units'") if "units" in entries else []:
        if TYPE_RE.fullmatch(ty) is None:
            r.error(knode, f"'units' are given per message type 'package/Type', got {ty!r}")
            continue
        units[ty] = r.units(vnode, f"the units of {ty}", ("type", ty))
    model = SystemModel(topics, nodes, units=units, topic_units=topic_units,
                        source=f"the system model {src.name}")
    definitions = r.mapping(entries["definitions"][1], "'definitions'") if "definitions" in entries else []
    for ty, knode, vnode in definitions:
        text = r.string(vnode, f"the definition of {ty}")
        if text is None:
            continue
        problems = definition_problems(ty, text, [t for t, _, _ in definitions])
        try:
            spec = parse_msg(ty, text)
        except DefinitionError as exc:
            problems = problems or [(exc.line, str(exc))]
        for line, why in problems:
            why = why[len(ty) + 2:] if why.startswith(f"{ty}: ") else why  # "the definition of a/B: a/B: …"
            place = _definition_line(src, vnode, line)
            if place is None:
                r.error(vnode, f"the definition of {ty}: {why}")
            else:
                r.diags.append(Diagnostic(place, f"the definition of {ty}: {why}"))
        if not problems:
            model.registry.add(spec)
    for kind, owner, path, knode in r.unit_keys:  # fields a known definition lacks
        root_type = topics.get(owner) if kind == "topic" else owner
        problem = unit_path_problem(model.registry, root_type, path) if root_type else None
        if problem:
            r.error(knode, f"the units of {'topic ' + repr(owner) if kind == 'topic' else owner}: {problem}")
    if "source" in entries:
        text = r.string(entries["source"][1], "'source'")
        if text:
            model.source = f"the system model {src.name} (from {text})"
    r.diags.sort(key=lambda d: (d.span.line, d.span.col))
    return (None, r.diags) if r.diags else (model, [])


def _definition_line(src: Source, node: yaml.Node, line: int) -> Optional[Span]:
    """Where line `line` of a definition written as a literal block (`Type: |`) is in the file;
    None for another style, whose lines are not the file's."""
    if not line or not isinstance(node, yaml.ScalarNode) or node.style != "|":
        return None
    lines = src.text.splitlines(True)
    index = node.start_mark.line + line  # 0-based: the block starts on the line after its '|'
    if index >= len(lines):
        return None
    start = sum(len(x) for x in lines[:index])
    text = lines[index]
    col = len(text) - len(text.lstrip(" "))
    return Span(src.name, index + 1, col + 1, start + col, start + len(text.rstrip("\r\n")))


def load_model(path: str, sources: SourceSet) -> Tuple[Optional[SystemModel], List[Diagnostic]]:
    """Read a model file; its text goes into `sources` so errors show their line."""
    from .sourcefile import read_source

    src, diag = read_source(path, what="system model")
    if src is None:
        return None, [diag] if diag else []
    sources.add(src)
    return parse_model(src)


def _unit_name(d: Dimension) -> str:
    if d == DIMENSIONLESS:
        return "1"
    return next((u for u, (f, dd) in UNITS.items() if dd == d and f == 1.0), "1")


class _Dumper(yaml.SafeDumper):
    pass


def _str(dumper: yaml.SafeDumper, text: str) -> yaml.Node:
    style = "|" if "\n" in text else None
    return dumper.represent_scalar("tag:yaml.org,2002:str", text, style=style)


_Dumper.add_representer(str, _str)


def dump_model(model: SystemModel, origin: str) -> str:
    """The model file text of a model (definitions of every type its topics use)."""
    topics: Dict[str, Any] = {}
    for name, ty in sorted(model.topics.items()):
        units = model.topic_units.get(name)
        topics[name] = ty if not units else {"type": ty, "units": {p: _unit_name(d) for p, d in sorted(units.items())}}
    data: Dict[str, Any] = {"rubass_model": 1, "source": origin, "topics": topics}
    if model.nodes is not None:
        data["nodes"] = list(model.nodes)
    if model.units:
        data["units"] = {t: {p: _unit_name(d) for p, d in u.items()} for t, u in sorted(model.units.items())}
    defs = sorted(model.registry.closure(model.topics.values()), key=lambda s: s.type)
    data["definitions"] = {s.type: s.text() for s in defs}
    head = ("# A rubass system model (docs/model.md): topics and their types, nodes, message definitions.\n"
            "# Check a spec against it with: rubass check --model THIS_FILE SPEC\n")
    return head + yaml.dump(data, Dumper=_Dumper, sort_keys=False, default_flow_style=False, allow_unicode=True)
