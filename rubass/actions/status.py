"""What the monitor reports in /diagnostics: one status per entity and one for itself.

Pure: built from plain snapshots, so it is tested without ROS.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

from ..lang import ast
from ..lang.errors import counted
from ..lang.fmt import format_attrs
from ..lang.model import CheckedSpec

OK, WARN, ERROR = 0, 1, 2  # DiagnosticStatus levels
# an action's last error once a later attempt succeeded: kept for the record, no longer an ERROR
RESOLVED = "resolved (a later attempt succeeded); was: "
# what a plugin's start, hold or release returns when it did nothing this time by its configuration (a
# service not called in that phase, a release with no `on_release`): a success that resolves no failure,
# so that a failed start is not shown fixed by a release that proved nothing
NOTHING_DONE = "nothing done"
# node references: NodeRef (version 1), NodeStat (alive/cpu/memory in version 2 of the language)
_NODE_REFS = tuple(getattr(ast, n) for n in ("NodeRef", "NodeStat") if hasattr(ast, n))


@dataclass
class Entry:
    name: str
    level: int
    message: str
    values: List[Tuple[str, str]] = field(default_factory=list)


def _text(v: Any) -> str:
    return "unknown" if v is None or (v is not True and v is not False) else ("true" if v else "false")


def topic_shown(name: str, resolved: Optional[str], written_in: str = "the spec") -> str:
    """A topic (or service) as the robot names it (namespace and remappings applied), and as `written_in`
    wrote it when that is more than a leading '/' away: `/base/cmd_vel (cmd_vel in the spec)`."""
    if not resolved or resolved == name:
        return name
    if resolved == "/" + name.lstrip("/"):
        return resolved
    return f"{resolved} ({name} in {written_in})"


def unknown_reasons(spec: CheckedSpec, rule_key: str, topics: Dict[str, Dict[str, Any]],
                    nodes: Dict[str, Dict[str, Any]], field_errors: Dict[Tuple[str, str], str]) -> List[str]:
    """Why a rule may be unknown: silent topics, bad fields, unmeasurable nodes."""
    why: List[str] = []
    for e in ast.walk(spec.rule(rule_key).expr):
        if isinstance(e, ast.TopicRef) and e.path:
            t = topics.get(e.topic, {})
            if not t.get("messages"):
                why.append(f"no message on {topic_shown(e.topic, t.get('resolved'))} yet")
            for err in t.get("errors", []):
                why.append(err)
            fe = field_errors.get((e.topic, str(e.path)))
            if fe:
                resolved, field = t.get("resolved") or e.topic, ast.path_suffix(e.path)
                if topic_shown(e.topic, resolved) in (e.topic, resolved):  # one name, or a leading '/' more
                    why.append(f"rule '{rule_key}' reads {resolved}{field}: {fe}")
                else:  # moved by a namespace or a remap
                    why.append(f"rule '{rule_key}' reads {e.topic}{field} (on {resolved}): {fe}")
        elif isinstance(e, _NODE_REFS):
            n = nodes.get(e.node)
            if n is not None and n.get("why") not in (None, "alive"):
                why.append(f"node {topic_shown(e.node, n.get('resolved'))}: {n['why']}")
    return sorted(set(why))


# what holds the robot apart from the active behaviours: latched actions kept across a reload or a clock
# jump, and those restored at start (actions/keeper.py)
HELD = ("held over a reload or clock jump (until ~reset)", "latched at start (until ~reset)")
ELSEWHERE = "latched under another master's name"  # actions/keeper.py: WARN until ~reset


def _behaviour(spec: CheckedSpec, index: int) -> str:
    """An active behaviour as /diagnostics lists it: its number, and its name and attributes (§14, §15)."""
    b = spec.behaviours[index - 1] if 0 < index <= len(spec.behaviours) else None
    extra = " ".join(x for x in (b.name, format_attrs(b.attrs)) if x) if b is not None else ""
    return f"{index} ({extra})" if extra else str(index)


def build(spec: CheckedSpec, rules: Dict[str, Any], active: List[int], topics: Dict[str, Dict[str, Any]],
          nodes: Dict[str, Dict[str, Any]], field_errors: Dict[Tuple[str, str], str],
          monitor: Dict[str, Any], failing: Sequence[Tuple[str, str]] = (),
          computed: Optional[Dict[str, List[str]]] = None) -> List[Entry]:
    """Entries for every entity (WARN while one of its rules is true, ERROR on data errors) and the
    monitor; `failing`: (name, error) of the actions whose latest attempt failed (ERROR meanwhile);
    `computed`: rule -> why its expression is unknown from values that came (engine/unknowns.py)."""
    out: List[Entry] = []
    by_entity: Dict[str, List[str]] = {}
    attrs = {r.key: r.attrs for r in spec.rules}
    for r in spec.rules:
        by_entity.setdefault(r.entity, []).append(r.key)
    for entity, keys in by_entity.items():
        values: List[Tuple[str, str]] = []
        true_rules, unknown, errors = [], [], []
        for key in keys:
            v = rules.get(key)
            values.append((key.split(".", 1)[1], _text(v)))
            if attrs.get(key):  # §15: its traceability, beside its value
                values.append((f"{key.split('.', 1)[1]} attributes", format_attrs(attrs[key])))
            reasons = unknown_reasons(spec, key, topics, nodes, field_errors)
            # a field it cannot read is an error whatever its value (`false and unknown` is false)
            errors += [r for r in reasons if "reads" in r or "deserialise" in r]
            if v is True:
                true_rules.append(key)
            elif v is not False:
                errors += [r for r in reasons if "changed type" in r]  # a mere change is no error of a rule it leaves known
                unknown.append(key)
                reasons = reasons + [r for r in (computed or {}).get(key, ()) if r not in reasons]
                if reasons:
                    values.append((f"{key.split('.', 1)[1]} unknown because", "; ".join(reasons)))
        if errors:  # named: the rule, the field and what is wrong
            first = min(set(errors), key=lambda e: ("changed type" in e, e))  # what a rule cannot read first
            level, msg = ERROR, f"DATA ERROR: {first}" + (
                f" (and {len(set(errors)) - 1} more)" if len(set(errors)) > 1 else "")
        elif true_rules:
            level, msg = WARN, "violated: " + ", ".join(k.split(".", 1)[1] for k in true_rules)
        elif unknown:
            level, msg = OK, "unknown: " + ", ".join(k.split(".", 1)[1] for k in unknown)
        else:
            level, msg = OK, "all rules false"
        out.append(Entry(f"rubass: {entity}", level, msg, values))
    mvalues = [(k, str(v)) for k, v in monitor.items()]
    mvalues.append(("active behaviours", ", ".join(_behaviour(spec, i) for i in active) or "none"))
    level = ERROR if monitor.get("last reload error") or failing else OK
    if monitor.get("latch state error"):  # a latched stop may not survive a restart, or one was restored blind
        level = ERROR
        msg_latch = f" (latch state: {monitor['latch state error']})"
    else:
        msg_latch = ""
    if monitor.get("data errors", "none") != "none":  # a rule that cannot read its field protects nothing
        level = ERROR
        msg_latch += f" (DATA ERROR: {monitor['data errors']})"
    live = monitor.get("spec errors against the live types", "none")
    if live != "none":  # the spec has an error `rubass check --live` would give; the rule still runs on its numbers
        level = ERROR
        msg_latch += f" (SPEC ERROR against the live message types: {live})"
    msg = f"enforcing {spec.path}: {counted(len(spec.rules), 'rule')}, {counted(len(spec.behaviours), 'behaviour')}"
    if monitor.get("overloaded", "no") != "no":
        level = ERROR
        cause = monitor.get("overload cause", "none")
        msg += f" (OVERLOADED, {cause if cause != 'none' else 'dropping messages'}: {monitor['overloaded']})"
    if monitor.get("read late", "no") != "no":  # the rules see the robot that late (overload, without drops)
        level = max(level, WARN)
        msg += f" (READ LATE: {monitor['read late']})"
    if str(monitor.get("master", "connected")) != "connected":
        level = max(level, WARN)
        msg += f" (master {monitor['master']})"
    if monitor.get("silent agents", "none") not in ("none", ""):  # cpu/memory of that host's nodes unknown
        level = max(level, WARN)
        msg += f" (agent silent: {monitor['silent agents']})"
    if monitor.get("agents claiming one host", "none") not in ("none", ""):  # whose values are used is unclear
        level = max(level, WARN)
        msg += f" ({monitor['agents claiming one host']})"
    latched = sorted({a.action.name for b in spec.behaviours for a in b.actions if a.action.latch})
    if latched and str(monitor.get("latch state file", "")).startswith("off"):  # ~state_file: false (maybe a leftover)
        level = max(level, WARN)
        msg += (f" (LATCH PERSISTENCE OFF: ~state_file is false, so a latched stop ({', '.join(latched)}) will not "
                f"survive a restart of the monitor; a private parameter stays on the master for later runs)")
    if monitor.get(ELSEWHERE):  # this master spelt otherwise in ROS_MASTER_URI since the last run, maybe
        level = max(level, WARN)
        msg += (f" (LATCHED UNDER ANOTHER MASTER'S NAME: {monitor[ELSEWHERE]} holds a latched stop of this node; "
                f"if that is this robot's master spelt otherwise, restart with ~state_file:= that file; ~reset "
                f"acknowledges)")
    held = "; ".join(monitor[k] for k in HELD if monitor.get(k))
    if held:  # held by nothing the rules now say (a reload, a clock jump, a restart): only ~reset releases it
        level = max(level, WARN)
        msg += f" (HOLDING until ~reset: {held})"
    if monitor.get("last reload error"):
        msg += " (the last reload was rejected; the previous rules still run)"
    if failing:
        msg += " (ACTION FAILING: " + "; ".join(f"{name}: {error}" for name, error in failing) + ")"
    msg += msg_latch
    out.append(Entry("rubass: monitor", level, msg, mvalues))
    return out


def failing_of(stats: Dict[str, Any]) -> List[Tuple[str, str]]:
    """(name, error) of the actions whose latest attempt failed, from each action's ActionStats
    (`failing` is the phase that failed; a later success clears it, the error stays on record)."""
    return [(name, st.last_error) for name, st in stats.items() if st.failing]


def not_enforcing(spec_path: str, error: str, reloads: int, rejected: int) -> List[Entry]:
    """The monitor's only status while no spec could be used: ERROR, naming the file and the error."""
    first = error.splitlines()[0] if error else "no spec loaded"
    return [Entry("rubass: monitor", ERROR, f"NOT ENFORCING ANY RULE: {first}",
                  [("spec", spec_path), ("error", error), ("reloads", str(reloads)),
                   ("rejected reloads", str(rejected)), ("heartbeat", "not published until a usable spec is loaded")])]


def waiting_for_clock(spec_path: str, waited: float, held: Sequence[str] = ()) -> List[Entry]:
    """The monitor's only status while use_sim_time is true and no /clock message has come: ERROR
    (ROS time is 0, nothing is watched or enforced; a use_sim_time left set on a real robot looks so)."""
    return [Entry("rubass: monitor", ERROR,
                  f"NOT ENFORCING ANY RULE: use_sim_time is true and no /clock message has come for {waited:.1f} s: "
                  f"waiting for the first one (no rule is evaluated until then; is /use_sim_time left set?)",
                  [("spec", spec_path), ("use_sim_time", "true"), ("waiting for /clock", f"{waited:.1f} s"),
                   ("heartbeat", "not published until the first /clock message"),
                   ("latched at start (until ~reset)", "; ".join(held) or "none")])]
