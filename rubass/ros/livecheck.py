"""The running spec checked again against the message types its topics turned out to carry, as
`rubass check --live` would: a unit or kind error on a topic field (`linear.x > 3 s` on a Twist)
that no check could see before the types were known is logged once and kept for /diagnostics.

The rule keeps being evaluated on the numbers as written (a field's value is in SI units, the
literal's too): unlike a field the type lacks, it can be read, and taking it away would remove
protection the engineer may be relying on. The check runs on a thread of its own, never on a
subscriber's or the engine's."""
from __future__ import annotations

import threading
from typing import Callable, Dict, List, Optional, Sequence, Tuple

from ..lang.errors import SpecError
from ..lang.loader import check_source
from ..lang.model import CheckedSpec
from ..lang.msgdef import DefinitionError, Registry
from ..lang.source import SourceSet
from ..lang.sysmodel import SystemModel

Log = Callable[[str, str], None]
Types = Dict[str, Tuple[str, str]]  # spec topic name -> (message type, its full definition text)


def live_errors(spec: CheckedSpec, libraries: Sequence[str], types: Types) -> List[str]:
    """The errors `rubass check` gives for `spec` with a model of these topic types, rendered."""
    registry = Registry()
    for type_name, text in types.values():
        try:
            registry.add_full(type_name, text)
        except (DefinitionError, ValueError):
            continue  # a definition we cannot read: its fields stay unchecked, as without a model
    model = SystemModel({t: ty for t, (ty, _) in types.items()}, None, registry,
                        source="the message types the topics carry")
    source = spec.sources.get(spec.path)
    if source is None:
        return []
    try:
        check_source(source, libraries, SourceSet(), model)
    except SpecError as exc:
        return [d.render(exc.sources) for d in exc.diagnostics if d.severity == "error"]
    return []


class LiveTypeCheck:
    """Checks the spec again whenever a topic's type becomes known or changes (`note`), or the
    spec changes (`use`); `errors` is what the latest check found."""

    def __init__(self, log: Log) -> None:
        self.log = log
        self.errors: List[str] = []
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._spec: Optional[CheckedSpec] = None
        self._libraries: Sequence[str] = ()
        self._types: Types = {}
        self._said: set = set()  # errors logged for this spec
        self._version = 0  # bumped by every change; a check of an older one is not kept
        self._known: Optional[Tuple[CheckedSpec, Types, List[str]]] = None  # a result found elsewhere
        self._closed = False
        threading.Thread(target=self._run, name="rubass-livecheck", daemon=True).start()

    def use(self, spec: CheckedSpec, libraries: Sequence[str]) -> None:
        """The spec now enforced (at start and after every reload)."""
        with self._lock:
            if spec is self._spec:
                return
            self._spec, self._libraries, self._said, self.errors = spec, list(libraries), set(), []
            self._version += 1
        self._wake.set()

    def known(self, spec: CheckedSpec, types: Types, errors: List[str]) -> None:
        """What live_errors gave for `spec` with `types` (a reload checked it before its swap): the
        thread takes it rather than checking the same spec against the same types again."""
        with self._lock:
            self._known = (spec, dict(types), list(errors))

    def note(self, types: Types) -> None:
        """The types the spec's topics carry now (cheap when nothing changed: call it freely)."""
        with self._lock:
            if types == self._types:
                return
            self._types = dict(types)
            self._version += 1
        self._wake.set()

    def close(self) -> None:
        self._closed = True
        self._wake.set()

    def _run(self) -> None:
        while True:
            self._wake.wait()
            self._wake.clear()
            if self._closed:
                return
            with self._lock:
                spec, libraries, types, version = self._spec, self._libraries, dict(self._types), self._version
            if spec is None or not types:
                continue
            known = self._known
            try:
                errors = known[2] if known is not None and known[0] is spec and known[1] == types else \
                    live_errors(spec, libraries, types)
            except Exception as exc:  # noqa: BLE001 - a bug here must not end the thread, nor hide itself
                self.log("error", f"rubass: checking the spec against the live message types failed: "
                                  f"{exc.__class__.__name__}: {exc}")
                continue
            with self._lock:
                if version != self._version:
                    continue  # the spec or the types changed meanwhile: the newer check counts
                self.errors = errors
                new = [e for e in errors if e not in self._said]
                self._said.update(new)
            for e in new:
                self.log("error", "rubass: the spec does not fit the message types its topics carry (fix the spec "
                                  "and reload; a unit or kind error: the rule is still evaluated on the numbers as "
                                  f"written; a field the type lacks: a data error, the rule unknown):\n{e}")
