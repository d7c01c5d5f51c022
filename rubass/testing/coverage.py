"""Coverage over test results: rules never true, behaviours never started, ids and hazards untested."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import List, Set, Tuple

from ..lang.attributes import entity_ids
from ..lang.model import CheckedSpec
from .runner import Outcome


@dataclass
class Coverage:
    spec: str
    tests: int
    rules_never_true: List[str] = field(default_factory=list)
    behaviours_never_started: List[str] = field(default_factory=list)
    ids_untested: List[str] = field(default_factory=list)
    hazards_untested: List[str] = field(default_factory=list)


def traced(spec: CheckedSpec) -> Tuple[List[str], List[str]]:
    """The spec's @id values (entities, rules and behaviours) and @hazard values (rules, with inherited
    ones, and behaviours), in order."""
    ids: List[str] = []
    hazards: List[str] = []
    by_entity = entity_ids(spec.spec)
    for owner in list(spec.rules) + list(spec.behaviours):
        attrs = getattr(owner, "attrs", None) or {}
        entity_id = by_entity.get(getattr(owner, "entity", ""))
        for v in ((entity_id,) if entity_id else ()) + tuple(attrs.get("id", ())):
            if v not in ids:
                ids.append(v)
        for v in attrs.get("hazard", ()):
            if v not in hazards:
                hazards.append(v)
    ids += [v for v in by_entity.values() if v not in ids]  # an entity with no rule
    return ids, hazards


def behaviour_label(spec: CheckedSpec, index: int) -> str:
    b = spec.behaviours[index - 1]
    return b.name if getattr(b, "name", "") else f"behaviour {index} (line {b.span.line})"


def coverage(spec: CheckedSpec, outcomes: List[Outcome]) -> Coverage:
    """Coverage of one spec by the outcomes (runner.Outcome) of all tests that ran on it."""
    true: Set[str] = set()
    started: Set[int] = set()
    covers: Set[str] = set()
    for o in outcomes:
        true |= o.rules_true
        started |= o.started
        covers |= set(o.counted_covers)  # a test that expects nothing proves nothing
    ids, hazards = traced(spec)
    return Coverage(spec.path, len(outcomes),
                    [r.key for r in spec.rules if r.key not in true],
                    [behaviour_label(spec, b.index) for b in spec.behaviours if b.index not in started],
                    [i for i in ids if i not in covers], [h for h in hazards if h not in covers])


def render(cov: Coverage) -> str:
    from .results import shown_path  # results builds on this module

    def line(title: str, items: List[str]) -> str:
        return f"  {title}: {', '.join(items) if items else 'none'}"

    return "\n".join([f"coverage of {shown_path(cov.spec)} ({cov.tests} test{'s' if cov.tests != 1 else ''}):",
                      line("rules never true", cov.rules_never_true),
                      line("behaviours never started", cov.behaviours_never_started),
                      line("ids no test covers", cov.ids_untested),
                      line("hazards no test covers", cov.hazards_untested)])


def unknown_covers(spec: CheckedSpec, names: List[str]) -> List[str]:
    ids, hazards = traced(spec)
    return [n for n in names if n not in ids and n not in hazards]


