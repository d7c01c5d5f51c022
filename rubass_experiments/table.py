"""Table 1, ours beside the paper's: text for people, and a plot of the distributions."""
from __future__ import annotations

from typing import Any, Dict, TextIO

from .rows import MONITOR_NICE

TARGET_B_P99_MS = 10.0


def _fmt(x: Any, scale: float = 1.0, digits: int = 2) -> str:
    return "-" if x is None else f"{x * scale:.{digits}f}"


def print_table(data: Dict[str, Any], out: TextIO) -> bool:
    """Print the table; True when every row stopped every time and (b) met its target. An
    interrupted experiment (data["interrupted"]) says so, and marks the rows it cut short."""
    stop = data.get("interrupted")
    ok = not stop
    if stop:
        cut = stop.get("cut_short")
        out.write(f"\nINTERRUPTED by {stop['signal']}: the table holds only the {stop['finished_runs']} finished runs"
                  + (f"; the run cut short ({cut['row']} run {cut['rep'] + 1}) counts in no figure, its bag: {cut['bag']}"
                     if cut else "") + "\n")
    out.write("\nTable 1 (seconds). (a): as the paper defines each row (from the fault, the first command over\n"
              "the limit, the crossing of the border, or the start of the CPU loop, to the stop reaching the base;\n"
              "rows beyond the paper say theirs in the notes).\n"
              "(b): the monitor's own delay, from the instant its rule became due to the stop reaching the base (ms).\n\n")
    head = (f"{'row':<13} {'ideal':>5} | {'paper: avg':>10} {'sd':>5} {'min':>5} {'max':>5} | {'ours (a): avg':>13} {'sd':>5} "
            f"{'min':>5} {'max':>5} | {'(b) ms: avg':>11} {'sd':>5} {'min':>5} {'max':>5} {'p99':>5} | stopped")
    out.write(head + "\n" + "-" * len(head) + "\n")
    if stop and not data["rows"]:
        out.write("(no run finished)\n")
    for r in data["rows"]:
        a, b, p = r["a"] or {}, r["b"] or {}, r["paper"] or {}
        stopped = f"{r['stopped']}/{r['runs']}"
        b_ok = bool(b) and (b["p99"] * 1000 <= TARGET_B_P99_MS or r["row"] == "CPU")
        ok = ok and r["stopped"] == r["runs"] and r["runs"] > 0 and b_ok
        out.write(f"{r['row']:<13} {r['ideal']:>5.2f} | {_fmt(p.get('avg')):>10} {_fmt(p.get('sd')):>5} {_fmt(p.get('min')):>5} "
                  f"{_fmt(p.get('max')):>5} | "
                  f"{_fmt(a.get('avg')):>13} {_fmt(a.get('sd')):>5} {_fmt(a.get('min')):>5} {_fmt(a.get('max')):>5} | "
                  f"{_fmt(b.get('avg'), 1000, 1):>11} {_fmt(b.get('sd'), 1000, 1):>5} {_fmt(b.get('min'), 1000, 1):>5} "
                  f"{_fmt(b.get('max'), 1000, 1):>5} {_fmt(b.get('p99'), 1000, 1):>5} | "
                  f"{stopped}{'' if r['stopped'] == r['runs'] else '  NOT EVERY TIME'}"
                  f"{'  (interrupted)' if r.get('interrupted') else ''}\n")
    notes = [f"{r['row']}: {r['note']}" for r in data["rows"] if r["note"]]
    early = [(r["row"], d["b"]) for r in data["rows"] for d in r.get("details", ()) if (d.get("b") or 0.0) < 0.0]
    if early:  # the due instant comes from the recorder's receive times, which lag on a loaded machine
        notes.append(f"(b) below 0 in {len(early)} run(s) ({', '.join(f'{row} {b * 1000:.1f} ms' for row, b in early)}): "
                     f"the recorder received the data after the base got the stop, so its receive times (the due "
                     f"instant) lagged by more than the monitor's own delay; (b) there is a lower bound, not a delay")
    refused = sum(d.get("nice_refused", False) for r in data["rows"] for d in r.get("details", ()))
    if refused:  # the runner starts it at a negative ~nice, which needs root or CAP_SYS_NICE
        notes.append(f"the monitor ran at its starting priority in {refused} run(s), not at nice {MONITOR_NICE} "
                     f"(not permitted: see a run's monitor.log)")
    slow = [(r["row"], d) for r in data["rows"] if r["row"] != "CPU" for d in r.get("details", ())
            if (d.get("b") or 0.0) * 1000 > TARGET_B_P99_MS]
    if slow:  # where the time went: the monitor's dispatch (its ~events start) or the way to the base
        notes.append(f"(b) over {TARGET_B_P99_MS:g} ms in {len(slow)} run(s): " + ", ".join(
            f"{row} run {d['rep'] + 1} {d['b'] * 1000:.1f} ms"
            + (f" ({d['b_monitor'] * 1000:.1f} in the monitor, {(d['b'] - d['b_monitor']) * 1000:.1f} to the base)"
               if d.get("b_monitor") is not None else "") for row, d in slow))
    errors = [f"{r['row']}: {e}" for r in data["rows"] for e in r["errors"]]
    if notes:
        out.write("\nnotes: " + "; ".join(notes) + "\n")
    if errors:
        out.write("\nruns with problems:\n" + "".join(f"  {e}\n" for e in errors))
    return ok


def plot(data: Dict[str, Any], path: str) -> None:
    """Per row: our (a) runs as dots beside the paper's min–max range and average; (b) in ms."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = data["rows"]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(14, 0.55 * len(rows) + 2), gridspec_kw={"width_ratios": [3, 2]})
    for y, r in enumerate(rows):
        p = r["paper"]
        if p:  # rows beyond the paper have no figures of its own
            ax.plot([p["min"], p["max"]], [y + 0.18] * 2, color="#999999", lw=5, solid_capstyle="butt")
            ax.plot([p["avg"]], [y + 0.18], "|", color="black", ms=14, mew=2)
        runs_a = [d["a"] for d in r["details"] if d["a"] is not None]
        runs_b = [d["b"] * 1000 for d in r["details"] if d["b"] is not None]
        ax.plot(runs_a, [y - 0.18] * len(runs_a), "o", color="#1f77b4", ms=5, alpha=0.8)
        ax.plot([r["ideal"]], [y], "*", color="#d62728", ms=10)
        bx.plot(runs_b, [y] * len(runs_b), "o", color="#2ca02c", ms=5, alpha=0.8)
    for axis in (ax, bx):
        axis.set_yticks(range(len(rows)))
        axis.set_yticklabels([r["row"] for r in rows])
        axis.invert_yaxis()
        axis.grid(axis="x", alpha=0.3)
    ax.set_xscale("symlog", linthresh=1.0)
    ax.set_xlabel("reaction (a), seconds (log scale past 1 s)")
    ax.set_title("ours (blue dots) vs the paper (grey: min–max, black: avg); red star: ideal")
    bx.axvline(TARGET_B_P99_MS, color="#d62728", ls="--", lw=1)
    bx.set_xlabel("monitor's own delay (b), ms (dashed: 10 ms target)")
    bx.set_title("rule due → stop at the base")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
