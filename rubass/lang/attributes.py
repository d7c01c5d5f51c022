"""Traceability attributes (LANGUAGE.md §15): which are known, their arguments, unique ids, and
what a rule inherits from its entity."""
from __future__ import annotations

from typing import Dict, List, Optional, Sequence, Tuple

from . import ast
from .errors import Diagnostic, a_noun, did_you_mean
from .model import Attrs
from .source import Span

# name -> (least, most) number of string arguments; most None: no limit
KNOWN: Dict[str, Tuple[int, object]] = {"id": (1, 1), "hazard": (1, None), "title": (1, 1), "ref": (1, None)}
NOT_INHERITED = frozenset({"id"})  # an entity's id names the entity, not each of its rules


class AttrChecker:
    """Checks attributes where they stand and keeps the ids seen, to report duplicates."""

    def __init__(self, diags: List[Diagnostic]) -> None:
        self.diags = diags
        self.ids: Dict[str, Span] = {}  # each id -> where it is first given in the source
        self._given: Dict[str, List[Span]] = {}  # each id -> every place it is given, as visited

    def own(self, attrs: Sequence[ast.Attr], what: str) -> Attrs:
        """The attributes written on one entity, rule or behaviour, checked."""
        out: Attrs = {}
        for a in attrs:
            if a.name not in KNOWN:
                self.diags.append(Diagnostic(a.span, f"unknown attribute '@{a.name}' on {a_noun(what)}; known: "
                                                     f"@id, @hazard, @title, @ref{did_you_mean(a.name, KNOWN)}"))
                continue
            least, most = KNOWN[a.name]
            if len(a.args) < least or (most is not None and len(a.args) > most):
                want = "one string" if most == 1 else "one or more strings"
                self.diags.append(Diagnostic(a.span, f"@{a.name} takes {want}, got {len(a.args)}"))
                continue
            if a.name in out:
                self.diags.append(Diagnostic(a.span, f"@{a.name} is given twice on this {what}: write all its "
                                                     f"values in one, e.g. @{a.name}(\"A\", \"B\")"
                                             if most is None else f"@{a.name} is given twice on this {what}"))
                continue
            if a.name == "id":  # duplicates are reported by check_rules, in source order
                self._given.setdefault(a.args[0], []).append(a.span)
            out[a.name] = tuple(a.args)
        return out

    def check_rules(self, entities: Dict[str, ast.Entity]) -> None:
        """Check every entity's and rule's own attributes (ids included), once."""
        self._entity_attrs = {name: self.own(ent.attrs, "entity") for name, ent in entities.items()}
        self._rule_attrs = {(name, r.name.name): self.own(r.attrs, "rule")
                            for name, ent in entities.items() for r in ent.rules}
        self._inherited = {name: {k: v for k, v in attrs.items() if k not in NOT_INHERITED}
                           for name, attrs in self._entity_attrs.items()}
        self.report_duplicate_ids()

    def report_duplicate_ids(self) -> None:
        """One error at each later place an id is given, naming the first place in the source (entities,
        rules and behaviours are checked in different passes, so not in source order)."""
        for value, spans in self._given.items():
            ordered = sorted(set(spans), key=lambda sp: (sp.file, sp.line, sp.col))
            self.ids[value] = ordered[0]
            for later in ordered[1:]:
                self.diags.append(Diagnostic(later, f"duplicate id \"{value}\"; first given at {ordered[0]}"))
        self._given = {}

    def rule_attrs(self, entity: ast.Entity, rule: ast.Rule) -> Attrs:
        """A rule's attributes: its own, and for each attribute it lacks, its entity's (not the id)."""
        inherited = dict(self._inherited.get(entity.name.name, ()))  # a dict of its own for each rule
        own = self._rule_attrs.get((entity.name.name, rule.name.name))
        if own:
            inherited.update(own)
        return inherited


def entity_ids(spec: ast.Spec) -> Dict[str, str]:
    """Each entity's @id (entities that have one), by entity name. An entity's id names the entity: its
    rules do not take it as their own @id (§15), but it names those of its rules that have no id."""
    return {d.name.name: a.args[0] for d in spec.decls if isinstance(d, ast.Entity)
            for a in d.attrs if a.name == "id" and len(a.args) == 1}


def rule_ids(attrs: Attrs, entity_id: Optional[str]) -> Tuple[str, ...]:
    """The ids that name a rule: its own @id, else its entity's (none when neither has one)."""
    own = attrs.get("id", ())
    if own:
        return tuple(own)
    return (entity_id,) if entity_id else ()
