"""A system model of a robot: its topics and their types, its nodes, message definitions and
units; the FieldModel the checker asks, and the warnings for topics and nodes it lacks."""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Dict, Iterator, List, Optional, Set, Tuple

from . import ast
from .errors import Diagnostic, did_you_mean
from .fieldmodel import FieldInfo
from .msgdef import FieldDef, Registry
from .msgpath import UnitTable, has_stamp, resolve
from .std_units import STANDARD_UNITS
from .topicnames import resolve as resolve_topic
from .units import Dimension


def norm_topic(name: str) -> str:
    """'/cmd_vel' for 'cmd_vel', '/cmd_vel/' or '//cmd_vel'; '/rubass/x' for '~x' (topicnames.py)."""
    return resolve_topic(name)


@dataclass
class SystemModel:
    """What the checker may know of a robot before it runs.

    topics: topic -> message type ('package/Type'); nodes: the node names, or None when the
    source does not say (then no node is reported missing); units: per message type, dotted
    field path -> dimension (custom messages); topic_units: the same per topic (e.g. a
    JointState whose joints all rotate); source: how messages name it ('recording run.bag').
    """

    topics: Dict[str, str]
    nodes: Optional[List[str]] = None
    registry: Registry = field(default_factory=Registry)
    units: UnitTable = field(default_factory=dict)
    topic_units: Dict[str, Dict[str, Dimension]] = field(default_factory=dict)
    source: str = "the system model"
    unpublished: Set[str] = field(default_factory=set)  # known topics nobody publishes (live graph)
    broken: Dict[str, str] = field(default_factory=dict)  # topic -> why its recorded definition is unreadable

    def __post_init__(self) -> None:
        self.topics = {norm_topic(t): ty for t, ty in self.topics.items()}
        self.topic_units = {norm_topic(t): u for t, u in self.topic_units.items()}
        self.unpublished = {norm_topic(t) for t in self.unpublished}
        if self.nodes is not None:
            self.nodes = sorted({norm_topic(n) for n in self.nodes})

    # -- the FieldModel protocol ------------------------------------------------------------
    def field(self, topic: str, path: Tuple[ast.PathElem, ...]) -> Optional[FieldInfo]:
        type_name = self.topics.get(norm_topic(topic))
        if type_name is None:
            return None
        beyond, past = _index_beyond(self.registry, type_name, path)
        if beyond is not None:
            return FieldInfo("missing", why=beyond)
        info = resolve(self.registry, type_name, path, (STANDARD_UNITS, self.units),
                       self.topic_units.get(norm_topic(topic)))
        return replace(info, warning=past) if past and info is not None and info.kind != "missing" else info

    def has_stamp(self, topic: str) -> Optional[bool]:
        type_name = self.topics.get(norm_topic(topic))
        return None if type_name is None else has_stamp(self.registry, type_name)

    # -- helpers --------------------------------------------------------------------------
    def type_of(self, topic: str) -> Optional[str]:
        return self.topics.get(norm_topic(topic))

    def undefined_types(self) -> List[str]:
        """Topic types (and types they use) with no definition in the model."""
        missing = set()
        todo = list(self.topics.values())
        seen = set()
        while todo:
            t = todo.pop()
            if t in seen:
                continue
            seen.add(t)
            spec = self.registry.get(t)
            if spec is None:
                missing.add(t)
            else:
                todo += [f.type for f in spec.fields if not f.is_primitive]
        return sorted(missing)


def _index_beyond(registry: Registry, root: str, path: Tuple[ast.PathElem, ...]) -> Tuple[Optional[str], str]:
    """(why an index or slice of the path is outside a fixed-size array: `position_covariance[9]`
    or `[40:50]` of a float64[9], a slice that selects no element; a warning for a slice that
    runs past its end). None and '' when every index fits or a size is not known (other problems
    are resolve's)."""
    current: Optional[FieldDef] = None
    past = ""
    for i, elem in enumerate(path):
        if isinstance(elem, str):
            spec = registry.get(root if current is None else current.type)
            current = spec.get(elem) if spec is not None else None
            if current is None:
                return None, past
        elif isinstance(elem, (int, ast.Slice)) and current is not None and current.is_array \
                and current.length is not None:
            n = current.length
            where = ast.path_suffix(path[:i]).lstrip(".")
            array = f"'{where}', a {current.type}[{n}]: its indices are 0 to {n - 1}"
            if isinstance(elem, int) and not -n <= elem < n:
                return f"'{where}[{elem}]' is beyond the end of {array}", past
            if isinstance(elem, ast.Slice):
                chosen = range(n)[elem.start:elem.stop]
                if not chosen:
                    return (f"'{where}{elem.text}' selects no element of {array} (a slice is clipped to "
                            "the array, so this one is always empty)"), past
                if any(b is not None and not -n <= b <= n for b in (elem.start, elem.stop)):
                    side = "start" if any(b is not None and b < -n for b in (elem.start, elem.stop)) else "end"
                    past = past or (f"'{where}{elem.text}' runs past the {side} of {array}; it is clipped to "
                                    f"'{where}[{chosen[0]}:{chosen[-1] + 1}]'")
            current = FieldDef(current.name, current.type)  # its element
        else:
            return None, past
    return None, past


def _topic_refs(spec: ast.Spec) -> Iterator[ast.TopicRef]:
    for e in _exprs(spec):
        for sub in ast.walk(e):
            if isinstance(sub, ast.TopicRef):
                yield sub


def _exprs(spec: ast.Spec) -> Iterator[ast.Expr]:
    for d in spec.decls:
        if isinstance(d, ast.Entity):
            yield from (r.expr for r in d.rules)
        elif isinstance(d, ast.Behaviour):
            yield d.cond


def graph_warnings(spec: ast.Spec, model: SystemModel) -> List[Diagnostic]:
    """A warning at the first use of each topic the model lacks and each node it does not list,
    with a did-you-mean from the model's names. Relative names are taken from the root."""
    out: List[Diagnostic] = []
    seen = set()
    undefined = set()
    for ref in sorted(_topic_refs(spec), key=lambda r: (r.span.line, r.span.col)):
        name = norm_topic(ref.topic)
        type_name = model.topics.get(name)
        if ref.path and type_name is not None and name not in undefined and model.registry.get(type_name) is None:
            undefined.add(name)  # a hung publisher of a type not installed here: no definition to check with
            out.append(Diagnostic(ref.span, f"the fields of topic '{ref.topic}' cannot be checked: {model.source} "
                                            f"gives no definition of {type_name}", "warning"))
        if name in seen or (name in model.topics and name not in model.unpublished):
            continue
        seen.add(name)
        if name in model.topics:
            out.append(Diagnostic(ref.span, f"topic '{ref.topic}' has no publisher in {model.source}: "
                                            "its data would never come", "warning"))
            continue
        out.append(Diagnostic(ref.span, f"topic '{ref.topic}' is not in {model.source}"
                                        f"{did_you_mean(name, model.topics)}", "warning"))
    if model.nodes is None:
        return out
    out += _node_warnings(spec, model, model.nodes)
    return sorted(out, key=lambda d: (d.span.line, d.span.col))


def _node_warnings(spec: ast.Spec, model: SystemModel, known: List[str]) -> List[Diagnostic]:
    out: List[Diagnostic] = []
    nodes: List[Tuple[str, ast.Ident]] = []
    seen_nodes = set()
    for d in spec.decls:
        if isinstance(d, ast.Entity):
            nodes += [(n.name, n) for n in d.nodes]
    for e in _exprs(spec):
        nodes += [(sub.node, ast.Ident(sub.node, sub.span)) for sub in ast.walk(e) if isinstance(sub, ast.NodeRef)]
    for name, ident in sorted(nodes, key=lambda p: (p[1].span.line, p[1].span.col)):
        key = norm_topic(name)
        if key in seen_nodes or key in known:
            continue
        seen_nodes.add(key)
        out.append(Diagnostic(ident.span, f"node '{name}' is not in {model.source}"
                                          f"{did_you_mean(key, known)}", "warning"))
    return out
