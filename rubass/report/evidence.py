"""What a report shows, gathered: the spec's traceability, test results, bag replays, measured reaction."""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Set, Tuple


from ..lang.errors import RubassError
from ..engine import Event
from ..lang import ast
from ..lang.attributes import entity_ids, rule_ids
from ..lang.model import CheckedSpec
from ..lang.topicnames import resolve, spellings
from ..testing.coverage import Coverage, coverage
from ..testing.results import FileResult
from ..testing.runner import Outcome
from .bench import Reaction
from .hazards import Hazard, HazardsError, read_hazards  # noqa: F401 (the report's inputs, read here)


class ReportError(RubassError):
    """An input of the report that cannot be used; the message says which and why."""


@dataclass
class BagRun:
    path: str
    duration: float = 0.0
    messages: int = 0
    events: List[Event] = field(default_factory=list)
    error: str = ""
    warnings: List[str] = field(default_factory=list)
    type_errors: List[str] = field(default_factory=list)  # the spec against the recording's types, printed as is
    spec_warnings: List[str] = field(default_factory=list)  # the spec's, read against the recording, rendered


@dataclass
class Row:
    """One line of the traceability matrix: a hazard and one rule (or none) for it; or a rule that traces
    to no hazard (hazard None)."""

    hazard: Optional[Hazard]
    rule: Optional[str]  # rule key; None: the hazard has no rule
    behaviours: List[str]
    tests: List[Outcome]
    gaps: List[str]


@dataclass
class Evidence:
    spec: CheckedSpec
    hazards: List[Hazard]
    results: List[FileResult]
    bags: List[BagRun]
    reaction: Optional[Reaction]
    matrix: List[Row] = field(default_factory=list)
    coverage: Optional[Coverage] = None

    @property
    def outcomes(self) -> List[Outcome]:
        """The outcomes of the tests of this spec (a file testing another spec is not evidence for it)."""
        return [o for r in self.results if self.same_spec(r) for o in r.outcomes]

    @property
    def untraced(self) -> List[str]:
        """The rules that trace to no hazard (rows of the matrix with no hazard)."""
        return [row.rule for row in self.matrix if row.hazard is None and row.rule is not None]

    def same_spec(self, r: FileResult) -> bool:
        return r.spec is not None and os.path.realpath(r.spec.path) == os.path.realpath(self.spec.path)


def attrs(owner: Any) -> Dict[str, Sequence[str]]:
    return getattr(owner, "attrs", None) or {}


def rule_ids_of(spec: CheckedSpec, rule: Any) -> Tuple[str, ...]:
    """The ids that name a rule: its own @id, else its entity's (a test covering the entity covers it)."""
    return rule_ids(attrs(rule), entity_ids(spec.spec).get(rule.entity))


def behaviour_label(spec: CheckedSpec, index: int) -> str:
    b = spec.behaviours[index - 1]
    return b.name if getattr(b, "name", "") else f"behaviour {index}"


def _rules_used(spec: CheckedSpec, expr: ast.Expr) -> Set[str]:
    """Rules an expression uses, directly or through other rules."""
    by_key = {r.key: r for r in spec.rules}
    out: Set[str] = set()
    stack = [e.key for e in ast.walk(expr) if isinstance(e, ast.RuleRef)]
    while stack:
        k = stack.pop()
        if k in out or k not in by_key:
            continue
        out.add(k)
        stack.extend(by_key[k].rule_deps)
    return out


def build_matrix(ev: Evidence) -> None:
    """Hazard -> rule -> behaviour -> test, with the gaps marked."""
    spec = ev.spec
    known = {h.id for h in ev.hazards}
    for owner in list(spec.rules) + list(spec.behaviours):
        for hz in attrs(owner).get("hazard", ()):
            if hz not in known:
                ev.hazards.append(Hazard(hz, "(named in the spec, not in the risk table)"))
                known.add(hz)
    uses = {b.index: _rules_used(spec, b.cond) for b in spec.behaviours}
    outcomes = ev.outcomes
    for h in ev.hazards:
        rules = [r for r in spec.rules if h.id in attrs(r).get("hazard", ())]
        direct_b = [b for b in spec.behaviours if h.id in attrs(b).get("hazard", ())]
        if not rules and not direct_b:
            tests = covering(outcomes, [h.id])
            ev.matrix.append(Row(h, None, [], tests, ["no rule"] + _failing(tests)))
            continue
        for r in rules:
            users = [b for b in spec.behaviours if r.key in uses[b.index]]
            ids = list(rule_ids_of(spec, r))
            row = _row(h, r.key, [behaviour_label(spec, b.index) for b in users], ids, outcomes, not users)
            row.gaps += _uncovered_rules(spec, _rules_used(spec, ast.RuleRef(r.key)) - {r.key}, outcomes)
            if outcomes and not any(r.key in o.rules_true for o in outcomes):
                row.gaps.append("never true in any test")  # as the coverage's "rules never true"
            ev.matrix.append(row)
        for b in direct_b:
            if any(r.key in uses[b.index] for r in rules):
                continue  # shown with its rule
            ids = list(attrs(b).get("id", ()))
            row = _row(h, None, [behaviour_label(spec, b.index)], ids, outcomes, False)
            row.gaps += _uncovered_rules(spec, uses[b.index], outcomes)
            if outcomes and not any(b.index in o.started for o in outcomes):
                row.gaps.append("never started in any test")  # as the coverage's "behaviours never started"
            ev.matrix.append(row)
    traced = _traced_rules(spec)
    for r in spec.rules:
        if r.key not in traced:
            ev.matrix.append(_untraced_row(ev, r, [b for b in spec.behaviours if r.key in uses[b.index]]))
    if outcomes:
        ev.coverage = coverage(spec, outcomes)


def _traced_rules(spec: CheckedSpec) -> Set[str]:
    """The rules that trace to a hazard: those with @hazard (their own or their entity's), and the rules
    they or a behaviour with @hazard use (a helper rule traces to the hazards of the rules built on it)."""
    out: Set[str] = set()
    for r in spec.rules:
        if attrs(r).get("hazard"):
            out |= _rules_used(spec, ast.RuleRef(r.key))
    for b in spec.behaviours:
        if attrs(b).get("hazard"):
            out |= _rules_used(spec, b.cond)
    return out


def _untraced_row(ev: Evidence, r: Any, users: List[Any]) -> Row:
    """A rule that traces to no hazard: a gap of its own, with the rule's other gaps beside it."""
    ids = list(rule_ids_of(ev.spec, r))
    outcomes = ev.outcomes
    tests = covering(outcomes, ids) if ids else []
    gaps = ["traces to no hazard"] + (["no behaviour acts on it"] if not users else [])
    if not tests:
        gaps.append(f"no test covers {' or '.join(ids)}" if ids else "no test covers it (it has no @id)")
    if outcomes and not any(r.key in o.rules_true for o in outcomes):
        gaps.append("never true in any test")
    return Row(None, r.key, [behaviour_label(ev.spec, b.index) for b in users], tests, gaps + _failing(tests))


def covering(outcomes: List[Outcome], names: Sequence[str]) -> List[Outcome]:
    """The tests whose `covers` names one of `names`: the one meaning of "covered", shared with
    `rubass test --coverage` (a test that only happens to make a rule true covers nothing)."""
    return [o for o in outcomes if set(names) & set(o.counted_covers)]  # one that expects nothing proves nothing


def _row(h: Hazard, rule: Optional[str], behaviours: List[str], ids: List[str], outcomes: List[Outcome],
         no_behaviour: bool) -> Row:
    """A matrix row: the tests that cover the rule's (or behaviour's) ids, or the hazard when it has no id;
    a gap for each of those names and the hazard that no test covers, as the coverage lists them."""
    tests = covering(outcomes, ids or [h.id])
    gaps = ["no behaviour acts on it"] if no_behaviour else []
    if not tests:
        gaps.append(f"no test covers {' or '.join(ids)}" if ids else f"no test (none covers {h.id})")
    if ids and not covering(outcomes, [h.id]):
        gaps.append(f"no test covers hazard {h.id}")
    return Row(h, rule, behaviours, tests, gaps + _failing(tests))


def _uncovered_rules(spec: CheckedSpec, keys: Set[str], outcomes: List[Outcome]) -> List[str]:
    """A gap for each rule in `keys` (the rules a row's rule or behaviour uses) whose ids no test covers:
    the coverage lists it, so the row that rests on it is not covered (a rule with no id is covered with
    the row it serves)."""
    out = []
    for key in sorted(keys):
        ids = list(rule_ids_of(spec, spec.rule(key)))
        if ids and not covering(outcomes, ids):
            out.append(f"no test covers {' or '.join(ids)} (rule {key}, used here)")
    return out


def _failing(tests: List[Outcome]) -> List[str]:
    return [f"test '{o.name}' fails" for o in tests if not o.passed]


def replay_bag(spec: CheckedSpec, path: str, rate: float = 50.0, actions: Sequence[str] = ()) -> BagRun:
    """The spec over a recording, as `rubass replay` runs it; not replayed (`error`, `type_errors`) when the
    spec cannot read the recording's types, as `rubass replay` and `rubass check --bag` refuse it."""
    from ..replay.command import bag_check
    from ..replay.run import replay
    from ..ros.bag import BagError, open_bag, read

    run = BagRun(path)
    try:
        bag, info = open_bag(path)
    except BagError as exc:
        run.error = str(exc)
        return run
    with bag:
        names = spellings(spec.topics)  # bag name -> every spelling of it in the spec, as replay feeds them
        present = [t for t in names if t in info.types]
        run.warnings = [f"topic {t} is not in the recording; its fields stay unknown and its age() grows from "
                        f"the recording's start" for t in sorted(names)
                        if t not in info.types]
        strings = [t for t, ty in info.types.items() if ty == "std_msgs/String"] if spec.nodes else []
        node_topics = sorted(t for t in strings if t.endswith("/node_samples"))
        agent_topics = sorted(t for t in strings if t.endswith("/agent_samples"))
        decode = {t for t in present if any(spec.topics[n].needs_data for n in names[t])} | set(node_topics) | \
            set(agent_topics)
        run.type_errors, run.spec_warnings = bag_check(spec, spec.path, actions, bag, path, info, decode,
                                                       "rubass report")
        if run.type_errors:
            run.warnings = []
            run.error = (f"not replayed: {os.path.basename(spec.path)} cannot read this recording's types "
                         f"(as `rubass check --bag` and `rubass replay` say):")
            return run
        try:
            run.warnings += unsampled_nodes(spec, bag, node_topics, agent_topics)
        except BagError as exc:
            run.error = str(exc)
            return run
        stream: Any = ((t, name, msg) for t, topic, msg in read(bag, present + node_topics + agent_topics, decode)
                       for name in names.get(topic, (topic,)))
        try:
            if agent_topics:  # multi-host: the agents' reports, as `rubass replay` reads them
                from ..replay.agents import SAMPLES, agent_samples
                from ..replay.command import _sampled_nodes

                skip = _sampled_nodes(read(bag, node_topics, set(node_topics)))
                nodes = {resolve(n): n for n in spec.nodes}
                stream = agent_samples(stream, set(agent_topics), nodes, skip, info.end)
                node_topics = node_topics + [SAMPLES]
            _, run.events = replay(spec, stream, info.start, info.end, rate, node_topics)
        except BagError as exc:
            run.error = str(exc)
            return run
    run.duration, run.messages = info.end - info.start, info.messages
    return run


def unsampled_nodes(spec: CheckedSpec, bag: Any, node_topics: List[str], agent_topics: List[str]) -> List[str]:
    """`rubass replay`'s warning for each node of the spec that no recorded node sample covers (when the
    recording has some), as text; BagError if the bag cannot be read."""
    from ..replay.command import unsampled_warnings

    if not spec.nodes or not (node_topics or agent_topics):
        return []
    return unsampled_warnings(spec.nodes, bag, node_topics, agent_topics)


def spec_text(spec: CheckedSpec, span: Any) -> str:
    """The source text at a span (a rule's or a behaviour's own text)."""
    src = spec.sources.get(span.file) if getattr(spec, "sources", None) is not None else None
    if src is not None and span.end > span.start:
        return src.text[span.start:span.end].strip()
    try:
        with open(span.file, encoding="utf-8") as fh:
            return fh.read().splitlines()[span.line - 1].strip()
    except (OSError, IndexError):
        return ""


def hazards_via_rules(spec: CheckedSpec, b: Any) -> List[str]:
    """Hazards of the rules a behaviour uses (directly or through other rules)."""
    out: List[str] = []
    for key in sorted(_rules_used(spec, b.cond)):
        for h in attrs(spec.rule(key)).get("hazard", ()):
            if h not in out:
                out.append(h)
    return out
