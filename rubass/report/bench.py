"""The monitor's measured reaction on this machine, from the benchmark (bench/reaction.py)."""
from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass
from typing import List, Optional

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


def from_json_lines(path: str) -> Optional[Reaction]:
    """The output of `bench/reaction.py` (JSON lines); None when it holds no reaction figure."""
    worst, p99, p50, n = 0.0, 0.0, 0.0, 0
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            try:
                obj = json.loads(line)
            except ValueError:
                continue
            rb = obj.get("rubass") if isinstance(obj, dict) and obj.get("benchmark") == "reaction" else None
            if not isinstance(rb, dict) or rb.get("max_ms") is None:
                continue
            worst, p99, p50 = max(worst, float(rb["max_ms"])), max(p99, float(rb["p99_ms"])), max(p50, float(rb["p50_ms"]))
            n += 1
    return Reaction(worst, p99, p50, f"{path} (bench/reaction.py)", n) if n else None


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
    """From the JSON lines given, else from bench/README.md; None when neither has figures."""
    if path:
        return from_json_lines(path)
    return from_readme()
