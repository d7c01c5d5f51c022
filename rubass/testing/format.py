"""Reading a test file (TESTING.md) into plain data (cases.py), with the line of everything for errors."""
from __future__ import annotations

import math
import os
import re
from typing import Any, Callable, Dict, List, Tuple, TypeVar

from ..lang.errors import did_you_mean
from ..lang.paths import PathError, resolve as resolve_path
from ..lang.units import MEMORY, TIME, FREQUENCY, parse_quantity
from .cases import UNSET, Case, Expect, MessageInput, NodeSampleInput, TestFile, TopicInput
from .messages import MessageError, NoRosPython, Path, field_info, field_problems, message_class, parse_path
from .series import GAP, UNKNOWN, SeriesError, expand
from .yamlpos import LDict, LList, TestFileError, load

DEFAULT_TOLERANCE = 1e-3
MAX_TIME = 24 * 3600.0  # a test simulates at most a day (ticks at 50 Hz: 4.3 million)
MAX_MESSAGES = 1_000_000  # per test: each is a real message object
_CHECK_EPOCH = 1000.0  # test time 0 when a message's header stamp is checked (any such time does)
T = TypeVar("T")
_BARE_NUMBER = re.compile(r"\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?\s*")  # no unit: the default one


class _Reader:
    def __init__(self, path: str) -> None:
        self.path = path
        self.registry: Any = None  # message definitions of the system model, when the file names one
        self.sysmodel: Any = None  # the system model itself (its unit tables)
        self.errors: List[TestFileError] = []

    def fail(self, line: int, message: str, fatal: bool = False) -> TestFileError:
        return TestFileError(self.path, line, message, fatal)

    def guard(self, default: T, read: Callable[..., T], *args: Any, also: bool = False) -> T:
        """read(*args), or `default` when it fails: its error is kept and reading goes on, so that
        one run reports every error of the file (a fatal one still stops the file). `also`: the error
        is said even after another one at its line (a negative `at` beside a misspelt key)."""
        try:
            return read(*args)
        except TestFileError as exc:
            if exc.fatal:
                raise
            exc.also = also
            self.errors.append(exc)
            return default

    def mapping(self, value: Any, line: int, what: str, keys: Tuple[str, ...], required: Tuple[str, ...] = ()) -> LDict:
        if not isinstance(value, LDict):
            raise self.fail(line, f"{what} must be a mapping")
        for k in value:
            if k not in keys:  # left out, and reading goes on
                hint = f"{did_you_mean(str(k), keys)} (keys: {', '.join(keys)})"
                self.errors.append(self.fail(value.key_at(k), f"unknown key '{k}' in {what}{hint}"))
        for k in required:
            if k not in value:
                raise self.fail(value.line, f"{what} needs '{k}'")
        return value

    def seq(self, value: Any, line: int, what: str) -> LList:
        if not isinstance(value, LList):
            raise self.fail(line, f"{what} must be a list")
        return value

    def quantity(self, value: Any, line: int, what: str, dim: Any, unit: str, negative: bool = False) -> float:
        if isinstance(value, bool) or value is None:
            raise self.fail(line, f"{what} must be a number (in {unit}), not {value!r}")
        if isinstance(value, (int, float)):
            q: Any = (float(value), dim)
        else:
            q = parse_quantity(str(value))
            if q is not None and q[1] == () and dim != ():
                if not _BARE_NUMBER.fullmatch(str(value)):  # `50 %`: a share is no time, rate or size
                    raise self.fail(line, f"{what}: '{value}' is a share, not a quantity in {unit}")
                q = (q[0], dim)  # only a bare number takes the default unit
        if q is None or q[1] != dim or not math.isfinite(q[0]):
            raise self.fail(line, f"{what}: '{value}' is not a (finite) quantity in {unit}")
        if q[0] < 0 and not negative:
            raise self.fail(line, f"{what} must not be negative")
        return float(q[0])

    def time(self, value: Any, line: int, what: str) -> float:
        t = self.quantity(value, line, what, TIME, "seconds, e.g. 1.5 s or 200 ms")
        if t > MAX_TIME:
            raise self.fail(line, f"{what}: {t:g} s is longer than a test may run ({MAX_TIME:g} s)")
        return t

    # -- the file ---------------------------------------------------------------------------
    def read(self) -> TestFile:
        doc = load(self.path)
        top = self.mapping(doc, 1, "a test file", ("spec", "actions", "model", "tests"))
        for key in ("spec", "tests"):  # a missing one is said, and the rest of the file is still read
            if key not in top:
                self.errors.append(self.fail(top.line or 1, f"a test file needs '{key}'"))
        spec = top.get("spec", "")
        if "spec" in top and (not isinstance(spec, str) or not spec):
            self.errors.append(self.fail(top.at("spec"), "spec must be the path of a .rbs file"))
            spec = ""
        base = os.path.dirname(os.path.abspath(self.path))
        actions = self.guard([], self.actions, top, base)
        model = self.guard(None, self.model, top, base) if "model" in top else None
        self.registry = model.registry if model is not None else None
        self.sysmodel = model
        tests = self.guard(LList(), self.seq, top.get("tests", LList()), top.at("tests"), "tests")
        if not tests and isinstance(top.get("tests"), LList):
            self.errors.append(self.fail(top.at("tests"), "tests is empty: a file needs at least one test"))
        cases = [c for c in (self.guard(None, self.case, t, tests.at(i), i) for i, t in enumerate(tests)) if c]
        seen: Dict[str, int] = {}
        for c in cases:
            if c.name in seen:
                self.errors.append(self.fail(c.line, f"a second test named '{c.name}' (the first is at line "
                                                     f"{seen[c.name]})"))
            seen.setdefault(c.name, c.line)
        spec_path = _file_in(base, spec) if spec else ""
        errors = sorted(self.errors, key=lambda e: e.line)  # stable: one line's errors as found
        return TestFile(self.path, spec_path, top.at("spec"), actions, cases, model, errors)

    def actions(self, top: LDict, base: str) -> List[str]:
        listed = top.get("actions", LList())
        listed = [listed] if isinstance(listed, str) else self.seq(listed, top.at("actions"), "actions")
        return [_file_in(base, str(a)) for a in listed]

    def model(self, top: LDict, base: str) -> Any:
        """The system model file named by `model:` (relative to the test file)."""
        from ..lang.modelfile import load_model
        from ..lang.source import SourceSet

        name = top["model"]
        if not isinstance(name, str) or not name:
            raise self.fail(top.at("model"), "model must be the path of a system model file (docs/model.md)")
        sources = SourceSet()
        model, diags = load_model(os.path.join(base, name), sources)
        if model is None:
            text = "\n".join(d.render(sources) for d in diags)
            raise self.fail(top.at("model"), f"system model {name} cannot be used:\n{text}")
        return model

    def case(self, value: Any, line: int, i: int) -> Case:
        t = self.mapping(value, line, "a test", ("name", "covers", "duration", "topics", "nodes", "expect",
                                                 "tolerance"))
        before = len(self.errors)
        name = str(t.get("name", f"test {i + 1}"))
        covers, covers_lines = self.guard(([], []), self.covers, t)
        duration = self.guard(None, self.time, t["duration"], t.at("duration"), "duration") if "duration" in t else None
        tol = self.guard(DEFAULT_TOLERANCE, self.time, t["tolerance"], t.at("tolerance"), "tolerance") \
            if "tolerance" in t else DEFAULT_TOLERANCE
        case = Case(name, t.line, covers, duration, tol, covers_lines=covers_lines)
        topics = self.guard(LDict(), self.mapping, t.get("topics", LDict()), t.at("topics"), "topics",
                            tuple(t.get("topics") or ()) if isinstance(t.get("topics"), dict) else ())
        for topic, spec in topics.items():
            self.guard(None, self.topic, case, str(topic), spec, topics.at(topic))
        nodes = self.guard(LDict(), self.mapping, t.get("nodes", LDict()), t.at("nodes"), "nodes",
                           tuple(t.get("nodes") or ()) if isinstance(t.get("nodes"), dict) else ())
        for node, samples in nodes.items():
            self.guard(None, self.node, case, str(node), samples, nodes.at(node))
        expects = self.guard(LList(), self.seq, t.get("expect", LList()), t.at("expect"), "expect")
        read = [self.guard(None, self.expect, e, expects.at(k)) for k, e in enumerate(expects)]
        case.expects = [e for e in read if e is not None]
        if duration is not None:
            for e in case.expects:
                self.guard(None, self.within_duration, e, duration, e.tolerance if e.tolerance is not None else tol)
        case.readable = len(self.errors) == before
        return case

    def covers(self, t: LDict) -> Tuple[List[str], List[int]]:
        """The @id / @hazard values a test names, each with its line; a value that is no name (null, a
        mapping, true, 1.5) is an error rather than a name nobody wrote."""
        value = t.get("covers", LList())
        if isinstance(value, (str, int)) and not isinstance(value, bool):
            return [str(value)], [t.at("covers")]
        items = self.seq(value, t.at("covers"), "covers")
        out: List[str] = []
        for k, v in enumerate(items):
            if isinstance(v, bool) or not isinstance(v, (str, int)) or v == "":
                shown = "an empty entry" if v is None or v == "" else f"{v!r}"
                raise self.fail(items.at(k), f"covers lists @id and @hazard values of the spec: {shown} is not "
                                             f"one (write it as in the spec, quoted: covers: [\"SR-1\", \"H1\"])")
            out.append(str(v))
        return out, [items.at(k) for k in range(len(items))]

    def within_duration(self, e: Expect, duration: float, tol: float) -> None:
        """An expectation the test cannot see (after its end) is an error at its line, not a verdict."""
        last = e.at if e.kind in ("start", "release") else e.end if e.kind == "active" else 0.0
        if last > duration + tol:
            what = f"{e.kind} at {last:g} s" if e.kind != "active" else f"active until {last:g} s"
            raise self.fail(e.line, f"{what} is after the test's end (duration {duration:g} s): the test cannot "
                                    f"see it; lengthen duration or end the expectation by {duration:g} s")

    def topic(self, case: Case, topic: str, value: Any, line: int) -> None:
        if topic.startswith("~"):  # the monitor's private name, as the spec's `~x` resolves (docs/testing.md)
            from ..lang.topicnames import resolve

            topic = resolve(topic)
        elif not topic.startswith("/"):
            topic = "/" + topic
        t = self.mapping(value, line, f"topic {topic}", ("type", "rate", "start", "field", "fields", "values",
                                                         "messages"))
        # without its type (missing, not installed), the rest of the topic is still read: all but what
        # needs the type (its series' fields and their units) is checked
        known = TopicInput(topic, str(t.get("type", "")), None, line)
        if "type" not in t:
            self.errors.append(self.fail(line, f"topic {topic} needs 'type'"))
        else:
            try:
                known.cls = message_class(t["type"], self.registry)
            except NoRosPython as exc:  # no type can be had here: said once, for the whole file
                raise self.fail(t.at("type"), str(exc), fatal=True) from None
            except MessageError as exc:
                self.errors.append(self.fail(t.at("type"), str(exc)))
        before = case.topics.get(topic)
        if before is not None and known.cls is not None and before.type_name != t["type"]:  # `odom:` beside `/odom:`
            self.errors.append(self.fail(t.at("type"), f"topic {topic} is {before.type_name} at line {before.line}: "
                                                       f"one topic has one type"))
        elif known.cls is not None:
            case.topics[topic] = known
        series = [k for k in ("field", "fields", "values", "rate") if k in t]
        if series:
            self.guard(None, self.series, known, case, t)
        if "messages" in t:
            msgs = self.seq(t["messages"], t.at("messages"), f"messages of {topic}")
            for k, m in enumerate(msgs):
                self.guard(None, self.message, case, known, m, msgs.at(k))
        if not series and "messages" not in t:
            raise self.fail(line, f"topic {topic} has no input: give a series (rate, field, values) or messages")

    def series(self, known: TopicInput, case: Case, t: LDict) -> None:
        """A series of `known` (its cls None when its type cannot be had: then its fields and their units
        are left unchecked); each error at its line, the rest still read (a bad rate, field or value)."""
        topic, before = known.topic, len(self.errors)
        rate = self.guard(None, self.rate, topic, t)
        start = self.guard(0.0, self.time, t.get("start", 0.0), t.at("start"), "start")
        if ("field" in t) == ("fields" in t):
            raise self.fail(t.line, f"the series of {topic} needs either field + values or fields")
        if "field" in t:
            if "values" not in t:
                raise self.fail(t.line, f"the series of {topic} needs values")
            columns = [(t["field"], t["values"], t.key_at("field"), t.at("values"))]
        else:
            if "values" in t:
                raise self.fail(t.key_at("values"), "with fields, give the values per field: fields: {PATH: VALUES}")
            fields = self.mapping(t["fields"], t.at("fields"), "fields", tuple(t["fields"] or ()))
            columns = [(k, v, fields.key_at(k), fields.at(k)) for k, v in fields.items()]
            if not columns:
                raise self.fail(t.at("fields"), f"the series of {topic} has no fields")
        steps: List[Tuple[Path, List[Any]]] = []
        lines: List[int] = []
        for path_text, values, pline, vline in columns:
            try:
                path: Path = parse_path(path_text)
                field_dim = self.field_dim(known, path, pline) if known.cls is not None else UNKNOWN
            except MessageError as exc:
                self.errors.append(self.fail(pline, str(exc)))
                path, field_dim = (), UNKNOWN  # its values are still read, their units unchecked
            except TestFileError as exc:
                self.errors.append(exc)
                field_dim = UNKNOWN
            try:
                steps.append((path, expand(values, field_dim, str(path_text))))
            except SeriesError as exc:
                self.errors.append(self.fail(vline, f"values of {path_text}: {exc}"))
            lines.append(vline)
        if len(steps) != len(columns) or rate is None:
            return  # what is left needs every column's steps and the rate
        lengths = {len(s) for _, s in steps}
        if len(lengths) != 1:
            raise self.fail(t.at("fields"), f"the fields of {topic} have series of different lengths "
                                            f"({', '.join(str(len(s)) for _, s in steps)} steps)")
        n = lengths.pop()
        if len(self.errors) > before or known.cls is None:
            return  # the steps are checked; no message is built of a series with an error
        if len(case.messages) + n > MAX_MESSAGES:
            raise self.fail(t.line, f"more than {MAX_MESSAGES} messages in one test")
        for k in range(n):
            parts = [(path, s[k]) for path, s in steps if s[k] is not GAP]
            if parts and len(parts) != len(steps):  # `_` is no message: it cannot be one field of one
                gap = next(j for j, (_, s) in enumerate(steps) if s[k] is GAP)
                valued = next(p for p, s in steps if s[k] is not GAP)
                raise self.fail(lines[gap], f"step {k + 1} of {topic} (at {start + k / rate:g} s) is _ (no message) "
                                            f"in {_path_text(steps[gap][0])} but a value in {_path_text(valued)}: "
                                            f"a step with no message is _ in every field")
            if parts:
                line = t.at("values") if "values" in t else t.at("fields")
                case.messages.append(MessageInput(round(start + k / rate, 9), topic, parts, line))

    def rate(self, topic: str, t: LDict) -> float:
        if "rate" not in t:
            raise self.fail(t.line, f"the series of {topic} needs a rate (e.g. rate: 10 Hz)")
        rate = self.quantity(t["rate"], t.at("rate"), "rate", FREQUENCY, "Hz")
        if rate <= 0:
            raise self.fail(t.at("rate"), "rate must be more than 0 Hz")
        return rate

    def field_dim(self, t: TopicInput, path: Path, line: int) -> Any:
        """The dimension of a series' field (series.UNKNOWN when no unit table gives it, None when it is
        no number); a field the type lacks is an error at the field's line."""
        from ..lang.std_units import STANDARD_UNITS

        tables = (STANDARD_UNITS, self.sysmodel.units) if self.sysmodel is not None else (STANDARD_UNITS,)
        topic_units = self.sysmodel.topic_units.get(t.topic) if self.sysmodel is not None else None
        info = field_info(t.cls, path, tables, topic_units)
        if info is None:
            return UNKNOWN
        if info.kind == "missing":
            raise self.fail(line, f"{t.topic} ({t.type_name}): {info.why}")
        if info.kind == "msg":
            raise self.fail(line, f"{t.topic} ({t.type_name}): '{_path_text(path)}' is a message, not a value: "
                                  f"{info.why}")
        numeric = info.kind == "num" or (info.kind == "array" and info.elem_kind == "num")
        if not numeric:
            return None
        return info.dim if info.dim is not None else UNKNOWN

    def message(self, case: Case, known: TopicInput, value: Any, line: int) -> None:
        """One explicit message; its fields and values are checked against the topic's type here (when
        the type can be had), each error at its field's line, whatever else is wrong in the file."""
        topic = known.topic
        if not isinstance(value, LDict) or "at" not in value:
            raise self.fail(line, f"a message of {topic} is a mapping with 'at' and its fields")
        before = len(self.errors)
        at = self.guard(None, self.time, value["at"], value.at("at"), "at", also=True)
        parts: List[Tuple[Path, Any]] = []
        keys: List[Any] = []
        for k, v in value.items():
            if k == "at":
                continue
            try:
                parts.append((parse_path(str(k)), v))
                keys.append(k)
            except MessageError as exc:
                self._also(value.key_at(k), str(exc))
        if known.cls is not None:
            for k, why in field_problems(known.cls, parts, _CHECK_EPOCH):
                self._also(value.key_at(keys[k]) if k >= 0 else line, f"{topic} ({known.type_name}): {why}")
        if len(self.errors) == before and at is not None:
            case.messages.append(MessageInput(at, topic, parts, line))

    def _also(self, line: int, message: str) -> None:
        """An error said even beside another at its line: one field's error never follows from another's."""
        err = self.fail(line, message)
        err.also = True
        self.errors.append(err)

    def node(self, case: Case, node: str, value: Any, line: int) -> None:
        samples = self.seq(value, line, f"the samples of node {node}")
        for k, s in enumerate(samples):
            self.guard(None, self.sample, case, node, s, samples.at(k))

    def sample(self, case: Case, node: str, value: Any, line: int) -> None:
        s = self.mapping(value, line, f"a sample of node {node}", ("at", "alive", "cpu", "memory"), ("at",))
        alive = s.get("alive", UNSET)
        if alive is not UNSET and alive is not None and not isinstance(alive, bool):
            raise self.fail(s.at("alive"), f"alive must be true or false, not {alive!r}")
        cpu = s.get("cpu", UNSET)
        if cpu is not UNSET and cpu is not None:
            cpu = self.quantity(cpu, s.at("cpu"), "cpu", (), "a share of one core (0.5 or 50 %)")
        mem = s.get("memory", UNSET)
        if mem is not UNSET and mem is not None:
            mem = self.quantity(mem, s.at("memory"), "memory", MEMORY, "bytes (or 50 MB)")
        at = self.time(s["at"], s.at("at"), "at")
        case.nodes.append(NodeSampleInput(node, at, alive, cpu, mem, line))

    def expect(self, value: Any, line: int) -> Expect:
        e = self.mapping(value, line, "an expectation", ("at", "start", "release", "never", "active", "from", "to",
                                                         "tolerance"))
        # its times first: a bad one is said beside a misspelt key of the same line (`{at: -1 s, strat: x}`)
        times = {k: self.guard(None, self.time, e[k], e.at(k), k, also=True) for k in ("at", "from", "to", "tolerance")
                 if k in e}
        kinds = [k for k in ("start", "release", "never", "active") if k in e]
        if len(kinds) != 1:
            raise self.fail(line, "an expectation has one of start, release, never or active")
        kind = kinds[0]
        name = e[kind]
        if isinstance(name, bool) or not isinstance(name, (str, int)) or name == "":
            raise self.fail(e.at(kind), f"{kind} names a behaviour (name or number) or an action")
        out = Expect(kind, name, line)  # with a bad time it is kept (its name is still checked), at 0 s
        out.tolerance = times.get("tolerance")
        if kind == "never" and "tolerance" in e:  # on active it widens from and to (docs/testing.md)
            raise self.fail(e.at("tolerance"), "'tolerance' does not go with never: it has no instant to be "
                                               "near (never holds over the whole test)")
        allowed = {"start": ("at",), "release": ("at",), "never": (), "active": ("from", "to")}[kind]
        for k in ("at", "from", "to"):
            if k in e and k not in allowed:
                raise self.fail(e.at(k), f"'{k}' does not go with {kind}")
            if k not in e and k in allowed:
                raise self.fail(line, f"{kind} needs '{k}'")
        if kind in ("start", "release"):
            out.at = times["at"] or 0.0
        elif kind == "active":
            out.start, out.end = times["from"] or 0.0, times["to"] or 0.0
            if times["from"] is not None and times["to"] is not None and out.end < out.start:
                raise self.fail(e.at("to"), "to is before from")
        return out


def _path_text(path: Path) -> str:
    return "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in path).lstrip(".")


def read_test_file(path: str) -> TestFile:
    """The test file at `path` with every error found in it (`errors`), or TestFileError when it
    cannot be read at all (not YAML, not a mapping, no spec or tests, no ROS Python here): then its
    `before` holds the errors found until then (an unknown key `spce` beside the missing `spec`)."""
    reader = _Reader(path)
    try:
        return reader.read()
    except TestFileError as exc:
        exc.before = list(reader.errors)
        raise


def _file_in(base: str, path: str) -> str:
    """A file a test file names: relative to the test file, absolute, or `package://PKG/…` (left as
    written when the package is not found: reading it then says why)."""
    try:
        return resolve_path(path, base)
    except PathError:
        return path
