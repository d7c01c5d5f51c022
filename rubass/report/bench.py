"""The monitor's measured reaction on this machine, from the benchmark (bench/reaction.py)."""
from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass
from typing import List, Optional

from ..lang.errors import RubassError

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


class BenchError(RubassError):
    """A benchmark file given with --bench that cannot be used; the message names the file and why."""


_EXPECTED = ('expected the JSON lines of bench/reaction.py, e.g. {"benchmark": "reaction", '
             '"rubass": {"p50_ms": 0.4, "p99_ms": 0.9, "max_ms": 1.2}}')


def from_json_lines(path: str) -> Reaction:
    """The output of `bench/reaction.py` (JSON lines). Raises BenchError when the file cannot be read or
    holds no reaction figure (lines that are no JSON are skipped while some line holds figures)."""
    worst, p99, p50, n = 0.0, 0.0, 0.0, 0
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
        rb = obj.get("rubass") if isinstance(obj, dict) and obj.get("benchmark") == "reaction" else None
        if not isinstance(rb, dict) or rb.get("max_ms") is None:
            first_bad = first_bad or f"line {number} holds no reaction figures"
            continue
        try:
            figures = float(rb["max_ms"]), float(rb["p99_ms"]), float(rb["p50_ms"])
        except (KeyError, TypeError, ValueError):
            raise BenchError(f"{path}:{number}: a reaction needs the numbers max_ms, p99_ms and p50_ms "
                             f"under \"rubass\"") from None
        worst, p99, p50 = max(worst, figures[0]), max(p99, figures[1]), max(p50, figures[2])
        n += 1
    if not n:
        raise BenchError(f"{path}: no reaction figures ({first_bad or 'the file is empty'}); {_EXPECTED}")
    return Reaction(worst, p99, p50, f"{path} (bench/reaction.py)", n)


def from_readme(path: str = README) -> Optional[Reaction]:
    """The reaction table of bench/README.md: `| rate | load | raw | p50 / p99 / max ms | … |`."""
    try:
        with open(path, encoding="utf-8") as fh:
            text = fh.read()
    except OSError:
        return None
    section = text.split("## reaction.py", 1)
    if len(section) < 2:
        return None
    body = section[1].split("\n## ", 1)[0]
    rows: List[List[float]] = []
    for m in re.finditer(r"^\|[^|\n]*\|[^|\n]*\|[^|\n]*\|\s*([\d.]+)\s*/\s*([\d.]+)\s*/\s*([\d.]+)\s*ms\s*\|", body, re.M):
        rows.append([float(m.group(1)), float(m.group(2)), float(m.group(3))])
    if not rows:
        return None
    dated = re.search(r"Figures of (\d{4}-\d\d-\d\d)", text)
    when = f", figures of {dated.group(1)}" if dated else ""
    return Reaction(max(r[2] for r in rows), max(r[1] for r in rows), max(r[0] for r in rows),
                    f"bench/README.md (bench/reaction.py{when})", len(rows))


def measured(path: Optional[str] = None) -> Optional[Reaction]:
    """From the JSON lines given (BenchError when they hold none), else from bench/README.md (None when it
    has no figures)."""
    if path:
        return from_json_lines(path)
    return from_readme()
