"""The report as one self-contained HTML page: inline CSS and SVG, no script, no external file."""
from __future__ import annotations

import datetime
import os
import platform
from html import escape
from typing import Any, Iterable, List, Sequence

from ..lang import ast
from .design import design, up
from .evidence import Evidence, attrs, behaviour_label, hazards_via_rules, rule_ids_of, spec_text
from .timeline import svg

CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",sans-serif;margin:2em auto;max-width:1100px;color:#222;
  line-height:1.4;padding:0 1em}
h1{font-size:1.6em;margin-bottom:.2em}h2{border-bottom:2px solid #ddd;padding-bottom:.2em;margin-top:1.8em}
table{border-collapse:collapse;width:100%;margin:.6em 0;font-size:.92em}
th,td{border:1px solid #ccc;padding:.3em .5em;text-align:left;vertical-align:top}
th{background:#f3f3f3}code,pre{font-family:ui-monospace,Menlo,Consolas,monospace;font-size:.9em}
pre{background:#f7f7f7;padding:.5em;overflow-x:auto;margin:.2em 0;white-space:pre-wrap}
.pass{color:#1a7f37;font-weight:bold}.fail{color:#c62828;font-weight:bold}
.gap{background:#fde7e7}.ok{background:#e8f5e9}.muted{color:#777}
.summary{display:flex;gap:1em;flex-wrap:wrap}.card{border:1px solid #ccc;border-radius:6px;padding:.6em 1em;min-width:12em}
.card b{font-size:1.4em;display:block}
.w{font-family:ui-monospace,Menlo,Consolas,monospace;font-size:.88em}
"""


def _shown(path: str) -> str:
    rel = os.path.relpath(path)
    return path if rel.startswith("..") else rel


def _e(text: Any) -> str:
    return escape(str(text))


def _list(items: Iterable[str]) -> str:
    items = list(items)
    return ", ".join(_e(i) for i in items) if items else '<span class="muted">—</span>'


def _attr(owner: Any, key: str) -> str:
    return _list(attrs(owner).get(key, ()))


def _rule_id(ev: Evidence, rule: Any) -> str:
    """A rule's id: its own, else its entity's, marked as the entity's."""
    if attrs(rule).get("id"):
        return _attr(rule, "id")
    ids = rule_ids_of(ev.spec, rule)
    return f"{_list(ids)} <span class='muted'>(entity {_e(rule.entity)})</span>" if ids else _list([])


def _table(head: Sequence[str], rows: List[str]) -> str:
    return ("<table><thead><tr>" + "".join(f"<th>{_e(h)}</th>" for h in head) + "</tr></thead><tbody>"
            + "".join(rows) + "</tbody></table>")


def render(ev: Evidence) -> str:
    spec = ev.spec
    outcomes = ev.outcomes
    passed = sum(o.passed for o in outcomes)
    failed = len(outcomes) - passed
    gaps = sum(1 for row in ev.matrix if row.gaps)
    errors = [r for r in ev.results if r.error]
    foreign = [r for r in ev.results if not r.error and not ev.same_spec(r)]
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    out = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>Safety evidence: "
           f"{_e(os.path.basename(spec.path))}</title><style>{CSS}</style></head><body>",
           f"<h1>Safety evidence for <code>{_e(os.path.basename(spec.path))}</code></h1>",
           f"<p class='muted'>{_e(spec.path)} · generated {now} by rubass report on {_e(platform.node())} "
           f"({_e(platform.machine())}, Python {_e(platform.python_version())})</p>"]
    untraced = len(ev.untraced)
    untraced_note = (f"<br><span class='fail'>{untraced} rule{' traces' if untraced == 1 else 's trace'} to no "
                     f"hazard</span>" if untraced else "")
    out.append("<div class='summary'>"
               f"<div class='card'><b>{len(ev.hazards)}</b>hazard{'s' if len(ev.hazards) != 1 else ''}</div>"
               f"<div class='card'><b>{len(spec.rules)} / {len(spec.behaviours)}</b>rules / behaviours</div>"
               f"<div class='card'><b class='{'fail' if failed or errors or foreign else 'pass'}'>{passed} passed, "
               f"{failed} failed</b>tests{f', {len(errors)} file(s) could not run' if errors else ''}"
               f"{f', {len(foreign)} file(s) of another spec not counted' if foreign else ''}</div>"
               f"<div class='card'><b class='{'fail' if gaps else 'pass'}'>{gaps}</b>gap{'s' if gaps != 1 else ''} in the matrix"
               f"{untraced_note}</div>"
               f"<div class='card'>{_reaction_card(ev)}</div>{_bags_card(ev)}</div>")
    out += _matrix(ev), _rules(ev), _behaviours(ev), _tests(ev), _bags(ev)
    out.append("</body></html>")
    return "\n".join(out)


def _bags_card(ev: Evidence) -> str:
    """Recordings replayed, and, in red, those that could not be (unreadable, or types the spec cannot read)."""
    if not ev.bags:
        return ""
    bad = sum(1 for b in ev.bags if b.error)
    return (f"<div class='card'><b class='{'fail' if bad else 'pass'}'>{len(ev.bags) - bad} / {len(ev.bags)}</b>"
            f"recordings replayed{f', <span class=fail>{bad} not replayed</span>' if bad else ''}</div>")


def _reaction_card(ev: Evidence) -> str:
    r = ev.reaction
    if r is None:
        return "<b>n/a</b>no benchmark figures"
    where = (f"the developers' figures{f' of {_e(r.date)}' if r.date else ''} (bench/README.md), "
             f"<span class='fail'>not measured on this machine</span>" if r.developers else
             f"measured: {_e(r.source)}{f': {_e(r.extent)}' if r.extent else ''}")
    return f"<b>≤ {up(r.worst_ms)} ms</b>monitor's worst case ({_e(r.p99_label())} {up(r.p99_ms)} ms); {where}"


def _matrix(ev: Evidence) -> str:
    rows = []
    for row in ev.matrix:
        h = row.hazard
        if h is None:
            hazard_cell = ("<b class='fail'>no hazard</b><br><span class='muted'>neither the rule nor any rule or "
                           "behaviour using it names a <code>@hazard</code></span>")
        else:
            details = "; ".join(f"{k}: {v}" for k, v in h.details.items())
            hazard_cell = f"<b>{_e(h.id)}</b> {_e(h.title)}<br><span class='muted'>{_e(details)}</span>"
        rule = ev.spec.rule(row.rule) if row.rule else None
        rule_cell = (f"<code>{_e(row.rule)}</code><br>{_rule_id(ev, rule)} {_e(' '.join(attrs(rule).get('title', ())))}"
                     if rule is not None else '<span class="muted">—</span>')
        tests = "<br>".join(f"<span class='{'pass' if o.passed else 'fail'}'>{'✔' if o.passed else '✘'}</span> "
                            f"{_e(o.name)}" for o in row.tests) or '<span class="muted">—</span>'
        status = ("<td class='gap'>" + "<br>".join(_e(g) for g in row.gaps) + "</td>") if row.gaps \
            else "<td class='ok'>covered</td>"
        rows.append(f"<tr><td>{hazard_cell}</td>"
                    f"<td>{rule_cell}</td><td>{_list(row.behaviours)}</td><td>{tests}</td>{status}</tr>")
    note = ("<p>Each hazard of the risk assessment, the rules that detect it (<code>@hazard</code>), the behaviours "
            "that act on those rules, and the tests that cover them. <b>Covered</b> means named in a test's "
            "<code>covers</code>, as in the coverage below: a rule by its <code>@id</code> (its entity's when it has "
            "none; the hazard's when neither has one), and the hazard by its own id. A test that only makes a rule true "
            "covers nothing. Gaps are marked red: a hazard with no rule, a rule or hazard no test covers, a failing "
            "test, a rule no behaviour acts on, a rule no test made true, and a rule that traces to no hazard (no "
            "<code>@hazard</code> on it, its entity, or any rule or behaviour that uses it), listed after the "
            "hazards.</p>")
    return "<h2 id='matrix'>Hazard → rule → behaviour → test</h2>" + note + \
        _table(["hazard", "rule", "behaviours", "tests", "status"], rows)


DESIGN_NOTE = ("A reaction by design is the time on the slowest path from the inputs to the value (an upper "
               "bound): each <code>for</code> adds its time; a comparison of ages adds the time after the last "
               "message that makes it true (<code>age(…) &gt; T</code>: T; <code>2 * age(…) &gt; 3 s</code>: "
               "1.5 s; sums, constant multiples, <code>min</code> and <code>max</code> of <code>age</code> and "
               "<code>stamp_age</code> and constants added to them are solved, in either orientation and under "
               "<code>not</code>); <code>frequency(…, W)</code> adds its window W (1 s by default); "
               "<code>alive()</code>, <code>cpu()</code> and <code>memory()</code> two node samples at the monitor's "
               "default <code>~node_rate</code> of 10 Hz (0.2 s; a slower rate lengthens it); "
               "<code>active(A)</code> the slowest behaviour that starts A; <code>within</code> and "
               "<code>latch</code> add nothing to turning true; of several operands the slowest counts. Where no "
               "bound can be given, the page says <i>not computed</i> and why.")


def _reaction_note(ev: Evidence) -> str:
    note = f"<p>{DESIGN_NOTE}</p>"
    r = ev.reaction
    if r is None:
        return note + "<p>No benchmark figures were found, so the monitor's own reaction is not stated.</p>"
    if r.developers:
        return note + (f"<p>The monitor adds its own reaction, from the violating message to the stop received by "
                       f"the base: <b>{_e(r.figures())}</b>. <b>These are the developers' figures"
                       f"{f' of {_e(r.date)}' if r.date else ''} (bench/README.md), not measured on this machine.</b> "
                       f"Run <code>/usr/bin/python3 bench/reaction.py &gt; reaction.jsonl</code> on the robot's "
                       f"computer and pass <code>--bench reaction.jsonl</code> to state its own.</p>")
    return note + (f"<p>The monitor adds its own reaction, from the violating message to the stop received by the "
                   f"base, measured by bench/reaction.py where it was run: <b>{_e(r.figures())}</b> "
                   f"(source: {_e(r.source)}).</p>")


def _rules(ev: Evidence) -> str:
    rows = []
    worst = ev.reaction.worst_ms if ev.reaction else None
    for r in ev.spec.rules:
        d = design(ev.spec, ast.RuleRef(r.key))  # through the rules it uses
        bound = _e(d.text()) + (f" + ≤ {up(worst)} ms = ≤ {up(d.total + worst / 1000)} s"
                                if worst is not None and not d.unknown else "")
        rows.append(f"<tr><td><code>{_e(r.key)}</code></td><td>{_rule_id(ev, r)}</td><td>{_attr(r, 'hazard')}</td>"
                    f"<td>{_attr(r, 'title')}</td><td>{_attr(r, 'ref')}</td><td>{bound}</td>"
                    f"<td><pre>{_e(spec_text(ev.spec, r.span))}</pre></td></tr>")
    return ("<h2 id='rules'>Rules</h2>" + _reaction_note(ev)
            + _table(["rule", "id", "hazard", "title", "ref", "reaction (design + monitor)", "text"], rows))


def _behaviours(ev: Evidence) -> str:
    rows = []
    worst = ev.reaction.worst_ms if ev.reaction else None
    for b in ev.spec.behaviours:
        hazards = list(attrs(b).get("hazard", ()))
        via = [h for h in hazards_via_rules(ev.spec, b) if h not in hazards]
        hz = _list(hazards) if hazards else ""
        hz += (" " if hz else "") + (f"<span class='muted'>via rules: {_list(via)}</span>" if via else "")
        d = design(ev.spec, b.cond, frozenset({b.index}))
        bound = _e(d.text()) + (f" + ≤ {up(worst)} ms" if worst is not None and not d.unknown else "")
        rows.append(f"<tr><td>{b.index}</td><td><b>{_e(behaviour_label(ev.spec, b.index))}</b></td>"
                    f"<td>{_attr(b, 'id')}</td><td>{hz or _list([])}</td><td>{_attr(b, 'title')}</td>"
                    f"<td>{_list(a.name for a in b.actions)}</td><td>{bound}</td>"
                    f"<td><pre>{_e(spec_text(ev.spec, b.span))}</pre></td></tr>")
    return ("<h2 id='behaviours'>Behaviours</h2><p>A behaviour's time is its slowest path from its inputs through "
            "its rules to its condition, reckoned as the rules' (see Rules), then the monitor's worst case.</p>"
            + _table(["#", "name", "id", "hazard", "title", "actions", "reaction (design + monitor)", "text"], rows))


def _tests(ev: Evidence) -> str:
    if not ev.results:
        return "<h2 id='tests'>Tests</h2><p class='fail'>No test file was given (--tests).</p>"
    parts = ["<h2 id='tests'>Tests</h2>"]
    for r in ev.results:
        parts.append(f"<h3><code>{_e(_shown(r.path))}</code></h3>")
        if r.error:
            parts.append(f"<pre class='fail'>{_e(r.error)}</pre>")
            continue
        if not ev.same_spec(r):
            parts.append(f"<p class='fail'>These tests are of {_e(r.spec_path)}, not of this spec: they are not "
                         f"counted as evidence for it.</p>")
        rows = []
        for o in r.outcomes:
            verdict = "<span class='pass'>PASS</span>" if o.passed else "<span class='fail'>FAIL</span>"
            problems = f"<pre>{_e(chr(10).join(o.problems))}</pre>" if o.problems else ""
            rows.append(f"<tr><td>{verdict}</td><td>{_e(o.name)}{problems}</td><td>{_list(o.covers)}{'' if o.proves else ' (not counted: it expects nothing)'}</td>"
                        f"<td>{o.duration:g} s</td></tr>")
        parts.append(_table(["result", "test", "covers", "simulated"], rows))
    cov = ev.coverage
    if cov is not None:
        def line(title: str, items: List[str]) -> str:
            cell = f"<td class='gap'>{_list(items)}</td>" if items else "<td class='ok'>none</td>"
            return f"<tr><th>{_e(title)}</th>{cell}</tr>"

        parts.append("<h3>Coverage over all tests</h3><table><tbody>"
                     + line("rules never true", cov.rules_never_true)
                     + line("behaviours never started", cov.behaviours_never_started)
                     + line("ids no test covers", cov.ids_untested)
                     + line("hazards no test covers", cov.hazards_untested) + "</tbody></table>")
    return "".join(parts)


def _bags(ev: Evidence) -> str:
    if not ev.bags:
        return "<h2 id='recordings'>Recordings</h2><p class='muted'>No recording was given (--bag).</p>"
    labels = {b.index: behaviour_label(ev.spec, b.index) for b in ev.spec.behaviours}
    parts = ["<h2 id='recordings'>Recordings</h2>"]
    for run in ev.bags:
        parts.append(f"<h3><code>{_e(_shown(run.path))}</code></h3>")
        if run.error:
            parts.append(f"<pre class='fail'>{_e(chr(10).join([run.error] + run.type_errors))}</pre>")
            continue
        parts.append(f"<p>{run.duration:.3f} s, {run.messages} messages. Rules: red true, green false, grey "
                     f"unknown; behaviours: orange while active, ▼ at each start.</p>")
        parts += [f"<p class='muted'>{_e(w)}</p>" for w in run.warnings]
        parts.append(svg(ev.spec, run.events, run.duration, labels))
        rows = []
        for e in run.events:
            if e.kind not in ("start", "release"):
                continue
            w = getattr(e, "witness", None)
            why = ""
            if w is not None:
                why = "".join(f"{what}: " + ", ".join(f"<code>{_e(k)}</code>" for k in keys) + "<br>"
                              for what, keys in (("true", w.rules), ("false", w.false_rules)) if keys) + \
                    "<br>".join(f"<span class='w'>{_e(r.text())}</span>" for r in w.readings)
            rows.append(f"<tr><td>{e.time:.3f} s</td><td>{_e(e.kind)}</td><td>{_e(labels.get(e.behaviour, ''))}</td>"
                        f"<td>{_attr(ev.spec.behaviours[e.behaviour - 1], 'id')}</td><td>{_list(e.actions)}</td>"
                        f"<td>{why}</td></tr>")
        parts.append(_table(["time", "event", "behaviour", "id", "actions", "why (witnesses)"], rows) if rows
                     else "<p>No behaviour started.</p>")
    return "".join(parts)
