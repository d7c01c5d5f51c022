"""`rubass experiments [--reps N] [--only ROW…] [--out DIR]`: the paper's Table 1, reproduced.

SIGINT, SIGTERM or SIGHUP stops every process it started, closes the bag of the run in
progress, prints and saves the table of the finished runs marked as interrupted, and exits
128 + the signal (130, 143, 129)."""
from __future__ import annotations

import argparse
import io
import json
import os
import sys
from dataclasses import asdict
from typing import TYPE_CHECKING, Any, Dict, List, TextIO

from .rows import ROWS, Row, row
from .procs import Interrupted, Supervisor

if TYPE_CHECKING:
    from .runner import Outcome


def register(sub: "argparse._SubParsersAction[argparse.ArgumentParser]") -> None:
    p = sub.add_parser("experiments", help="run the paper's experiments on the simulated robots",
                       description="Run every row of the paper's Table 1 on the simulated Kobuki-like and "
                                   "Frobit-like bases, with its own rosmaster, and print the table.")
    p.add_argument("--reps", type=int, default=10, metavar="N", help="runs per row (default 10)")
    p.add_argument("--only", nargs="+", metavar="ROW", default=[],
                   help=f"only these rows ({', '.join(r.name for r in ROWS)}); case does not matter")
    p.add_argument("--out", default="out/experiments", metavar="DIR",
                   help="results: table.json, table.png, and a bag per run (default out/experiments)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.reps < 1:
        print("rubass experiments: error: --reps must be at least 1", file=sys.stderr)
        return 2
    try:  # a row named twice runs once (twice, its second run replaced the first's folder and bag)
        rows = list(dict.fromkeys(row(n) for n in args.only)) if args.only else list(ROWS)
    except KeyError as exc:
        print(f"rubass experiments: error: no row {exc}; rows: {', '.join(r.name for r in ROWS)}", file=sys.stderr)
        return 2
    if not os.path.exists("/usr/bin/rosmaster"):
        print("rubass experiments: error: ROS 1 is not installed (no rosmaster); run tools/demo.sh, which installs it",
              file=sys.stderr)
        return 1
    from .runner import spec_problems

    problems = spec_problems(rows)
    if problems:
        print("rubass experiments: error: " + "\nrubass experiments: error: ".join(problems), file=sys.stderr)
        return 1
    out = os.path.abspath(args.out)
    unwritable = _unwritable(out)
    if unwritable:
        print(f"rubass experiments: error: cannot write the results to {out} (--out): {unwritable}", file=sys.stderr)
        return 1
    sup = Supervisor()
    try:
        with sup:
            return _run(rows, args.reps, out, sup)
    except Interrupted as exc:  # a signal outside the runs (setting up, or before the table): processes stopped
        print(f"rubass experiments: interrupted by {exc.name}", file=sys.stderr)
        return exc.exit_status


def _run(rows: List[Row], reps: int, out: str, sup: Supervisor) -> int:
    from .table import plot, print_table
    from .runner import main_loop, results_json

    print(f"rubass experiments: {len(rows)} rows x {reps} runs; results in {out}", file=sys.stderr)
    outcome = main_loop(rows, reps, out, sup)
    png, json_path = os.path.join(out, "table.png"), os.path.join(out, "table.json")
    with sup.deferred():  # the table is written whole; a signal meanwhile is raised after it
        data = results_json(rows, outcome.results)
        if outcome.signal is not None:
            data = _mark_interrupted(data, outcome, reps)
        table = io.StringIO()
        ok = print_table(data, table)
        # saved before anything is printed: a Ctrl-C on `demo.sh | tee` also ends tee, so printing can fail
        saved = _save(json_path, data)
        _remove_plot(png)  # an earlier run's plot beside this table would disagree with it, if this one is not drawn
    _say(sys.stdout, table.getvalue())
    if saved:  # the runs' figures are on the console above; the bags are under runs/
        _say(sys.stderr, f"rubass experiments: error: cannot write {json_path}: {saved}\n")
        json_path = "(not written)"
    if outcome.signal is None:
        try:
            plot(data, png)
        except Interrupted as exc:  # a signal while drawing (about 1 s): no plot, not half of one
            with sup.deferred(raise_after=False):
                _remove_plot(png)
                _say(sys.stderr, f"rubass experiments: interrupted by {exc.name} after the runs: the plot was not "
                                 f"drawn (table: {json_path})\n")
            return exc.exit_status
    bags = f"{os.path.join(out, 'runs')}/ROW/N/run.bag (rubass replay SPEC BAG)"
    _say(sys.stdout, f"\ntable: {json_path}\nplot:  "
                     f"{png if outcome.signal is None else '(not drawn: interrupted)'}\nbags:  {bags}\n")
    if outcome.signal is not None:
        exc = Interrupted(outcome.signal)
        _say(sys.stderr, f"rubass experiments: interrupted by {exc.name}: {len(outcome.results)} of "
                         f"{len(rows) * reps} runs finished; every process it started is stopped\n")
        return exc.exit_status
    if not ok:
        _say(sys.stderr, "rubass experiments: some row did not stop every time or missed the (b) target\n")
    return 0 if ok and not saved else 1


def _unwritable(out: str) -> str:
    """Why the results cannot be written under `out` ("" when they can): found before any run."""
    try:
        os.makedirs(os.path.join(out, "runs"), exist_ok=True)
        probe = os.path.join(out, f".rubass-write-test-{os.getpid()}")
        with open(probe, "w"):
            pass
        os.remove(probe)
    except OSError as exc:
        return f"{exc.strerror or exc}" + (f" ({exc.filename})" if exc.filename and exc.filename != out else "")
    return ""


def _save(path: str, data: Dict[str, Any]) -> str:
    """Write the table's JSON; why it could not be ("" when written)."""
    try:
        with open(path, "w") as fh:
            json.dump(data, fh, indent=1)
    except OSError as exc:
        return exc.strerror or str(exc)
    return ""


def _remove_plot(png: str) -> None:
    if os.path.exists(png):
        try:
            os.remove(png)
        except OSError as exc:
            _say(sys.stderr, f"rubass experiments: cannot remove the earlier plot {png}: {exc.strerror or exc}\n")


def _say(stream: TextIO, text: str) -> None:
    """Write and flush; a reader that is gone (EPIPE) silences the stream, the run's status stands."""
    try:
        stream.write(text)
        stream.flush()
    except (BrokenPipeError, ValueError):  # ValueError: already closed
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, stream.fileno())  # the interpreter's flush at exit must not fail either
            os.close(devnull)
        except (OSError, ValueError):
            pass


def _mark_interrupted(data: Dict[str, Any], outcome: "Outcome", reps: int) -> Dict[str, Any]:
    """The table of an interrupted experiment: only the rows with a finished run, each saying
    how many of its runs finished; the run cut short is named, not counted."""
    cut = outcome.cut_short
    data["interrupted"] = {
        "signal": Interrupted(outcome.signal or 0).name, "finished_runs": len(outcome.results),
        "cut_short": {k: v for k, v in asdict(cut).items() if k != "events"} if cut else None,
    }
    data["rows"] = [dict(r, interrupted=r["runs"] < reps) for r in data["rows"] if r["runs"] > 0]
    return data
