"""`rubass model` (write a system model from a recording or the live graph) and the system-model
options of `rubass check` (--bag, --live, --model): building the model, and the checks that run
after the spec's own (topics and nodes the model lacks, action libraries against definitions)."""
from __future__ import annotations

import argparse
import os
import sys
from typing import Optional, Tuple

from ..lang.errors import counted
from ..lang.modelfile import dump_model, parse_model
from ..lang.source import SourceSet
from ..lang.sourcefile import read_source
from ..lang.std_units import urdf_joint_kinds
from ..lang.sysmodel import SystemModel
from .bag import BagError
from .libtypes import try_installed
from .model_sources import LiveError, apply_joint_kinds, bag_model, live_model


def add_source_options(parser: argparse.ArgumentParser, for_check: bool) -> None:
    """--bag / --live / --model (check only) / --master, one source at a time."""
    g = parser.add_mutually_exclusive_group(required=not for_check)
    g.add_argument("--bag", metavar="RUN.bag", help="a recording: its topics, types and message definitions")
    g.add_argument("--live", action="store_true", help="the running ROS graph (ROS_MASTER_URI or --master)")
    if for_check:
        g.add_argument("--model", metavar="ROBOT.yaml", help="a system model file written by 'rubass model'")
    parser.add_argument("--master", metavar="URI", help="the master for --live (default: ROS_MASTER_URI)")
    parser.add_argument("--urdf", metavar="ROBOT.urdf", help="the robot's URDF: units of JointState fields by "
                                                              "joint kind (--live reads /robot_description)")


def build_model(args: argparse.Namespace, strict: bool = True) -> Tuple[Optional[SystemModel], int]:
    """The model the options name (None when none), or an exit status when it cannot be had;
    problems are printed."""
    urdf = getattr(args, "urdf", None)
    sourced = getattr(args, "bag", None) or getattr(args, "live", False) or getattr(args, "model", None)
    if urdf and not sourced:  # options without what they apply to are errors, not silently ignored
        print("rubass: error: --urdf needs --bag, --live or --model", file=sys.stderr)
        return None, 2
    if getattr(args, "master", None) and not getattr(args, "live", False):
        print("rubass: error: --master needs --live (it names the master to ask)", file=sys.stderr)
        return None, 2
    model, status = _build_model(args, strict)
    if model is None or not urdf:
        return model, status
    try:
        with open(urdf, encoding="utf-8") as fh:
            kinds = urdf_joint_kinds(fh.read())
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        print(f"rubass: error: {urdf}: {getattr(exc, 'strerror', None) or exc}", file=sys.stderr)
        return None, 2
    apply_joint_kinds(model, kinds)
    return model, 0


def _build_model(args: argparse.Namespace, strict: bool = True) -> Tuple[Optional[SystemModel], int]:
    try:
        if getattr(args, "bag", None):
            return bag_model(args.bag, strict), 0
        if getattr(args, "live", False):
            return live_model(args.master), 0
    except (BagError, LiveError) as exc:
        print(f"rubass: error: {exc}", file=sys.stderr)
        return None, 2
    path = getattr(args, "model", None)
    if not path:
        return None, 0
    src, diag = read_source(path, what="system model")
    if src is None and diag is not None and diag.message.startswith("cannot read"):
        print(f"rubass: error: {path}: {diag.message}", file=sys.stderr)  # as an unreadable --bag: 2
        return None, 2
    sources = SourceSet()
    if src is None:  # read, but not text
        model, diags = None, [diag] if diag else []
    else:
        model, diags = parse_model(sources.add(src))
    if model is None:
        for d in diags:
            print(d.render(sources), file=sys.stderr)
        n = len(diags)
        print(f"{path}: {n} error{'s' if n != 1 else ''}", file=sys.stderr)
        return None, 1
    undefined = model.undefined_types()
    if undefined:  # a hand-written model: what is installed here fills the gaps
        try_installed(model.registry, undefined, ())
    return model, 0


def cmd_model(args: argparse.Namespace) -> int:
    """Write the system model of a recording or of the live graph."""
    model, status = build_model(args)
    if model is None:
        return status or 2
    origin = f"recording {os.path.basename(args.bag)}" if args.bag else f"live graph ({model.source.split(' at ')[-1]})"
    text = dump_model(model, origin)
    if args.output in (None, "-"):
        sys.stdout.write(text)
    else:
        tmp = args.output + ".rubass-model.tmp"
        try:
            with open(tmp, "w", encoding="utf-8") as fh:
                fh.write(text)
            os.replace(tmp, args.output)
        except OSError as exc:
            print(f"rubass: error: cannot write {args.output}: {exc.strerror or exc}", file=sys.stderr)
            return 1
        print(f"{args.output}: {counted(len(model.topics), 'topic')}, "
              f"{'no node list' if model.nodes is None else counted(len(model.nodes), 'node')}, "
              f"{counted(len(model.registry.closure(model.topics.values())), 'message type')}", file=sys.stderr)
    missing = model.undefined_types()
    if missing:
        print(f"rubass: warning: no definition found for {', '.join(missing)}: their fields cannot be checked",
              file=sys.stderr)
    return 0


def register(sub: "argparse._SubParsersAction") -> None:
    """Add `rubass model` to the command line."""
    m = sub.add_parser("model", help="write a system model (topics, types, nodes) from a recording or the live graph",
                       description="Write a system model of a robot (its topics, their message types and "
                                   "definitions, its nodes) from a recording (--bag) or the running graph (--live), "
                                   "for `rubass check --model` with no ROS running (docs/model.md). Exit 0 written, "
                                   "2 a source that cannot be read.")
    add_source_options(m, for_check=False)
    m.add_argument("-o", "--output", metavar="ROBOT.yaml", help="write to this file (default: standard output)")
    m.set_defaults(func=cmd_model)
