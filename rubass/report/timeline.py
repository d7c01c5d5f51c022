"""An inline SVG timeline of a replay: a row per rule (true/false/unknown) and per behaviour (active)."""
from __future__ import annotations

from html import escape
from typing import Any, Dict, List, Tuple

from ..engine import Event
from ..lang.model import CheckedSpec

COLOURS = {True: "#d62728", False: "#2ca02c", None: "#bbbbbb"}
ACTIVE = "#ff7f0e"
LEFT, WIDTH, ROW = 230, 660, 18


def _rule_segments(events: List[Event], key: str, end: float) -> List[Tuple[float, float, Any]]:
    changes = [(e.time, e.value) for e in events if e.kind == "rule" and e.rule == key] or [(0.0, None)]
    out = []
    for (t, v), nxt in zip(changes, changes[1:] + [(end, None)]):
        if nxt[0] > t:
            out.append((t, nxt[0], v if v in (True, False) else None))
    return out


def _active(events: List[Event], index: int, end: float) -> Tuple[List[Tuple[float, float]], List[float]]:
    spans, starts, since = [], [], None
    for e in events:
        if e.behaviour != index or e.kind not in ("start", "release"):
            continue
        if e.kind == "start":
            since = e.time
            starts.append(e.time)
        elif since is not None:
            spans.append((since, e.time))
            since = None
    if since is not None:
        spans.append((since, end))
    return spans, starts


def svg(spec: CheckedSpec, events: List[Event], end: float, labels: Dict[int, str]) -> str:
    end = max(end, 1e-3)
    rows = len(spec.rules) + len(spec.behaviours)
    height = rows * ROW + 40

    def x(t: float) -> float:
        return LEFT + WIDTH * min(max(t, 0.0), end) / end

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{LEFT + WIDTH + 20}" height="{height}" '
             f'font-family="sans-serif" font-size="11" role="img" aria-label="timeline">']
    y = 4
    for r in spec.rules:
        parts.append(f'<text x="{LEFT - 6}" y="{y + 12}" text-anchor="end">{escape(r.key)}</text>')
        for a, b, v in _rule_segments(events, r.key, end):
            parts.append(f'<rect x="{x(a):.1f}" y="{y + 2}" width="{max(x(b) - x(a), 0.5):.1f}" height="{ROW - 4}" '
                         f'fill="{COLOURS[v]}"><title>{escape(r.key)}: {("unknown" if v is None else str(v).lower())} '
                         f'{a:.3f}–{b:.3f} s</title></rect>')
        y += ROW
    for bh in spec.behaviours:
        name = labels.get(bh.index, f"behaviour {bh.index}")
        parts.append(f'<text x="{LEFT - 6}" y="{y + 12}" text-anchor="end" font-weight="bold">{escape(name)}</text>')
        parts.append(f'<rect x="{LEFT}" y="{y + 2}" width="{WIDTH}" height="{ROW - 4}" fill="#eeeeee"/>')
        spans, starts = _active(events, bh.index, end)
        for a, b in spans:
            parts.append(f'<rect x="{x(a):.1f}" y="{y + 2}" width="{max(x(b) - x(a), 1.0):.1f}" height="{ROW - 4}" '
                         f'fill="{ACTIVE}"><title>{escape(name)} active {a:.3f}–{b:.3f} s</title></rect>')
        for t in starts:
            parts.append(f'<path d="M{x(t) - 4:.1f},{y + 1} h8 l-4,7 z" fill="black"/>')
        y += ROW
    for k in range(6):
        t = end * k / 5
        parts.append(f'<line x1="{x(t):.1f}" y1="4" x2="{x(t):.1f}" y2="{y}" stroke="#999" stroke-dasharray="2,3"/>')
        parts.append(f'<text x="{x(t):.1f}" y="{y + 14}" text-anchor="middle">{t:.2f} s</text>')
    parts.append("</svg>")
    return "".join(parts)
