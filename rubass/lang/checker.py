"""The checker (LANGUAGE.md §3, §9): names, duplicates, cycles, actions and libraries.

Every problem in a spec is reported in one run; kinds and units are checked by typecheck.
"""
from __future__ import annotations

import contextlib
import dataclasses
import gc
from typing import Any, Callable, Dict, FrozenSet, Iterator, List, Optional, Sequence, Set, Tuple

from . import ast
from .errors import Diagnostic, a_noun, did_you_mean
from .fieldmodel import FieldModel
from .fmt import format_expr
from .libcheck import argument_problem
from .library import ActionDef
from .actiondecls import ActionDecls
from .attributes import AttrChecker
from .deporder import dependency_order
from .model import BoundAction, CheckedBehaviour, CheckedRule, CheckedSpec, TopicUse, Value
from .source import SourceSet, Span
from .typecheck import ANY, ExprChecker, Resolution, Scope, Ty, _constant

STAMP_PATH: Tuple[ast.PathElem, ...] = ("header", "stamp")
UNUSED_ACTION = "unused action "  # the subject of that warning, then the action's name


class _Checker(ActionDecls):
    def __init__(self, spec: ast.Spec, sources: SourceSet, model: Optional[FieldModel] = None) -> None:
        self.spec, self.sources, self.model = spec, sources, model
        self.diags: List[Diagnostic] = []
        self._unusable_libraries: List[str] = []  # imported libraries that could not be read at all
        self.warnings: List[Diagnostic] = []
        self.consts: Dict[str, ast.Const] = {}
        self.const_values: Dict[str, Tuple[ast.Lit, Ty]] = {}
        self.const_busy: List[str] = []
        self.entities: Dict[str, ast.Entity] = {}
        self.rule_asts: Dict[str, ast.Rule] = {}
        self.rule_owners: Optional[Dict[str, str]] = None  # rule name -> first entity with it (on demand)
        self.used_rules: Dict[str, Set[str]] = {}
        self.declared_names: FrozenSet[str] = frozenset(
            i.name for d in spec.decls if isinstance(d, ast.ActionDecl) for i in d.names)
        self.active_uses: Dict[str, Set[str]] = {}  # rule key or 'b:N' -> actions its active() names
        self.attrs = AttrChecker(self.diags)
        # (a duplicate entity, constant or rule, the first definition of its name): the duplicate is
        # checked on its own afterwards, in place of the first (_inside_duplicates)
        self.duplicates: List[Tuple[Any, Any]] = []

    def error(self, span: Span, msg: str) -> None:
        self.diags.append(Diagnostic(span, msg))

    # -- names ---------------------------------------------------------------------------
    def collect(self) -> None:
        top: Dict[str, Span] = {}
        for d in self.spec.decls:
            if isinstance(d, ast.Behaviour) and d.name is not None:
                if d.name.name in self.declared_names:  # tests and events name both: one must not hide the other
                    self.error(d.name.span, f"behaviour name '{d.name.name}' is also the name of a declared "
                                            "action: give the behaviour another name")
                elif d.name.name in top:
                    self.error(d.name.span, f"duplicate name '{d.name.name}' (a behaviour); first defined at "
                                            f"{top[d.name.name]}")
                else:
                    top[d.name.name] = d.name.span
                continue
            if isinstance(d, (ast.Const, ast.Entity)):
                kind = "constant" if isinstance(d, ast.Const) else "entity"
                if d.name.name in top:
                    self.error(d.name.span, f"duplicate name '{d.name.name}' ({a_noun(kind)}); first defined at "
                                            f"{top[d.name.name]}")
                    first = self.consts.get(d.name.name) or self.entities.get(d.name.name)
                    if first is not None:  # (a behaviour's name is checked with its behaviour)
                        self.duplicates.append((d, first))
                    continue
                top[d.name.name] = d.name.span
                if isinstance(d, ast.Const):
                    self.consts[d.name.name] = d
                else:
                    self.entities[d.name.name] = d
        for ent in self.entities.values():
            seen: Dict[str, Span] = {}
            for r in ent.rules:
                if r.name.name in seen:
                    self.error(r.name.span, f"duplicate rule '{r.name.name}' in entity '{ent.name.name}'; "
                                            f"first defined at {seen[r.name.name]}")
                    self.duplicates.append((r, self.rule_asts[f"{ent.name.name}.{r.name.name}"]))
                    continue
                if r.name.name in self.consts:
                    self.error(r.name.span, f"rule '{r.name.name}' has the name of a constant "
                                            f"(defined at {self.consts[r.name.name].name.span})")
                seen[r.name.name] = r.name.span
                self.rule_asts[f"{ent.name.name}.{r.name.name}"] = r
            nodes: Dict[str, Span] = {}
            for n in ent.nodes:
                if n.name in nodes:
                    self.warnings.append(Diagnostic(n.span, f"node '{n.name}' is listed twice", "warning"))
                nodes[n.name] = n.span
            if not ent.rules:
                self.warnings.append(Diagnostic(ent.name.span, f"entity '{ent.name.name}' has no rules",
                                                "warning"))

    def resolver(self, entity: Optional[str], user: Optional[str]):  # type: ignore[no-untyped-def]
        """A name resolver for an expression in `entity` (None: at top level)."""

        def resolve_name(name: ast.Name) -> Resolution:
            parts = name.parts
            if len(parts) == 2:
                ent, rule = parts
                if ent not in self.entities:
                    return f"undefined entity '{ent}'{did_you_mean(ent, self.entities)}"
                key = f"{ent}.{rule}"
                if key not in self.rule_asts:
                    names = [r.name.name for r in self.entities[ent].rules]
                    return f"entity '{ent}' has no rule '{rule}'{did_you_mean(rule, names)}"
                return self._rule(key, user)
            (n,) = parts
            if entity is not None and f"{entity}.{n}" in self.rule_asts:
                return self._rule(f"{entity}.{n}", user)
            if n in self.consts:
                lit, ty = self.const_value(n)
                return ("const", lit, ty)
            owner = self._owner(n)
            if owner is not None:
                return f"'{n}' is a rule of entity '{owner}': write '{owner}.{n}'"
            if n in self.entities:
                return f"'{n}' is an entity; name one of its rules: '{n}.RULE'"
            visible = list(self.consts)
            if entity is not None:
                visible += [r.name.name for r in self.entities[entity].rules]
            return f"undefined name '{n}'{did_you_mean(n, visible)}"

        return resolve_name

    def _owner(self, rule: str) -> Optional[str]:
        """The first entity that has a rule of this name (an index built once: no scan per name)."""
        if self.rule_owners is None:
            self.rule_owners = {}
            for k in self.rule_asts:
                self.rule_owners.setdefault(k.split(".")[1], k.split(".")[0])
        return self.rule_owners.get(rule)

    def _rule(self, key: str, user: Optional[str]) -> Resolution:
        if user is not None:
            self.used_rules.setdefault(user, set()).add(key)  # user: a rule key, or 'b:N' for behaviour N
        return ("rule", ast.RuleRef(key), Ty("bool"))

    def const_value(self, name: str) -> Tuple[ast.Lit, Ty]:
        if name in self.const_values:
            return self.const_values[name]
        decl = self.consts[name]
        if name in self.const_busy:
            cycle = self.const_busy[self.const_busy.index(name):] + [name]
            self.error(decl.name.span, f"constant '{name}' is defined in terms of itself: {' -> '.join(cycle)}")
            self.const_values[name] = (ast.Lit(0.0), ANY)
            return self.const_values[name]
        self.const_busy.append(name)
        out, ty = ExprChecker(Scope(self.resolver(None, None), dynamic=False), self.diags).check(decl.expr)
        self.const_busy.pop()
        if not isinstance(out, ast.Lit):
            if not any(d.span.start >= decl.span.start and d.span.file == decl.span.file and
                       d.span.start <= decl.span.end for d in self.diags):
                self.error(decl.expr.span, f"constant '{name}' must be computable before the monitor starts"
                                           + (" (it has no value: a division by zero, the square root of a negative "
                                              "number, …)" if _constant(out) else ""))
            out = ast.Lit(0.0)
        self.const_values[name] = (out, ty)
        return out, ty

    # -- rules and cycles ----------------------------------------------------------------
    def check_rules(self) -> Dict[str, ast.Expr]:
        checked: Dict[str, ast.Expr] = {}
        for ent in self.entities.values():
            nodes = tuple(n.name for n in ent.nodes)
            for r in ent.rules:
                key = f"{ent.name.name}.{r.name.name}"
                if self.rule_asts.get(key) is not r:
                    continue
                uses = self.active_uses.setdefault(key, set())
                scope = Scope(self.resolver(ent.name.name, key), nodes=nodes, entity=ent.name.name,
                              actions=self.declared_names, active_uses=uses, model=self.model)
                try:
                    checked[key] = ExprChecker(scope, self.diags, self.warnings).condition(r.expr, f"rule '{r.name.name}'")
                except RecursionError:  # at the expression, not at 1:1 (issue 20.5)
                    self.error(r.name.span, TOO_DEEP)
                    checked[key] = ast.Lit(False, span=r.expr.span)
        return checked

    def order(self) -> List[str]:
        """Rule keys, each after the rules it uses; reports cycles."""
        def cycle(keys: List[str]) -> None:
            self.error(self.rule_asts[keys[0]].name.span, f"cyclic rule reference: {' -> '.join(keys)}")

        return dependency_order(self.rule_asts, lambda key: sorted(self.used_rules.get(key, ())), cycle)

    def evaluation_order(self, behaviours: List[CheckedBehaviour]) -> List[str]:
        """Rules ('entity.rule') and behaviours ('b:N') in one dependency order (§14): what an
        expression uses comes before it, and a behaviour comes before every active() of its
        actions. A behaviour that depends on active() of one of its own actions is an error."""
        starters: Dict[str, List[str]] = {}
        for b in behaviours:
            for a in b.actions:
                starters.setdefault(a.name, []).append(f"b:{b.index}")
        deps: Dict[str, List[str]] = {}
        for user in list(self.rule_asts) + [f"b:{b.index}" for b in behaviours]:
            d = sorted(self.used_rules.get(user, ()))
            for act in sorted(self.active_uses.get(user, ())):
                d += [f"active({act})"]
            deps[user] = d
        for act, who in starters.items():
            deps[f"active({act})"] = who
        spans = {f"b:{b.index}": b.span for b in behaviours}
        names = {f"b:{b.index}": b.label for b in behaviours}

        def cycle(nodes: List[str]) -> None:
            if any(c.startswith("active(") for c in nodes):
                owner = next(c for c in nodes if c.startswith("b:"))
                chain = " -> ".join(names.get(c, c) for c in nodes[nodes.index(owner):] + nodes[1:nodes.index(owner) + 1]) \
                    if nodes[0] != owner else " -> ".join(names.get(c, c) for c in nodes)
                self.error(spans[owner], f"{names[owner]} depends on active() of one of its own actions, so it "
                                         f"could hold itself on: {chain}")

        order = dependency_order(list(self.rule_asts) + [f"b:{b.index}" for b in behaviours],
                                 lambda node: deps.get(node, ()), cycle)
        return [node for node in order if not node.startswith("active(")]

    def _own_span(self, d: ast.Behaviour) -> Span:
        """A behaviour's span from its name or its `if`, after its attributes: its line is the one
        events, tests and reports give (docs/replay.md: 'the line of its if')."""
        src = self.sources.get(d.span.file)
        if not d.attrs or src is None:
            return d.span
        start = d.name.span.start if d.name is not None else src.text.rfind("if", d.span.start, d.cond.span.start)
        return src.span(start, d.span.end) if d.span.start <= start < d.span.end else d.span

    def check_behaviours(self, declared: Dict[str, Span], library: Dict[str, ActionDef]) -> List[CheckedBehaviour]:
        out: List[CheckedBehaviour] = []
        used: Set[str] = set()
        header_nodes = tuple(sorted({n.name for ent in self.entities.values() for n in ent.nodes}))
        for d in self.spec.decls:
            if not isinstance(d, ast.Behaviour):
                continue
            index = len(out) + 1
            uses = self.active_uses.setdefault(f"b:{index}", set())
            user = f"b:{index}"
            scope = Scope(self.resolver(None, user), actions=self.declared_names, active_uses=uses, model=self.model,
                          header_nodes=header_nodes)
            try:
                cond = ExprChecker(scope, self.diags, self.warnings).condition(d.cond, "the condition of 'if'")
            except RecursionError:
                self.error(d.span, TOO_DEEP)
                cond = ast.Lit(False, span=d.cond.span)
            bound: List[BoundAction] = []
            for call in d.actions:
                name = call.name.name
                used.add(name)
                if name not in declared:
                    self.error(call.name.span, f"action '{name}' is not declared: add 'action primitive {name};'"
                                               f"{did_you_mean(name, declared)}")
                args: List[Value] = []
                for a in call.args:
                    lit, _ = ExprChecker(Scope(self.resolver(None, None), dynamic=False), self.diags).check(a)
                    if isinstance(lit, ast.Lit):
                        args.append(lit.value)
                    else:
                        self.error(a.span, "an action argument must be a literal or a constant")
                if name in library:
                    wrong = argument_problem(library[name], len(call.args), call.span)
                    if wrong is not None:  # `crawl(0.05 m/s)` would still clamp as its library says
                        self.diags.append(wrong)
                    bound.append(BoundAction(name, library[name], tuple(args), call.span))
            if not d.actions:
                self.warnings.append(Diagnostic(d.span, "this behaviour has no actions", "warning"))
            sig = f"if ({format_expr(cond)}) then {{{' '.join(a.name + repr(a.args) for a in bound)}}}"
            name = d.name.name if d.name is not None else ""
            out.append(CheckedBehaviour(index, cond, tuple(bound), self._own_span(d), sig, name,
                                        self.attrs.own(d.attrs, "behaviour")))
        for name, span in declared.items():
            if name not in used:
                self.warnings.append(Diagnostic(span, f"action '{name}' is declared but never used", "warning",
                                                subject=UNUSED_ACTION + name))
        return out


@contextlib.contextmanager
def gc_paused() -> Iterator[None]:
    """No cyclic garbage collection inside: checking allocates many small objects and no garbage
    cycles (its peak memory is the same either way), and the collections it would trigger rescan
    them again and again (a 1,000-rule check inside load_spec: median ~35 % faster without).
    Restores the collector only if it was on (callers may nest). Not around parsing: pyparsing's
    backtracking leaves cycles (a 4,000-rule spec with an error would peak at ~490 MB, not 44)."""
    was_on = gc.isenabled()
    if was_on:
        gc.disable()
    try:
        yield
    finally:
        if was_on:
            gc.enable()


def check(spec: ast.Spec, sources: SourceSet, extra_libraries: Sequence[str] = (),
          model: Optional[FieldModel] = None) -> Tuple[Optional[CheckedSpec], List[Diagnostic], List[Diagnostic]]:
    """Check a parsed spec, against a system model when one is given; returns (checked spec or
    None, errors, warnings)."""
    with gc_paused():
        return _check(spec, sources, extra_libraries, model)


TOO_DEEP = ("this expression is nested too deeply to check: a sum or product of a few hundred terms, or as "
            "many nested parentheses; split it into several rules (an 'and'/'or' chain may be of any length)")


MAX_DUPLICATES_CHECKED = 20  # each is one more check of the whole spec (a duplicate in a duplicate too)


def _without(spec: ast.Spec, first: Any) -> ast.Spec:
    """`spec` without the definition `first` (a top-level declaration, or a rule of an entity)."""
    decls: List[ast.Decl] = []
    for d in spec.decls:
        if d is first:
            continue
        if isinstance(d, ast.Entity) and any(r is first for r in d.rules):
            d = dataclasses.replace(d, rules=tuple(r for r in d.rules if r is not first))
        decls.append(d)
    return dataclasses.replace(spec, decls=tuple(decls))


def _inside_duplicates(c: "_Checker", spec: ast.Spec, sources: SourceSet, extra_libraries: Sequence[str],
                       model: Optional[FieldModel], budget: List[int]) -> Tuple[List[Diagnostic], List[Diagnostic]]:
    """The errors and warnings inside each duplicate definition: it is checked in place of the first
    one of its name, so that fixing the name does not reveal a second round of errors. `budget`: how
    many more such checks may run."""
    errors: List[Diagnostic] = []
    warnings: List[Diagnostic] = []
    known = {(str(d.span), d.message) for d in c.diags + c.warnings}
    for dup, first in c.duplicates:
        if budget[0] <= 0:
            break
        budget[0] -= 1
        _, diags, warns = _check(_without(spec, first), sources, extra_libraries, model, budget)
        for found, out in ((diags, errors), (warns, warnings)):
            for d in found:
                inside = d.span.file == dup.span.file and dup.span.start <= d.span.start < dup.span.end
                if inside and (str(d.span), d.message) not in known:
                    known.add((str(d.span), d.message))
                    out.append(d)
    return errors, warnings


def _check(spec: ast.Spec, sources: SourceSet, extra_libraries: Sequence[str],
           model: Optional[FieldModel], budget: Optional[List[int]] = None
           ) -> Tuple[Optional[CheckedSpec], List[Diagnostic], List[Diagnostic]]:
    """`budget`: how many duplicates may still be checked on their own (_inside_duplicates)."""
    c = _Checker(spec, sources, model)
    try:
        c.collect()
        for name in c.consts:
            c.const_value(name)
        checked = c.check_rules()
        order = c.order()
        library, loaded = c.load_libraries(extra_libraries)
        declared = c.check_actions(library, loaded)
        behaviours = c.check_behaviours(declared, library)
        evaluation = c.evaluation_order(behaviours)
        c.attrs.check_rules(c.entities)
    except RecursionError:
        c.error(Span(spec.file, 1, 1), "expressions are nested too deeply to check")
    if c.duplicates:
        errors, warnings = _inside_duplicates(c, spec, sources, extra_libraries, model,
                                              [MAX_DUPLICATES_CHECKED] if budget is None else budget)
        c.diags.extend(errors)
        c.warnings.extend(warnings)
    if c.diags:
        c.diags.sort(key=lambda d: (d.span.file != spec.file, d.span.file, d.span.line, d.span.col))
        return None, c.diags, c.warnings
    rules = _build_rules(c, checked, order)
    behaviours = _sign_behaviours(behaviours, rules)
    topics, nodes = _uses([r.expr for r in rules] + [b.cond for b in behaviours])
    consts = {n: lit.value for n, (lit, _) in c.const_values.items()}
    return (CheckedSpec(spec.file, spec, rules, behaviours, consts, library, topics, nodes, loaded,
                        c.warnings, sources, evaluation), [], c.warnings)


def _build_rules(c: _Checker, checked: Dict[str, ast.Expr], order: List[str]) -> List[CheckedRule]:
    sigs: Dict[str, str] = {}
    rules: List[CheckedRule] = []
    for key in order:
        deps = frozenset(c.used_rules.get(key, ()))
        text = format_expr(checked[key])
        sigs[key] = text + "".join(f" [{d}: {sigs[d]}]" for d in sorted(deps))
        ent, name = key.split(".")
        rules.append(CheckedRule(key, ent, name, checked[key], c.rule_asts[key].span, deps, sigs[key],
                                 c.attrs.rule_attrs(c.entities[ent], c.rule_asts[key])))
    return rules


def _sign_behaviours(behaviours: List[CheckedBehaviour], rules: List[CheckedRule]) -> List[CheckedBehaviour]:
    """A behaviour's signature also covers the rules it names, as a rule's covers its rules."""
    sigs = {r.key: r.signature for r in rules}
    out = []
    for b in behaviours:
        keys = sorted({e.key for e in _walk(b.cond) if type(e) is ast.RuleRef})
        out.append(dataclasses.replace(b, signature=b.signature + "".join(f" [{k}: {sigs[k]}]" for k in keys),
                                       own_signature=b.signature))
    return out


def _uses(exprs: Sequence[ast.Expr]) -> Tuple[Dict[str, TopicUse], FrozenSet[str]]:
    paths: Dict[str, Set[Tuple[ast.PathElem, ...]]] = {}
    nodes: Set[str] = set()
    for e in (x for expr in exprs for x in _walk(expr)):
        t = type(e)  # the node types are final: `is` is an exact isinstance
        if t not in _USE_KINDS:
            continue
        if t is ast.TopicRef:
            paths.setdefault(e.topic, set())  # type: ignore[union-attr]
            if e.path:  # type: ignore[union-attr]
                paths[e.topic].add(e.path)  # type: ignore[union-attr]
        elif t is ast.Age or t is ast.Frequency or t is ast.StampAge:
            paths.setdefault(e.topic, set())  # type: ignore[union-attr]
            if t is ast.StampAge:
                paths[e.topic].add(STAMP_PATH)  # type: ignore[union-attr]
        elif t is ast.NodeStat:
            nodes.add(e.node)  # type: ignore[union-attr]
    return {t: TopicUse(t, frozenset(p)) for t, p in paths.items()}, frozenset(nodes)


_USE_KINDS = frozenset({ast.TopicRef, ast.Age, ast.Frequency, ast.StampAge, ast.NodeStat})

# The sub-expressions of each expression type, as ast.children gives them.
_KIDS: Dict[type, Callable[[Any], Sequence[ast.Expr]]] = {
    ast.Call: lambda e: e.args, ast.Unary: lambda e: (e.operand,), ast.Binary: lambda e: (e.left, e.right),
    ast.For: lambda e: (e.operand, e.duration), ast.Within: lambda e: (e.operand, e.duration),
    ast.Pair: lambda e: (e.x, e.y), ast.Rate: lambda e: (e.ref,), ast.ArrayFn: lambda e: (e.ref,),
    ast.Quant: lambda e: (e.ref, e.body), ast.Latch: lambda e: (e.set, e.reset), ast.Zone: lambda e: (e.x, e.y)}


def _walk(expr: ast.Expr) -> List[ast.Expr]:
    """ast.walk(expr) as a list, in the same order, with one dict look-up per node instead of a
    chain of isinstance tests (the checker walks every expression of the spec)."""
    out: List[ast.Expr] = []
    stack = [expr]
    kids = _KIDS.get
    while stack:
        e = stack.pop()
        out.append(e)
        sub = kids(type(e))
        if sub is not None:
            stack.extend(sub(e))
    return out
