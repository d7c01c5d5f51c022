"""The monitor's measured reaction: from bench/reaction.py's output given with --bench (measured where it was
run), else the developers' figures in bench/README.md (their machine, their date: not this machine)."""
from __future__ import annotations

import json
import math
import os
import re
from dataclasses import dataclass
from typing import List, Optional

from ..lang.errors import RubassError
from .design import up

README = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                      "bench", "README.md")


@dataclass
class Reaction:
    """Worst case and p99 over the benchmark's cases, in milliseconds, and where they come from."""

    worst_ms: float
    p99_ms: float
    p50_ms: float
    source: str
    cases: int
    developers: bool = False  # the figures of bench/README.md: the developers' machine, not this one
    date: str = ""  # the date of the developers' figures, when the README gives one
    extent: str = ""  # what was measured: rates, load, violations, seconds (a file given with --bench)
    loaded_cases: Optional[int] = None  # how many of its cases ran under background load (a file given with --bench)

    def figures(self) -> str:
        """The figures as what they are: one case's, or the largest of each over several cases (the p50
        shown is then no median of anything: the slowest case's), and what was measured."""
        extent = f" ({self.extent})" if self.extent else ""
        if self.cases == 1:
            return f"p50 {up(self.p50_ms)} ms, p99 {up(self.p99_ms)} ms, worst {up(self.worst_ms)} ms{extent}"
        return (f"largest p50 {up(self.p50_ms)} ms, largest p99 {up(self.p99_ms)} ms and worst {up(self.worst_ms)} ms "
                f"over {self.cases} cases{extent}")

    def p99_label(self) -> str:
        return "p99" if self.cases == 1 else f"largest p99 of {self.cases} cases"


class BenchError(RubassError):
    """A benchmark file given with --bench that cannot be used; the message names the file and why."""


_EXPECTED = ('expected the JSON lines of bench/reaction.py, e.g. {"benchmark": "reaction", '
             '"rubass": {"p50_ms": 0.4, "p99_ms": 0.9, "max_ms": 1.2}}')


def _no_bound(obj: dict, rb: dict) -> str:
    """Why a case's figures bound nothing ('' when they do): violations without their stop, extra stops
    (stops are matched to violations in order, so one extra shifts every later pair), no figure."""
    missed, extra = obj.get("rubass_unanswered", 0), obj.get("rubass_extra_stops", 0)
    if missed != 0:
        return f"has {missed} violations that got no stop"
    if extra != 0:
        return f"has {extra} extra stops"
    return "measured no reaction (max_ms is null)" if rb.get("max_ms") is None else ""


def from_json_lines(path: str) -> Reaction:
    """The output of `bench/reaction.py` (JSON lines). Raises BenchError when the file cannot be read or
    holds no reaction figure (lines that are no JSON are skipped while some line holds figures)."""
    worst, p99, p50, n = 0.0, 0.0, 0.0, 0
    rates: List[str] = []
    loaded, violations, seconds = 0, 0, 0.0
    first_bad = ""
    try:
        with open(path, encoding="utf-8") as fh:
            lines = fh.read().splitlines()
    except OSError as exc:
        raise BenchError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise BenchError(f"{path}: not a text file; {_EXPECTED}") from None
    for number, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            obj = json.loads(line)
        except ValueError:
            first_bad = first_bad or f"line {number} is not JSON"
            continue
        if not (isinstance(obj, dict) and obj.get("benchmark") == "reaction"):
            first_bad = first_bad or f"line {number} holds no reaction figures"
            continue
        if obj.get("smoke") is True:
            raise BenchError(f"{path}:{number}: a --smoke run of bench/reaction.py (one short case, to check that "
                             f"the script works) is no measurement of the monitor's reaction; run it without "
                             f"--smoke")
        rb = obj.get("rubass")
        if not isinstance(rb, dict):  # a reaction case without figures bounds nothing: not skipped
            raise BenchError(f"{path}:{number}: a reaction case without its figures (\"rubass\" is "
                             f"{json.dumps(rb)}): no upper bound; measure again")
        why = _no_bound(obj, rb)  # a case whose stops did not all come, or not one each, bounds nothing
        if why:
            case = f"{obj.get('rate_hz', '?')} Hz{', loaded' if obj.get('background_load') else ''}"
            raise BenchError(f"{path}:{number}: the case at {case} {why}: its latencies are no upper bound "
                             f"of the monitor's reaction; measure again")
        try:
            figures = float(rb["max_ms"]), float(rb["p99_ms"]), float(rb["p50_ms"])
        except (KeyError, TypeError, ValueError):
            raise BenchError(f"{path}:{number}: a reaction needs the numbers max_ms, p99_ms and p50_ms "
                             f"under \"rubass\"") from None
        if not all(math.isfinite(f) and f >= 0 for f in figures):
            raise BenchError(f"{path}:{number}: a reaction figure is not a finite, non-negative number: no upper "
                             f"bound; measure again")
        if not figures[2] <= figures[1] <= figures[0]:  # a max below a percentile is no worst case
            raise BenchError(f"{path}:{number}: the figures are out of order (p50 {figures[2]:g} ms, p99 "
                             f"{figures[1]:g} ms, max {figures[0]:g} ms; each must be at most the next): no upper "
                             f"bound; measure again")
        worst, p99, p50 = max(worst, figures[0]), max(p99, figures[1]), max(p50, figures[2])
        n += 1
        rate = f"{obj.get('rate_hz')} Hz" if isinstance(obj.get("rate_hz"), (int, float)) else ""
        if rate and rate not in rates:
            rates.append(rate)
        loaded += obj.get("background_load") is True
        violations += rb.get("n") if isinstance(rb.get("n"), int) else 0
        seconds += obj.get("seconds") if isinstance(obj.get("seconds"), (int, float)) else 0.0
    if not n:
        raise BenchError(f"{path}: no reaction figures ({first_bad or 'the file is empty'}); {_EXPECTED}")
    return Reaction(worst, p99, p50, f"{path} (bench/reaction.py)", n,
                    extent=_extent(rates, loaded, n, violations, seconds), loaded_cases=loaded)


def _extent(rates: List[str], loaded: int, cases: int, violations: int, seconds: float) -> str:
    """What a benchmark file measured, for the page: "at 100 and 1000 Hz, 2 of 4 cases under background
    load, 3,000 violations in 20 s" (a short or unloaded measurement shows as one)."""
    parts = [f"at {' and '.join(rates)}"] if rates else []
    parts.append("no case under background load" if not loaded else
                 "under background load" if loaded == cases == 1 else f"{loaded} of {cases} cases under background load")
    if violations:
        parts.append(f"{violations:,} violations" + (f" in {seconds:g} s" if seconds else ""))
    return ", ".join(parts)


def from_readme(path: str = README) -> Optional[Reaction]:
    """The reaction table of bench/README.md: `| rate | load | raw | p50 / p99 / max ms | … |`."""
    try:
        with open(path, encoding="utf-8") as fh:
            text = fh.read()
    except OSError:
        return None
    head = re.search(r"^## reaction\.py", text, re.M)
    if head is None:
        return None
    start = head.end()
    end = re.compile(r"^#{1,2} ", re.M).search(text, start)
    body = text[start:end.start() if end else len(text)]
    rows: List[List[float]] = []
    first_row = -1
    for m in re.finditer(r"^\|[^|\n]*\|[^|\n]*\|[^|\n]*\|\s*([\d.]+)\s*/\s*([\d.]+)\s*/\s*([\d.]+)\s*ms\s*\|", body, re.M):
        rows.append([float(m.group(1)), float(m.group(2)), float(m.group(3))])
        first_row = m.start() if first_row < 0 else first_row
    if not rows:
        return None
    date = _date_of(text, start + first_row)
    when = f", figures of {date}" if date else ""
    return Reaction(max(r[2] for r in rows), max(r[1] for r in rows), max(r[0] for r in rows),
                    f"bench/README.md (bench/reaction.py{when})", len(rows), developers=True, date=date)


def _date_of(text: str, pos: int) -> str:
    """The last "Figures of DATE" before `pos` in the part (top-level `#` section) of the README that
    holds it; "" when that part dates nothing."""
    part = 0
    for m in re.finditer(r"^# ", text[:pos], re.M):
        part = m.start()
    dates = re.findall(r"Figures of (\d{4}-\d\d-\d\d)", text[part:pos])
    return dates[-1] if dates else ""


def measured(path: Optional[str] = None) -> Optional[Reaction]:
    """From the JSON lines given (BenchError when they hold none), else from bench/README.md (None when it
    has no figures)."""
    if path:
        return from_json_lines(path)
    return from_readme()
