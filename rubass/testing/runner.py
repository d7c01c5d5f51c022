"""Running one test: its inputs through replay's engine driver, then its expectations checked.

The inputs become what a recording holds: real message objects at their instants and the
monitor's node samples, so a test runs exactly the path `rubass replay` and the monitor run.
"""
from __future__ import annotations

import io
import json
import math
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Set, Tuple

from ..engine import Event
from ..lang.ast import path_suffix
from ..lang.errors import did_you_mean
from ..lang.model import CheckedSpec
from ..lang.topicnames import resolve, spellings
from ..replay.run import replay
from .cases import UNSET, Case, Expect, MessageInput
from .messages import MessageError, assign, has_header, in_test_time
from .yamlpos import TestFileError

NODE_TOPIC = "/rubass_test/node_samples"  # a pseudo topic: node samples as a monitor records them
# what falls due at the end is seen: an `age() > T` crossing is scheduled a hair (engine
# CROSSING_MARGIN, 1 µs) after its instant
END_MARGIN = 1e-5
TICK_RATE = 50.0  # as `rubass replay` and the monitor's default tick
# Test time 0 is this absolute time for the engine, so that a message at 0 s has a real header
# stamp (a zero stamp is unknown, §11); events come back in test time.
EPOCH = 1000.0


@dataclass
class Outcome:
    """What one test did: pass or fail, why, and what it covered."""

    name: str
    line: int
    covers: List[str]
    passed: bool = True
    problems: List[str] = field(default_factory=list)
    events: List[Event] = field(default_factory=list)
    rules_true: Set[str] = field(default_factory=set)
    started: Set[int] = field(default_factory=set)
    duration: float = 0.0
    elapsed: float = 0.0
    proves: bool = True  # False: it expects nothing (docs/testing.md), so its covers count in no coverage

    @property
    def counted_covers(self) -> List[str]:
        """The covers that count as coverage: none for a test that expects nothing."""
        return list(self.covers) if self.proves else []


class _Sample:
    """A recorded ~node_samples message (what replay reads)."""

    def __init__(self, data: str) -> None:
        self.data = data


def _test_time(fpath: Tuple[Any, ...], value: Any) -> Any:
    """`value` to assign at `fpath`, a header stamp in test time as the engine's absolute time."""
    return in_test_time(fpath, value, EPOCH)


def _stream(spec: CheckedSpec, case: Case, path: str, warnings: List[str],
            errors: Optional[List[TestFileError]] = None) -> List[Tuple[float, str, Any]]:
    """The test's inputs as a recording. An error raises TestFileError, or with `errors` is kept there
    (the first at each line: a series gives one error, not one per step) and the rest is still checked."""
    from ..ros.msgtypes import check_path

    lines: Set[int] = set()

    def fail(err: TestFileError) -> None:
        if errors is None:
            raise err
        if err.line not in lines:
            lines.add(err.line)
            errors.append(err)

    names = spellings(spec.topics)  # resolved -> every spelling of it in the spec, each fed every message
    end = case.end
    readers = spec.field_readers(implicit=False)
    for topic, t in case.topics.items():
        if topic not in names:
            warnings.append(f"{path}:{t.line}: warning: the spec reads no topic {topic}"
                            f"{did_you_mean(topic, names)}; its messages change nothing")
            continue
        for fpath, owners in [r for n in names[topic] for r in readers.get(n, {}).items()]:
            plain = []
            for p in fpath:  # up to a slice or [*] (§12): what lies beyond is per element
                if not isinstance(p, (str, int)):
                    break
                plain.append(p)
            problem = check_path(t.cls, tuple(plain))
            if problem:
                text = path_suffix(fpath)
                fail(TestFileError(path, t.line, f"{' and '.join(owners)} reads {topic}{text}, but in "
                                                 f"{t.type_name}: {problem}"))
    groups: Dict[Tuple[float, str], List[MessageInput]] = {}
    for m in case.messages:
        if m.time > end:
            continue  # after the test's duration: a long series cut short
        groups.setdefault((m.time, m.topic), []).append(m)
    out: List[Tuple[float, int, str, Any]] = []
    for (time, topic), parts in groups.items():
        cls = case.topics[topic].cls
        msg = cls()
        try:
            if has_header(cls):
                assign(msg, ("header", "stamp"), EPOCH + time)
        except MessageError:
            pass
        broken = False
        for part in sorted(parts, key=lambda part: part.line):  # the later entry in the file wins per field
            try:
                for fpath, value in part.assignments:
                    assign(msg, fpath, _test_time(fpath, value))
            except MessageError as exc:
                fail(TestFileError(path, part.line, f"{topic} ({case.topics[topic].type_name}): {exc}"))
                broken = True
        if broken:
            continue
        try:
            msg.serialize(io.BytesIO())  # what a publisher would send: catches what the setters could not
        except Exception as exc:  # genpy raises SerializationError, struct.error, TypeError…
            fail(TestFileError(path, parts[0].line, f"the message of {topic} at {time:g} s does not fit "
                                                    f"{case.topics[topic].type_name}: {exc}"))
            continue
        for name in names.get(topic, ()):
            out.append((EPOCH + time, 0, name, msg))
    state: Dict[str, Dict[str, Any]] = {}
    # resolved -> every spelling of the node in the spec: the monitor samples each spelling (as it
    # resolves them), so each gets the samples of the node, as each spelling of a topic gets its messages
    nodes = spellings(spec.nodes)
    for s in sorted(case.nodes, key=lambda s: s.time):
        node = resolve(s.node)
        if node not in nodes:
            warnings.append(f"{path}:{s.line}: warning: the spec names no node {s.node}"
                            f"{did_you_mean(s.node, spec.nodes)}; its samples change nothing")
            continue
        if s.time > end:
            continue
        prev = state.setdefault(node, {"alive": None, "cpu": None, "memory": None})  # one node, any spelling
        for key, value in (("alive", s.alive), ("cpu", s.cpu), ("memory", s.memory)):
            if value is not UNSET:
                prev[key] = value
        if prev["alive"] is not True:
            # the monitor measures only a node that is alive (ros/nodes.py): else cpu and memory are
            # unknown, and not carried to a later sample
            given = [k for k, v in (("cpu", s.cpu), ("memory", s.memory)) if v is not UNSET and v is not None]
            if given:
                state_text = "not alive" if prev["alive"] is False else "not known to be alive"
                fail(TestFileError(path, s.line, f"a node that is {state_text} has no {' and no '.join(given)}: "
                                                 f"the monitor reads it unknown (measured only with alive: true)"))
            prev["cpu"] = prev["memory"] = None
        for name in nodes[node]:
            data = json.dumps({"node": name, "time": EPOCH + s.time, **prev})
            out.append((EPOCH + s.time, -1, NODE_TOPIC, _Sample(data)))
    out.sort(key=lambda x: (x[0], x[1]))  # samples before messages of the same instant
    return [(t, topic, msg) for t, _, topic, msg in out]


class Resolver:
    """Names in expectations: a behaviour's name or number, or a declared action."""

    def __init__(self, spec: CheckedSpec) -> None:
        self.spec = spec
        self.names = {b.name: b.index for b in spec.behaviours if getattr(b, "name", "")}

    def resolve(self, name: Any, path: str, line: int) -> Tuple[str, Any]:
        """('behaviour', index) or ('action', name); TestFileError for an unknown name."""
        n = len(self.spec.behaviours)
        if isinstance(name, str) and name in self.names:
            return "behaviour", self.names[name]
        if isinstance(name, str) and name in self.spec.actions:
            return "action", name
        text = str(name).strip()
        if text.startswith("behaviour "):
            text = text[len("behaviour "):].strip()
        if text.isdigit():
            if 1 <= int(text) <= n:
                return "behaviour", int(text)
            raise TestFileError(path, line, f"there is no behaviour {text}: the spec has {n}")
        raise TestFileError(path, line, f"'{name}' is neither a behaviour's name nor a declared action"
                                        f"{did_you_mean(str(name), list(self.names) + list(self.spec.actions))}")

    def label(self, target: Tuple[str, Any]) -> str:
        if target[0] == "action":
            return f"action {target[1]}"
        b = self.spec.behaviours[target[1] - 1]
        return b.name if getattr(b, "name", "") else f"behaviour {b.index} (line {b.span.line})"


def timeline(spec: CheckedSpec, events: List[Event], target: Tuple[str, Any]) -> List[Tuple[str, float]]:
    """The starts and releases of a behaviour, or of an action (first user starts, last releases)."""
    if target[0] == "behaviour":
        return [(e.kind, e.time) for e in events if e.kind in ("start", "release") and e.behaviour == target[1]]
    users = {b.index for b in spec.behaviours if any(a.name == target[1] for a in b.actions)}
    active: Set[int] = set()
    out: List[Tuple[str, float]] = []
    for e in events:
        if e.behaviour not in users or e.kind not in ("start", "release"):
            continue
        before = bool(active)
        (active.add if e.kind == "start" else active.discard)(e.behaviour)
        if bool(active) != before:
            out.append(("start" if active else "release", e.time))
    return out


def _intervals(tl: List[Tuple[str, float]], end: float) -> List[Tuple[float, float, bool]]:
    """The spans (from, to, still open) a behaviour or action is active; one still open at the test's
    end ends there: the test saw nothing after it."""
    out: List[Tuple[float, float, bool]] = []
    since: Optional[float] = None
    for kind, t in tl:
        if kind == "start" and since is None:
            since = t
        elif kind == "release" and since is not None:
            out.append((since, t, False))
            since = None
    if since is not None:
        out.append((since, end, True))
    return out


def _digits(tolerance: float) -> int:
    """Decimals of a time in a failure: at least ms, and the tolerance's precision (0.4 ms: 4)."""
    if tolerance <= 0:
        return 6
    return min(9, max(3, math.ceil(-math.log10(tolerance) - 1e-9)))


def _shown_digits(actual: List[Tuple[str, float]], exps: List[Expect], tolerance: float) -> int:
    """Decimals that show why the times differ: the tolerance's precision, the expected instants as
    written (2.0012 s), and more while a pair outside its tolerance would print as within it
    (2.001 s against 2.0021 s, tolerance 1 ms: 2.0010 and 2.0021)."""
    tols = [e.tolerance if e.tolerance is not None else tolerance for e in exps]
    d = max([_digits(min(tols, default=tolerance))] + [_places(e.at) for e in exps])
    pairs = []
    for kind in ("start", "release"):
        times = sorted(t for k, t in actual if k == kind)
        wanted = sorted((e.at, e.tolerance if e.tolerance is not None else tolerance) for e in exps if e.kind == kind)
        pairs += [(t, w, tol) for t, (w, tol) in zip(times, wanted)]
    while d < 9 and any(abs(t - w) > tol + 1e-9 and abs(round(t, d) - round(w, d)) <= tol + 1e-12
                        for t, w, tol in pairs):
        d += 1
    return d


def _places(t: float) -> int:
    """The decimals an expected instant was written with (2.0012 s: 4), so that it prints as written."""
    return next((d for d in range(3, 9) if abs(round(t, d) - t) < 1e-10), 9)


def _tol(tolerance: float) -> str:
    """A tolerance as a test author writes it: 1 ms, 0.4 ms, 2 s."""
    return f"{tolerance:g} s" if tolerance >= 1 else f"{round(tolerance * 1000, 6):g} ms"


def _fmt(tl: List[Tuple[str, float]], digits: int = 3) -> str:
    return ", ".join(f"{k} at {t:.{digits}f} s" for k, t in tl) or "no start or release"


@dataclass
class Prepared:
    """A test ready to run: its inputs as a recording and its expectations' targets."""

    spec: CheckedSpec
    case: Case
    stream: List[Tuple[float, str, Any]]
    targets: List[Tuple[Expect, Tuple[str, Any]]]


def prepare(spec: CheckedSpec, case: Case, path: str, warnings: List[str]) -> Prepared:
    """Check a test against its spec and build its inputs; TestFileError when they cannot be used."""
    resolver = Resolver(spec)
    targets = [(e, resolver.resolve(e.name, path, e.line)) for e in case.expects]
    return Prepared(spec, case, _stream(spec, case, path, warnings), targets)


def prepare_all(spec: CheckedSpec, case: Case, path: str, warnings: List[str],
                errors: List[TestFileError]) -> Optional[Prepared]:
    """prepare(), keeping every error (each expectation's name, then the inputs) in `errors` rather than
    stopping at the first; None when the test cannot run. The inputs of a test that had errors in the
    file are not built (what is left of them would only give errors that follow from the first)."""
    resolver = Resolver(spec)
    before = len(errors)
    targets = []
    for e in case.expects:
        try:
            targets.append((e, resolver.resolve(e.name, path, e.line)))
        except TestFileError as exc:
            exc.also = True  # a name the spec lacks follows from nothing else at its line (`{at: -1 s, start: stpo}`)
            errors.append(exc)
    if not case.readable:
        return None
    stream = _stream(spec, case, path, warnings, errors)
    return Prepared(spec, case, stream, targets) if len(errors) == before else None


def run_case(spec: CheckedSpec, case: Case, path: str, warnings: Optional[List[str]] = None) -> Outcome:
    """Prepare and run one test (TestFileError when it cannot run)."""
    return execute(prepare(spec, case, path, warnings if warnings is not None else []))


def execute(p: Prepared) -> Outcome:
    """Run a prepared test on the engine and check its expectations."""
    spec, case, stream, targets = p.spec, p.case, p.stream, p.targets
    resolver = Resolver(spec)
    if not spec.nodes:
        stream = [x for x in stream if x[1] != NODE_TOPIC]
    end = case.end
    # what falls due at the duration is seen (an `age() > T` crossing is scheduled a hair after its
    # instant): the engine runs to the duration plus the largest tolerance, as an expectation is matched
    tol = max([case.tolerance] + [e.tolerance for e, _ in targets if e.tolerance is not None])
    _, run = replay(spec, stream, EPOCH, EPOCH + end + tol, TICK_RATE, [NODE_TOPIC] if spec.nodes else [])
    # a test sees nothing after its end (docs/testing.md): what the engine ran past it is there only for
    # an expectation whose own window reaches past the end, and only within that window (_seen)
    events = [e for e in run if e.time <= end + END_MARGIN]
    out = Outcome(case.name, case.line, list(case.covers), duration=end, proves=bool(case.expects))
    out.events = [e for e in events if e.kind in ("start", "release", "rule")]
    out.rules_true = {e.rule for e in events if e.kind == "rule" and e.value is True}
    out.started = {e.behaviour for e in events if e.kind == "start"}
    counted: Dict[Tuple[str, Any], List[Expect]] = {}
    for exp, target in targets:
        if exp.kind in ("start", "release"):
            counted.setdefault(target, []).append(exp)
    for target, exps in counted.items():
        actual = _seen(timeline(spec, run, target), exps, end, case.tolerance)
        if not _match(actual, exps, case.tolerance):
            tols = sorted({e.tolerance if e.tolerance is not None else case.tolerance for e in exps})
            digits = _shown_digits(actual, exps, case.tolerance)
            lines = sorted({e.line for e in exps})
            where = f"line{'s' if len(lines) > 1 else ''} {', '.join(str(n) for n in lines)}"
            if len(tols) == 1:  # one tolerance: said once
                expected = _fmt(sorted(((e.kind, e.at) for e in exps), key=lambda x: x[1]), digits)
                expected += f" (each ± {_tol(tols[0])})"
            else:  # each expectation's own
                expected = ", ".join(f"{e.kind} at {e.at:.{digits}f} s ± "
                                     f"{_tol(e.tolerance if e.tolerance is not None else case.tolerance)}"
                                     for e in sorted(exps, key=lambda e: e.at))
            out.problems.append(f"{resolver.label(target)} ({where}):\n      expected: {expected}\n"
                                f"      actual:   {_fmt(actual, digits)}")
    for exp, target in targets:
        tol = exp.tolerance if exp.tolerance is not None else case.tolerance
        actual = timeline(spec, events, target)
        if exp.kind == "never":
            starts = [t for k, t in actual if k == "start"]
            if starts:
                out.problems.append(f"{resolver.label(target)}: expected never to start (line {exp.line}), "
                                    f"but: {_fmt(actual, _digits(case.tolerance))}")
        elif exp.kind == "active":
            spans = _intervals(actual, end)
            if not any(a <= exp.start + tol and b >= exp.end - tol for a, b, _ in spans):
                d = _digits(tol)
                shown = ", ".join(f"[{a:.{d}f}, {b:.{d}f}]" + (" (still active at the test's end)" if open_ else "")
                                  for a, b, open_ in spans) or "never"
                out.problems.append(f"{resolver.label(target)}: expected active (line {exp.line}) throughout "
                                    f"[{exp.start:.{d}f}, {exp.end:.{d}f}] s ± {_tol(tol)}, but active: {shown}")
    out.passed = not out.problems
    return out


def _seen(tl: List[Tuple[str, float]], exps: List[Expect], end: float, tolerance: float) -> List[Tuple[str, float]]:
    """The starts and releases of `tl` the test sees: those by its end, and after it only those within
    the window (at ± tolerance) of an expectation of the same kind whose window reaches past the end."""
    def within(kind: str, t: float) -> bool:
        for e in exps:
            tol = e.tolerance if e.tolerance is not None else tolerance
            if e.kind == kind and abs(t - e.at) <= tol + 1e-9:
                return True
        return False

    return [(k, t) for k, t in tl if t <= end + END_MARGIN or within(k, t)]


def _match(actual: List[Tuple[str, float]], exps: List[Expect], tolerance: float) -> bool:
    for kind in ("start", "release"):
        times = [t for k, t in actual if k == kind]
        wanted = sorted((e.at, e.tolerance if e.tolerance is not None else tolerance) for e in exps if e.kind == kind)
        if len(times) != len(wanted):
            return False
        if any(abs(t - w) > tol + 1e-9 for t, (w, tol) in zip(sorted(times), wanted)):
            return False
    return True
