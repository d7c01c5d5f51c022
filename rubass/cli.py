"""The `rubass` command line: check, fmt, replay, experiments. Exit 0 ok, 1 errors, 2 usage."""
from __future__ import annotations

import argparse
import os
import sys
from typing import List, Optional, Sequence

from .lang import SpecError, format_spec, parse_source
from .lang.paths import file_arg
from .lang.topicnames import spellings
from .replay.command import register as register_replay
from .testing.command import register as register_test
from .report.command import register as register_report
from rubass_experiments.command import register as register_experiments
from .ros.model_command import add_source_options, build_model
from .ros.libtypes import after_check, failed_check
from .ros.bag import BagError
from .ros.model_sources import load_spec_against
from .ros.model_command import register as register_model
from .lang.errors import Diagnostic, counted, in_text_order
from .lang.source import SourceSet
from .lang.sourcefile import read_source


def _print_diags(diags: Sequence[Diagnostic], sources: Optional[SourceSet]) -> int:
    """Print each diagnostic on stderr; the number of errors among them."""
    for d in diags:
        print(d.render(sources), file=sys.stderr)
    return sum(d.severity == "error" for d in diags)


def cmd_check(args: argparse.Namespace) -> int:
    """Check each spec; all errors of all files are printed."""
    # --bag, --live, --model: a system model to check against (a recorded definition that cannot be
    model, status = build_model(args, strict=False)  # read refuses only a spec that reads its topic)
    if status:
        return status
    for path in args.spec:
        try:
            checked = load_spec_against(path, args.actions, model, getattr(args, "bag", None))  # every recorded type
        except BagError as exc:
            print(f"rubass: error: {exc}", file=sys.stderr)
            status = 2
            continue
        except SpecError as exc:
            found = failed_check(exc, path, args.actions, model)
            for d, sources in found:
                print(d.render(sources), file=sys.stderr)
            # the summary counts every error printed above it: the spec's, and its libraries'
            n = sum(d.severity == "error" for d, _ in found)
            print(f"{path}: {counted(n, 'error')}", file=sys.stderr)
            status = 1
            continue
        errors, warnings = after_check(checked, model)
        n = _print_diags(in_text_order(checked.warnings + warnings + errors), checked.sources)
        if errors or n:
            print(f"{path}: {counted(max(n, len(errors)), 'error')}", file=sys.stderr)
            status = 1
            continue
        if not args.quiet:
            print(f"{path}: ok ({counted(len(checked.rules), 'rule')}, {counted(len(checked.behaviours), 'behaviour')}, "
                  f"{counted(len(spellings(checked.topics)), 'topic')}, {counted(len(checked.nodes), 'node')}, "
                  f"{counted(len(checked.actions), 'action')})")
    return status


def cmd_fmt(args: argparse.Namespace) -> int:
    """Print, check or rewrite the canonical layout of a spec."""
    src, diag = read_source(args.spec)
    if src is None:
        assert diag is not None
        _print_diags([diag], None)
        return 1
    try:
        spec = parse_source(src)
    except SpecError as exc:
        print(exc.render(), file=sys.stderr)
        return 1
    text = format_spec(spec, src.text)
    if args.check:
        if text != src.text:
            print(f"{args.spec}: not in canonical layout (run 'rubass fmt --write {args.spec}')", file=sys.stderr)
            return 1
        return 0
    if args.write:
        if text != src.text:
            tmp = args.spec + ".rubass-fmt.tmp"
            with open(tmp, "w", encoding="utf-8") as fh:
                fh.write(text)
            os.replace(tmp, args.spec)
        return 0
    sys.stdout.write(text)
    return 0


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="rubass", description="RuBaSS safety specs: check (also against a robot's "
                                "model), format, rule tests, replay of recordings, the certification report; the "
                                "paper's experiments.")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    c = sub.add_parser("check", help="check specs for errors")
    c.add_argument("spec", nargs="+", metavar="SPEC", type=file_arg)
    c.add_argument("--actions", action="append", default=[], metavar="LIB.yaml",
                   help="an action library to load besides the spec's imports (repeatable)")
    c.add_argument("-q", "--quiet", action="store_true",
                   help="leave out the 'ok' line of each clean spec (errors and warnings are still printed)")
    add_source_options(c, for_check=True)
    c.set_defaults(func=cmd_check)
    f = sub.add_parser("fmt", help="print a spec in canonical layout")
    f.add_argument("spec", metavar="SPEC")
    g = f.add_mutually_exclusive_group()
    g.add_argument("--check", action="store_true", help="exit 1 if the file is not in canonical layout")
    g.add_argument("--write", action="store_true", help="rewrite the file in place")
    f.set_defaults(func=cmd_fmt)
    register_replay(sub)
    register_test(sub)
    register_report(sub)
    register_experiments(sub)
    register_model(sub)
    return p


def main(argv: Optional[List[str]] = None) -> int:
    parser = _parser()
    args, extra = parser.parse_known_args(argv)
    if extra:  # named by the command's own usage, not the top level's
        command = getattr(args, "command", None)
        sub = next((a for a in parser._actions if isinstance(a, argparse._SubParsersAction)), None)
        target = sub.choices.get(command, parser) if sub is not None and command else parser
        target.error(f"unrecognized arguments: {' '.join(extra)}")
    if not getattr(args, "func", None):
        parser.print_usage(sys.stderr)
        print("rubass: error: a command is required (check, fmt, ...)", file=sys.stderr)
        return 2
    try:
        return int(args.func(args))
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        return 0
