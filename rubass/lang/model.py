"""The checked spec: what the engine and the monitor run, with every name resolved."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, FrozenSet, List, Tuple, Union

from . import ast
from .errors import Diagnostic
from .library import ActionDef
from .source import Span, SourceSet

Value = Union[float, bool, str]

# Traceability attributes (LANGUAGE.md §15): 'id', 'hazard', 'title', 'ref' -> their strings.
Attrs = Dict[str, Tuple[str, ...]]


@dataclass(frozen=True)
class CheckedRule:
    """A rule: key 'entity.rule', its checked expression, and what it depends on."""

    key: str
    entity: str
    name: str
    expr: ast.Expr
    span: Span
    rule_deps: FrozenSet[str]
    signature: str  # canonical text of the rule and of every rule it uses (for live reload)
    attrs: Attrs = field(default_factory=dict)  # its own, else its entity's (§15)


@dataclass(frozen=True)
class BoundAction:
    """An action call in a behaviour: the library action and its literal arguments."""

    name: str
    action: ActionDef
    args: Tuple[Value, ...]
    span: Span


@dataclass(frozen=True)
class CheckedBehaviour:
    """`if (cond) then {…}`; index is 1-based in file order."""

    index: int
    cond: ast.Expr
    actions: Tuple[BoundAction, ...]
    span: Span
    signature: str
    name: str = ""  # `name: if (…)` (§14); "" for an unnamed behaviour
    attrs: Attrs = field(default_factory=dict)
    own_signature: str = ""  # its condition and actions as written, without the rules it names

    @property
    def identity(self) -> str:
        """Who it is across a live reload, for the engine and the dispatcher alike: its name and its
        actions, or (unnamed) its condition and actions as written, so that editing a rule it
        names does not make it another behaviour (its stop would be released and started again)."""
        if not self.name:
            return f"sig:{self.own_signature or self.signature}"
        return f"name:{self.name} {{{' '.join(a.name + repr(a.args) for a in self.actions)}}}"

    @property
    def label(self) -> str:
        """How events, tests and reports name it: its name, else 'behaviour N'."""
        return self.name or f"behaviour {self.index}"

    @property
    def latched(self) -> bool:
        return any(a.action.latch for a in self.actions)


@dataclass(frozen=True)
class TopicUse:
    """How a spec uses a topic: the field paths it reads (none: only age/frequency)."""

    topic: str
    paths: FrozenSet[Tuple[ast.PathElem, ...]]

    @property
    def needs_data(self) -> bool:
        return bool(self.paths)


@dataclass
class CheckedSpec:
    """A spec that passed every check; rules are in dependency order (used before users)."""

    path: str
    spec: ast.Spec
    rules: List[CheckedRule]
    behaviours: List[CheckedBehaviour]
    consts: Dict[str, Value]
    actions: Dict[str, ActionDef]
    topics: Dict[str, TopicUse]
    nodes: FrozenSet[str]
    libraries: List[str]
    warnings: List[Diagnostic] = field(default_factory=list)
    sources: SourceSet = field(default_factory=SourceSet)
    # rules ('entity.rule') and behaviours ('b:N') in one dependency order (§14)
    evaluation: List[str] = field(default_factory=list)

    def field_readers(self, implicit: bool = True) -> Dict[str, Dict[Tuple[ast.PathElem, ...], List[str]]]:
        """topic -> field path -> who reads it ("rule 'e.r'", "behaviour 2 (line 9)"), for errors.

        implicit=False leaves out the header.stamp that only stamp_age() reads: a type without one
        makes stamp_age unknown (§11), it is no field error."""
        out: Dict[str, Dict[Tuple[ast.PathElem, ...], List[str]]] = {t: {} for t in self.topics}
        owners = [(f"rule '{r.key}'", r.expr) for r in self.rules] + \
                 [(f"behaviour {b.index} (line {b.span.line})", b.cond) for b in self.behaviours]
        for owner, expr in owners:
            for topic, path in _read_paths(expr, implicit):
                users = out[topic].setdefault(path, [])
                if owner not in users:
                    users.append(owner)
        return out

    def behaviour(self, name: str) -> CheckedBehaviour:
        """A behaviour by its name or its 1-based number."""
        for b in self.behaviours:
            if b.name == name or str(b.index) == name:
                return b
        raise KeyError(name)

    def rule(self, key: str) -> CheckedRule:
        for r in self.rules:
            if r.key == key:
                return r
        raise KeyError(key)


def _read_paths(expr: ast.Expr, implicit: bool = True) -> List[Tuple[str, Tuple[ast.PathElem, ...]]]:
    """Every (topic, field path) an expression reads; an array term's element paths in full
    (`status[*].level`), so they can be checked against the message type too."""
    out: List[Tuple[str, Tuple[ast.PathElem, ...]]] = []
    for e in ast.walk(expr):
        if isinstance(e, ast.TopicRef) and e.path:
            out.append((e.topic, e.path))
        elif isinstance(e, ast.ArrayFn) and e.elem:
            out.append((e.ref.topic, e.ref.path + e.elem))
        elif isinstance(e, ast.StampAge) and implicit:  # the message must be read for its stamp
            out.append((e.topic, ("header", "stamp")))
        elif isinstance(e, ast.Quant):
            out += [(e.ref.topic, e.ref.path + x.path) for x in ast.walk(e.body) if isinstance(x, ast.Elem) and x.path]
    return out
