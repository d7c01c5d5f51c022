"""`rubass report SPEC [--tests FILE…] [--bag BAG…] [--hazards RISK.yaml] [--bench FILE] -o report.html`."""
from __future__ import annotations

import argparse
import os
import sys

from ..lang import SpecError, load_spec
from ..lang.errors import in_text_order
from ..lang.paths import file_arg
from ..replay.command import is_bag


def register(sub: "argparse._SubParsersAction[argparse.ArgumentParser]") -> None:
    p = sub.add_parser("report", help="write one self-contained HTML page of safety evidence",
                       description="Write a report a certifier can read offline: rules with ids, hazards, titles "
                                   "and refs; the hazard -> rule -> behaviour -> test matrix with gaps; test results; "
                                   "each recording's timeline and events with their witnesses; the monitor's "
                                   "measured reaction. Exit 0 written, 1 a test fails or an input is bad, 2 usage.")
    p.add_argument("spec", metavar="SPEC", type=file_arg)
    p.add_argument("--tests", nargs="+", default=[], metavar="FILE.test.yaml", help="rule test files to run")
    p.add_argument("--bag", nargs="+", default=[], metavar="BAG", help="recordings to replay")
    p.add_argument("--hazards", metavar="RISK.yaml", help="the risk-assessment table (hazards: [{id, title, …}])")
    p.add_argument("--bench", metavar="FILE", help="bench/reaction.py JSON lines (default: bench/README.md figures)")
    p.add_argument("--actions", action="append", default=[], metavar="LIB.yaml",
                   help="an action library to load besides the spec's imports (repeatable)")
    p.add_argument("-o", "--output", required=True, metavar="report.html")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..testing.results import run_file
    from .bench import BenchError, measured
    from .evidence import Evidence, ReportError, build_matrix, replay_bag
    from .hazards import HazardsError, read_hazards
    from .html import render

    if is_bag(args.spec):
        print(f"rubass report: error: {args.spec} is a ROS bag, not a spec (usage: rubass report SPEC --bag BAG "
              f"[--tests FILE.test.yaml ...] -o report.html)", file=sys.stderr)
        return 1
    try:
        spec = load_spec(args.spec, args.actions)
    except SpecError as exc:
        print(exc.render(), file=sys.stderr)
        return 1
    said = [d.render(spec.sources) for d in in_text_order(spec.warnings)]  # as `rubass check` prints them
    if said:
        print("\n".join(said), file=sys.stderr)
    try:
        hazards = read_hazards(args.hazards) if args.hazards else []
    except HazardsError as exc:  # every error of the risk table, each at its place
        print("\n".join(exc.lines), file=sys.stderr)
        return 1
    try:
        reaction = measured(args.bench)
    except (ReportError, BenchError) as exc:
        print(f"rubass report: error: {exc}", file=sys.stderr)
        return 1
    results = [run_file(path, args.actions) for path in args.tests]
    foreign = []  # test files of another spec: shown on the page, not counted, and the exit says so
    for r in results:
        for w in r.warnings:
            print(w, file=sys.stderr)
        if r.error:
            print(r.error, file=sys.stderr)
        elif r.spec is not None and os.path.realpath(r.spec.path) != os.path.realpath(spec.path):
            foreign.append(r)
            print(f"rubass report: error: {r.path} tests {r.spec.path}, not {args.spec}: its "
                  f"{len(r.outcomes)} test{'s are' if len(r.outcomes) != 1 else ' is'} not evidence for this spec and "
                  f"{'are' if len(r.outcomes) != 1 else 'is'} not counted (give the test files of {args.spec}, whose 'spec:' names it)", file=sys.stderr)
    bags = [replay_bag(spec, path, actions=args.actions) for path in args.bag]
    for b in bags:
        more = [w for w in b.spec_warnings if w not in said]  # the spec's, against this recording's types
        said += more
        for line in more + [f"rubass report: warning: {b.path}: {w}" for w in b.warnings]:
            print(line, file=sys.stderr)
        if b.type_errors:  # at the spec's line, as `rubass check --bag` prints them
            print("\n".join(b.type_errors), file=sys.stderr)
            print(f"rubass report: error: {b.path} not replayed: {args.spec} cannot read its types (above); the "
                  f"page shows it as not replayed", file=sys.stderr)
        elif b.error:
            print(f"rubass report: error: {b.error}", file=sys.stderr)
    ev = Evidence(spec, hazards, results, bags, reaction)
    build_matrix(ev)
    text = render(ev)
    if os.path.isdir(args.output):
        print(f"rubass report: error: {args.output} is a folder: give the page's file name (-o "
              f"{os.path.join(args.output, os.path.splitext(os.path.basename(args.spec))[0] + '.html')})",
              file=sys.stderr)
        return 1
    folder = os.path.dirname(os.path.abspath(args.output))
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as exc:
        print(f"rubass report: error: cannot write {args.output}: cannot create its folder {folder}: "
              f"{exc.strerror or exc}", file=sys.stderr)
        return 1
    tmp = args.output + ".tmp"
    try:
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, args.output)
    except OSError as exc:
        print(f"rubass report: error: cannot write {args.output}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    outcomes = ev.outcomes
    failed = sum(not o.passed for o in outcomes)
    gaps = sum(1 for row in ev.matrix if row.gaps)
    ok = len(outcomes) - failed
    untraced = len(ev.untraced)
    print(f"report written to {args.output}: {ok} test{'s' if ok != 1 else ''} passed, {failed} failed, "
          f"{gaps} gap{'s' if gaps != 1 else ''} in the matrix"
          + (f" ({untraced} rule{' traces' if untraced == 1 else 's trace'} to no hazard)" if untraced else "")
          + (f"; {len(foreign)} test file{'s' if len(foreign) != 1 else ''} of another spec not counted" if foreign
             else "")
          + (f"; not run: {', '.join(r.path for r in results if r.error)}" if any(r.error for r in results) else "")
          + (f"; not replayed: {', '.join(b.path for b in bags if b.error)}" if any(b.error for b in bags) else ""))
    if reaction is not None and reaction.loaded_cases == 0:
        print(f"note: {args.bench} has no case under background load (bench/reaction.py without --smoke runs two): "
              f"the worst case on the page may understate the reaction on a busy computer", file=sys.stderr)
    if reaction is not None and reaction.developers:
        print(f"note: the monitor's reaction on the page is the developers' figures"
              f"{f' of {reaction.date}' if reaction.date else ''} (bench/README.md), not this machine's: run "
              f"bench/reaction.py on the robot's computer and pass its output with --bench", file=sys.stderr)
    return 1 if failed or foreign or any(r.error for r in results) or any(b.error for b in bags) else 0
