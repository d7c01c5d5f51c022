"""`rubass experiments [--reps N] [--only ROW…] [--out DIR]`: the paper's Table 1, reproduced."""
from __future__ import annotations

import argparse
import json
import os
import sys

from ...sim.rows import ROWS, row


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
    try:
        rows = [row(n) for n in args.only] if args.only else list(ROWS)
    except KeyError as exc:
        print(f"rubass experiments: error: no row {exc}; rows: {', '.join(r.name for r in ROWS)}", file=sys.stderr)
        return 2
    if not os.path.exists("/usr/bin/rosmaster"):
        print("rubass experiments: error: ROS 1 is not installed (no rosmaster); run tools/demo.sh, which installs it",
              file=sys.stderr)
        return 1
    from ...sim.table import plot, print_table
    from .runner import main_loop, results_json

    out = os.path.abspath(args.out)
    print(f"rubass experiments: {len(rows)} rows x {args.reps} runs; results in {out}", file=sys.stderr)
    results = main_loop(rows, args.reps, out)
    data = results_json(rows, results)
    ok = print_table(data, sys.stdout)
    with open(os.path.join(out, "table.json"), "w") as fh:
        json.dump(data, fh, indent=1)
    png = os.path.join(out, "table.png")
    plot(data, png)
    print(f"\ntable: {os.path.join(out, 'table.json')}\nplot:  {png}\nbags:  {os.path.join(out, 'runs')}/ROW/N/run.bag "
          f"(rubass replay SPEC BAG)")
    if not ok:
        print("rubass experiments: some row did not stop every time or missed the (b) target", file=sys.stderr)
    return 0 if ok else 1
