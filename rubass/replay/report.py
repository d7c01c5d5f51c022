"""What a replay found: the event lines for people, JSON lines for tools, and a summary."""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, Dict, List, TextIO, Tuple

from ..engine import Event
from ..lang.model import CheckedSpec


@dataclass
class RuleSummary:
    true: float = 0.0
    false: float = 0.0
    unknown: float = 0.0
    became_true: int = 0


@dataclass
class BehaviourSummary:
    line: int
    actions: List[str]
    fired: int = 0
    active: float = 0.0
    starts: List[float] = field(default_factory=list)


def summarise(spec: CheckedSpec, events: List[Event], end: float) -> Tuple[Dict[str, RuleSummary], Dict[int, BehaviourSummary]]:
    """How long each rule was true/false/unknown, and how often each behaviour fired."""
    rules = {r.key: RuleSummary() for r in spec.rules}
    last: Dict[str, Tuple[float, Any]] = {}
    behaviours = {b.index: BehaviourSummary(b.span.line, [a.name for a in b.actions]) for b in spec.behaviours}
    since: Dict[int, float] = {}
    for e in events:
        if e.kind == "rule":
            if e.rule in last:
                _add(rules[e.rule], last[e.rule][1], e.time - last[e.rule][0])
            if e.value is True:
                rules[e.rule].became_true += 1
            last[e.rule] = (e.time, e.value)
        elif e.kind == "start":
            behaviours[e.behaviour].fired += 1
            behaviours[e.behaviour].starts.append(e.time)
            since[e.behaviour] = e.time
        elif e.kind == "release" and e.behaviour in since:
            behaviours[e.behaviour].active += e.time - since.pop(e.behaviour)
    for key, (t, v) in last.items():
        _add(rules[key], v, end - t)
    for index, t in since.items():
        behaviours[index].active += end - t
    return rules, behaviours


def _add(s: RuleSummary, value: Any, dt: float) -> None:
    if value is True:
        s.true += dt
    elif value is False:
        s.false += dt
    else:
        s.unknown += dt


def json_lines(events: List[Event], out: TextIO) -> None:
    """One object per line, in time order: start, release, and every change of a rule."""
    for e in events:
        if e.kind in ("start", "release"):
            obj: Dict[str, Any] = {"time": e.time, "event": e.kind, "behaviour": e.behaviour, "line": e.line,
                                   "actions": list(e.actions)}
            if getattr(e, "name", ""):
                obj["name"] = e.name
            witness = getattr(e, "witness", None)
            if witness is not None:  # why it started: true rules, the values they read (docs/replay.md)
                obj.update(witness.as_json())
        elif e.kind == "rule":
            obj = {"time": e.time, "event": "rule", "rule": e.rule, "value": e.value}
        else:
            continue
        out.write(json.dumps(obj) + "\n")


def human(spec: CheckedSpec, events: List[Event], end: float, out: TextIO) -> None:
    """Each start and release, then a summary per rule and per behaviour."""
    for e in events:
        if e.kind == "start":
            witness = getattr(e, "witness", None)
            name = getattr(e, "name", "") or (witness.name if witness is not None else "")
            name = f" {name}" if name else ""
            out.write(f"{e.time:10.3f} s  start    behaviour {e.behaviour}{name} (line {e.line}): {', '.join(e.actions)}\n")
            if witness is not None:
                for label, values in sorted(witness.attrs):
                    out.write(f"{'':14}@{label}: {', '.join(values)}\n")
                if witness.rules:
                    out.write(f"{'':14}true: {', '.join(witness.rules)}\n")
                if witness.false_rules:  # read under `not`: their being false is the cause
                    out.write(f"{'':14}false: {', '.join(witness.false_rules)}\n")
                for reading in witness.readings:
                    out.write(f"{'':14}{reading.text()}\n")
        elif e.kind == "release":
            name = f" {e.name}" if getattr(e, "name", "") else ""
            out.write(f"{e.time:10.3f} s  release  behaviour {e.behaviour}{name} (line {e.line})\n")
    rules, behaviours = summarise(spec, events, end)
    width = max([len(k) for k in rules] + [4])
    out.write(f"\nrules over {end:.3f} s:\n")
    out.write(f"  {'rule':<{width}}  {'true':>10}  {'false':>10}  {'unknown':>10}  {'turned true':>11}\n")
    for key, s in rules.items():
        out.write(f"  {key:<{width}}  {s.true:>9.3f}s  {s.false:>9.3f}s  {s.unknown:>9.3f}s  {s.became_true:>11}\n")
    out.write("behaviours:\n")
    names = {x.index: f" {x.name}" if x.name else "" for x in spec.behaviours}
    for index, b in behaviours.items():
        out.write(f"  {index}.{names.get(index, '')} line {b.line} ({', '.join(b.actions) or 'no actions'}): fired {b.fired} time"
                  f"{'s' if b.fired != 1 else ''}, active {b.active:.3f} s\n")
