"""`rubass test FILE.test.yaml… [--junit OUT.xml] [--coverage] [--actions LIB.yaml]`.

Exit 0 when every test passes, 1 when one fails, 2 when a file cannot be run (TESTING.md).
"""
from __future__ import annotations

import argparse
import sys
from typing import Dict, List, TextIO

from .coverage import coverage, render
from .results import FileResult, run_file, shown_path


def register(sub: "argparse._SubParsersAction[argparse.ArgumentParser]") -> None:
    p = sub.add_parser("test", help="run rule tests (FILE.test.yaml) on the engine, with no master",
                       description="Run the rule tests of each FILE (docs/testing.md) on the same engine as "
                                   "replay and the monitor. Exit 0 all pass, 1 a test fails, 2 a file cannot run.")
    p.add_argument("files", nargs="+", metavar="FILE.test.yaml")
    p.add_argument("--junit", metavar="OUT.xml", help="write JUnit XML (one testcase per test)")
    p.add_argument("--coverage", action="store_true",
                   help="list rules never true, behaviours never started, @id/@hazard values no test covers")
    p.add_argument("--actions", action="append", default=[], metavar="LIB.yaml",
                   help="an action library to load besides the spec's imports (repeatable)")
    p.set_defaults(func=run)


def print_results(results: List[FileResult], out: TextIO, err: TextIO) -> None:
    for r in results:
        for w in r.warnings:
            print(w, file=err)
        if r.error:
            print(r.error, file=err)
            continue
        print(f"{shown_path(r.path)} (spec {shown_path(r.spec_path)})", file=out)
        for o in r.outcomes:
            covers = f"  [{', '.join(o.covers)}{'' if o.proves else ': not counted, it expects nothing'}]" \
                if o.covers else ""
            print(f"  {'PASS' if o.passed else 'FAIL'}  {o.name}{covers}", file=out)
            for problem in o.problems:
                print(f"    {problem}", file=out)


def summary(results: List[FileResult]) -> str:
    """The last line, `N passed, N failed` (TESTING.md), after a line naming the files none of whose tests
    ran, so that a file with errors never reads as a clean run: `not run: 3 errors in x.test.yaml`."""
    passed = sum(o.passed for r in results for o in r.outcomes)
    failed = sum(not o.passed for r in results for o in r.outcomes)
    unrun = ", ".join(f"{n} error{'s' if n != 1 else ''} in {shown_path(r.path)}"
                      for r, n in ((r, max(r.error_count, 1)) for r in results if r.error))
    head = f"not run: {unrun}\n" if unrun else ""
    return f"{head}{passed} passed, {failed} failed"


def run(args: argparse.Namespace) -> int:
    results = [run_file(path, args.actions) for path in args.files]
    print_results(results, sys.stdout, sys.stderr)
    failed = sum(not o.passed for r in results for o in r.outcomes)
    if args.coverage:
        by_spec: Dict[str, List[FileResult]] = {}
        for r in results:
            if r.spec is not None:
                by_spec.setdefault(r.spec.path, []).append(r)
        for rs in by_spec.values():
            spec = rs[0].spec
            assert spec is not None
            print(render(coverage(spec, [o for r in rs for o in r.outcomes])))
    junit_error = ""
    if args.junit:
        from .junit import FolderError, write_junit

        try:
            write_junit(results, args.junit)
        except FolderError as exc:
            junit_error = f"rubass test: error: cannot write {args.junit}: {exc}"
        except OSError as exc:
            junit_error = f"rubass test: error: cannot write {args.junit}: {exc.strerror or exc}"
    print(summary(results))  # the last line, even when the XML could not be written
    if junit_error:
        sys.stdout.flush()
        print(junit_error, file=sys.stderr)
        return 2
    if any(r.error for r in results):
        return 2
    return 1 if failed else 0
