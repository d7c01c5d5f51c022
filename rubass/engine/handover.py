"""A live reload's handover: what a new engine takes over from the one it replaces (data, rule values,
`for`/`within`/`latch` history, active behaviours, outside holders), so that a stop that held goes on."""
from __future__ import annotations

import re
from typing import TYPE_CHECKING, Callable, Dict, List, Optional, Set

from ..lang import ast
from ..lang.fmt import format_expr
from ..lang.model import CheckedBehaviour
from .events import Event

if TYPE_CHECKING:
    from .engine import Engine, _Node


def adopt(new: "Engine", old: "Engine", now: float,
          carry: Optional[Callable[[CheckedBehaviour], str]] = None) -> List[Event]:
    """`new` takes over the state of `old`, which it replaces, then evaluates everything.

    Data (fields, arrivals, node samples) carries over for topics and nodes both specs
    use; a rule whose text and whose used rules' texts are unchanged keeps its value and
    its operators' state; a behaviour keeps its state when its name is unchanged (or, when
    unnamed, its condition and actions), so an active one does not start again; outside
    holders of actions (restored latches) stay. Topics new to this spec are watched from now.
    `carry`: for an active behaviour whose condition's `for`/`within`/`latch` history could
    not be carried (operators added, removed or moved), the name of an outside holder that
    keeps its actions on (listed in `history_lost`; the caller ends the hold). Returns the
    events of the first evaluation. Call it on the engine's thread.
    """
    old.advance(now)
    src, dst = old.store, new.store
    for topic in new.spec.topics:
        if topic in old.spec.topics:
            dst.carry_topic(src, topic)
        else:
            dst.watch_start[topic] = now
    dst.fields.update({k: v for k, v in src.fields.items() if k[0] in new.spec.topics})
    dst.sync_cells()
    dst.nodes.update({n: v for n, v in src.nodes.items() if n in new.spec.nodes})
    dst.now = max(dst.now, now)
    old_rules = {n.key: n for n in old._nodes if not n.behaviour}
    old_sigs = {r.key: r.signature for r in old.spec.rules}
    kept: Set[str] = set()  # rules whose operators' history was carried
    for node in new._nodes:
        if node.behaviour:
            continue
        prev = old_rules.get(node.key)
        if prev is not None and old_sigs.get(node.key) == new.spec.rule(node.key).signature:
            _take_ops(new, prev, node)
            kept.add(node.key)
            if node.key in src.rules:
                dst.rules[node.key] = src.rules[node.key]
        elif prev is not None and _same_ops(prev, node):  # edited: its `for`/`within`/`latch` keep
            _take_ops(new, prev, node)  # their history, so an edit that still holds releases nothing
            kept.add(node.key)
    renames = _take_renamed_rules(new, old, old_rules)
    kept.update(renames.values())
    new.history_lost = []
    old_behaviours = {n.behaviour.identity: n for n in old._nodes if n.behaviour}
    new_ones: List["_Node"] = []
    for node in new._nodes:
        if not node.behaviour:
            continue
        prev = old_behaviours.pop(node.behaviour.identity, None)
        if prev is None:
            new_ones.append(node)
        else:
            took = prev.behaviour.signature == node.behaviour.signature or _same_ops(prev, node)  # type: ignore[union-attr]
            if took:
                _take_ops(new, prev, node)
            node.active, node.value = prev.active, prev.value
            if node.active:
                for a in node.actions:
                    new._holders.setdefault(a, set()).add(node.key)
                b = node.behaviour
                if carry is not None and not b.latched and _history_lost(new, node, took, kept):
                    holder = carry(b)
                    for a in node.actions:
                        new._holders[a].add(holder)
                    new.history_lost.append((b.index, holder))
    _take_condition_history(new, new_ones, list(old_behaviours.values()), renames)
    for action, holders in old._holders.items():
        outside = {h for h in holders if not h.startswith("b:")}
        if outside:
            new._holders.setdefault(action, set()).update(outside)
    new._sync_actions()
    new.orphans = [n for n in old_behaviours.values() if n.active]
    return new.evaluate_all(now)


def _history_lost(engine: "Engine", node: "_Node", took: bool, kept: Set[str]) -> bool:
    """Whether a behaviour's condition, or a rule it uses (at any depth), has `for`/`within`/
    `latch` whose history a reload could not carry: it may read false only for want of it."""
    if node.compiled.ops and not took:
        return True
    rules = {n.key: n for n in engine._nodes if not n.behaviour}
    todo = [e.key for e in ast.walk(node.behaviour.cond) if type(e) is ast.RuleRef]  # type: ignore[union-attr]
    seen: Set[str] = set()
    while todo:
        key = todo.pop()
        if key in seen or key not in rules:
            continue
        seen.add(key)
        if rules[key].compiled.ops and key not in kept:
            return True
        todo.extend(engine.spec.rule(key).rule_deps)
    return False


def _take_renamed_rules(new: "Engine", old: "Engine", old_rules: Dict[str, "_Node"]) -> Dict[str, str]:
    """A rule new to this spec (a key the old one lacks: renamed, or its entity renamed) whose
    signature is that of a rule the old spec had and this one lacks, once the rules it uses are
    renamed too, keeps that rule's value and its `for`/`within`/`latch` state: a rename is not a
    new rule, and its stop must not be released for a `for` time (found by an acceptance sweep).
    Returns the renames found (old key -> new key), in dependency order."""
    keys = {n.key for n in new._nodes if not n.behaviour}
    gone = [(r.key, r.signature) for r in old.spec.rules if r.key not in keys and r.key in old_rules]
    renames: Dict[str, str] = {}
    for node in new._nodes if gone else ():
        if node.behaviour or node.key in old_rules:
            continue
        sig, rename = new.spec.rule(node.key).signature, _renamer(renames)
        for key, old_sig in gone:
            if key not in renames and rename(old_sig) == sig:
                prev = old_rules[key]
                _take_ops(new, prev, node)
                if key in old.store.rules:
                    new.store.rules[node.key] = old.store.rules[key]
                renames[key] = node.key
                break
    return renames


def _take_ops(engine: "Engine", src: "_Node", dst: "_Node") -> None:
    """`dst`'s stateful operators take the state of `src`'s, kind by kind, and announce their deadlines."""
    for a, b in zip(src.compiled.ops, dst.compiled.ops):
        if type(a) is type(b):
            b.restore(a.snapshot())
    engine._schedule(engine._at[dst.key], dst)


def _take_condition_history(engine: "Engine", new_ones: List["_Node"], gone: List["_Node"], renames: Dict[str, str]) -> None:
    """A behaviour new to this spec whose condition reads as one the old spec's behaviours no longer
    have (renamed, its actions changed; the rules it names read under their new names): its
    `for`/`within`/`latch` keep that one's history, so a stop that held goes on (it starts at once,
    and the old one is released after it), not a `for` time later, and a `within`'s minimum hold is
    not cut short by a rename."""
    if not new_ones or not gone:
        return
    rename = _renamer(renames)
    by_text: Dict[str, "_Node"] = {}
    for prev in gone:
        if prev.compiled.ops:
            by_text.setdefault(rename(format_expr(prev.behaviour.cond)), prev)  # type: ignore[union-attr]
    for node in new_ones:
        prev = by_text.get(format_expr(node.behaviour.cond)) if node.compiled.ops else None  # type: ignore[union-attr]
        if prev is not None and _same_ops(prev, node):
            _take_ops(engine, prev, node)


def _renamer(renames: Dict[str, str]) -> Callable[[str], str]:
    """A function that writes a rule's or condition's canonical text with renamed rule keys (`e.fast`
    -> `base.fast`) in their new names: a key only as a whole name, not inside a topic, a field path
    or a longer name."""
    if not renames:
        return lambda text: text
    keys = re.compile(r"(?<![\w/.])(" + "|".join(re.escape(k) for k in sorted(renames, key=len, reverse=True))
                      + r")(?![\w])")
    return lambda text: keys.sub(lambda m: renames[m.group(1)], text)


def _same_ops(a: "_Node", b: "_Node") -> bool:
    """Whether an edited rule's stateful operators line up with its former ones (same kinds, same
    order), so that their state can carry across a reload."""
    return bool(a.compiled.ops) and [type(o) for o in a.compiled.ops] == [type(o) for o in b.compiled.ops]
