"""A timeline picture of a replay: one row per rule and behaviour, values as colours."""
from __future__ import annotations

from typing import Any, Dict, List, Tuple

from ..engine import Event
from ..lang.model import CheckedSpec

COLOURS = {True: "#d62728", False: "#2ca02c", None: "#bbbbbb"}  # true red, false green, unknown grey


def _segments(changes: List[Tuple[float, Any]], end: float) -> Dict[Any, List[Tuple[float, float]]]:
    out: Dict[Any, List[Tuple[float, float]]] = {True: [], False: [], None: []}
    for (t, v), nxt in zip(changes, changes[1:] + [(end, None)]):
        if nxt[0] > t:
            out[v if v in (True, False) else None].append((t, nxt[0] - t))
    return out


def plot(spec: CheckedSpec, events: List[Event], end: float, path: str, title: str = "") -> None:
    """Write a PNG: rules (true/false/unknown), behaviours (active spans, starts marked)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    rows: List[str] = [r.key for r in spec.rules] + [f"{b.label} (line {b.span.line})" for b in spec.behaviours]
    fig, ax = plt.subplots(figsize=(12, 0.45 * len(rows) + 1.6))
    end = max(end, 1e-3)
    for y, rule in enumerate(spec.rules):
        changes = [(e.time, e.value) for e in events if e.kind == "rule" and e.rule == rule.key]
        for value, spans in _segments(changes or [(0.0, None)], end).items():
            ax.broken_barh(spans, (y - 0.35, 0.7), facecolors=COLOURS[value])
    base = len(spec.rules)
    for b in spec.behaviours:
        y = base + b.index - 1
        since = None
        spans: List[Tuple[float, float]] = []
        starts: List[float] = []
        for e in events:
            if e.behaviour != b.index:
                continue
            if e.kind == "start":
                since = e.time
                starts.append(e.time)
            elif e.kind == "release" and since is not None:
                spans.append((since, e.time - since))
                since = None
        if since is not None:
            spans.append((since, end - since))
        ax.broken_barh([(0.0, end)], (y - 0.35, 0.7), facecolors="#eeeeee")
        ax.broken_barh(spans, (y - 0.35, 0.7), facecolors="#ff7f0e")
        ax.plot(starts, [y] * len(starts), "v", color="black", markersize=8)
    ax.set_yticks(range(len(rows)))
    ax.set_yticklabels(rows)
    ax.invert_yaxis()
    ax.set_xlim(0, end)
    ax.set_xlabel("time since the start of the recording (s)")
    ax.set_title(title or "rubass replay")
    ax.legend(handles=[Patch(color=COLOURS[True], label="rule true"), Patch(color=COLOURS[False], label="rule false"),
                       Patch(color=COLOURS[None], label="unknown"), Patch(color="#ff7f0e", label="behaviour active")],
              loc="upper center", bbox_to_anchor=(0.5, -0.12 if len(rows) > 4 else -0.25), ncol=4, frameon=False)
    ax.grid(axis="x", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
