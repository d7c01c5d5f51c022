"""`rubass replay SPEC BAG [--json] [--plot FILE.png] [--actions LIB.yaml] [--rate HZ]`."""
from __future__ import annotations

import argparse
import gc
import json
import os
import sys
from contextlib import contextmanager
from typing import Any, Iterable, Iterator, List, Sequence, Set, Tuple

from ..lang import SpecError, load_spec
from . import report
from ..lang.topicnames import resolve, spellings


def register(sub: "argparse._SubParsersAction[argparse.ArgumentParser]") -> None:
    p = sub.add_parser("replay", help="run a spec over a ROS 1 recording (no master needed)",
                       description="Evaluate SPEC over the messages of BAG at their recorded times, "
                                   "with ticks at the monitor's rate in between.")
    p.add_argument("spec", metavar="SPEC")
    p.add_argument("bag", metavar="BAG")
    p.add_argument("--json", action="store_true", help="print one JSON object per line (docs/replay.md)")
    p.add_argument("--plot", metavar="FILE.png", type=plot_path,
                   help="write a timeline picture (.png, .pdf, .svg, .jpg; .png if the name has none)")
    p.add_argument("--actions", action="append", default=[], metavar="LIB.yaml",
                   help="an action library to load besides the spec's imports (repeatable)")
    p.add_argument("--rate", type=_rate, default=50.0, metavar="HZ", help="tick rate (default 50)")
    p.set_defaults(func=run)


def _rate(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number of Hz") from None
    if not 0.1 <= value <= 10000:
        raise argparse.ArgumentTypeError(f"{value} Hz is out of range (0.1 to 10000)")
    return value


def _sampled_nodes(samples: Iterable[Tuple[float, str, Any]]) -> Set[str]:
    """The nodes that a monitor's recorded ~node_samples cover."""
    out: Set[str] = set()
    for _, _, msg in samples:
        try:
            out.add(str(json.loads(msg.data)["node"]))
        except (ValueError, KeyError, TypeError, AttributeError):
            continue
    return out


def bag_type_errors(spec: Any, spec_path: str, actions: Sequence[str], bag: Any, bag_path: str, info: Any,
                    decode: Set[str], prog: str) -> List[str]:
    """The errors of SPEC read against the recording's types, each a complete line to print: an array used
    as a number, a wrong field path, a unit mismatch… at the spec's line, as `rubass check --bag` reports
    them (issue 20.6); a field the recording's classes lack. Empty when the spec can read the recording.
    `rubass replay` and `rubass report --bag` both refuse a recording with such errors."""
    from ..ros.bag import BagError, message_classes
    from ..ros.model_sources import bag_model
    from ..ros.msgtypes import check_path

    try:
        classes = message_classes(bag, sorted(decode))
    except BagError as exc:
        return [f"{prog}: error: {exc}"]
    try:  # the recording's types as a system model
        load_spec(spec_path, list(actions), model=bag_model(bag_path))
    except SpecError as exc:
        return [exc.render()]
    except BagError as exc:
        return [f"{prog}: error: {exc}"]
    errors = []
    readers = [((t, p), owners) for t, paths in spec.field_readers(implicit=False).items() for p, owners in paths.items()]
    for (topic, path), owners in sorted(readers, key=str):
        cls = classes.get(resolve(topic))
        problem = check_path(cls, path) if cls is not None else None
        if problem:
            field = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in path)
            errors.append(f"{prog}: error: {' and '.join(owners)} reads {topic}{field}, but in "
                          f"{info.types[resolve(topic)]}: {problem}")
    return errors


@contextmanager
def _fewer_collections() -> Iterator[None]:
    """Python's cyclic garbage collector run less often: a replay allocates millions of
    short-lived objects (messages, tuples) and makes few cycles; this saves ~10 % of its time."""
    before = gc.get_threshold()
    gc.set_threshold(50000, *before[1:])
    try:
        yield
    finally:
        gc.set_threshold(*before)


def run(args: argparse.Namespace) -> int:
    try:
        spec = load_spec(args.spec, args.actions)
    except SpecError as exc:
        print(exc.render(), file=sys.stderr)
        return 1
    from ..ros.bag import BagError, open_bag, read

    try:
        bag, info = open_bag(args.bag)
    except BagError as exc:
        print(f"rubass replay: error: {exc}", file=sys.stderr)
        return 1
    with bag:
        topic_map = spellings(spec.topics)  # bag name -> every spelling of it in the spec (docs/replay.md)
        for name in sorted(topic_map):
            if name not in info.types:
                print(f"rubass replay: warning: topic {name} is not in {args.bag}; its fields stay unknown and "
                      f"its age() grows from the recording's start",
                      file=sys.stderr)
        node_topics = sorted(t for t, ty in info.types.items() if t.endswith("/node_samples") and ty == "std_msgs/String")
        agent_topics = sorted(t for t, ty in info.types.items()
                              if t.endswith("/agent_samples") and ty == "std_msgs/String")
        if spec.nodes and not node_topics and not agent_topics:
            print("rubass replay: warning: the recording has no node samples (a monitor's ~node_samples or the "
                  "agents' /rubass/agent_samples); alive(), cpu() and memory() stay unknown", file=sys.stderr)
        present = [t for t in topic_map if t in info.types]
        decode: Set[str] = {t for t in present if any(spec.topics[n].needs_data for n in topic_map[t])}
        errors = bag_type_errors(spec, args.spec, args.actions, bag, args.bag, info, decode, "rubass replay")
        if errors:
            print("\n".join(errors), file=sys.stderr)
            return 1
        from .run import replay

        node_topics = node_topics if spec.nodes else []
        agent_topics = agent_topics if spec.nodes else []
        stream: Iterable[Tuple[float, str, Any]] = read(bag, present + node_topics + agent_topics,
                                                        decode | set(node_topics) | set(agent_topics),
                                                        set(agent_topics))  # an agent's report counts from itself only
        if agent_topics:  # multi-host: the agents' reports, for the nodes the monitor's samples do not cover
            from .agents import SAMPLES, agent_samples

            try:
                skip = _sampled_nodes(read(bag, node_topics, set(node_topics)))
            except BagError as exc:
                print(f"rubass replay: error: {exc}", file=sys.stderr)
                return 1
            stream = agent_samples(stream, set(agent_topics), {resolve(n): n for n in spec.nodes}, skip, info.end,
                                   lambda text: print(f"rubass replay: warning: {text}", file=sys.stderr),
                                   keep=set(agent_topics) & set(present))  # a spec may time the reports too
            node_topics = node_topics + [SAMPLES]
        if any(names != [name] for name, names in topic_map.items()):  # relative, private or several spellings
            stream = ((t, name, msg) for t, topic, msg in stream for name in topic_map.get(topic, (topic,)))
        try:
            with _fewer_collections():
                _, events = replay(spec, stream, info.start, info.end, args.rate, node_topics)
        except BagError as exc:
            print(f"rubass replay: error: {exc}", file=sys.stderr)
            return 1
    duration = info.end - info.start
    if args.json:
        report.json_lines(events, sys.stdout)
    else:
        print(f"replay of {args.spec} over {args.bag}: {duration:.3f} s, {info.messages} "
              f"message{'s' if info.messages != 1 else ''}")
        report.human(spec, events, duration, sys.stdout)
    if args.plot:
        from .plot import plot

        try:
            plot(spec, events, duration, args.plot, title=f"{args.spec} over {args.bag}")
        except (OSError, ValueError) as exc:  # a full disk, a format the plotting back end lacks
            print(f"rubass replay: error: cannot write {args.plot}: {getattr(exc, 'strerror', None) or exc}",
                  file=sys.stderr)
            return 1
        if not args.json:
            print(f"timeline written to {args.plot}")
    return 0


PLOT_FORMATS = ("png", "pdf", "svg", "jpg", "jpeg")


def plot_path(path: str) -> str:
    """The timeline's file: .png when it names no format; an argparse error for a folder or a
    format matplotlib cannot write (checked before the replay, not after it)."""
    if os.path.isdir(path):
        raise argparse.ArgumentTypeError(f"{path} is a folder: name the image file, e.g. {path.rstrip('/')}/timeline.png")
    ext = os.path.splitext(path)[1].lower().lstrip(".")
    if not ext:
        return path + ".png"
    if ext not in PLOT_FORMATS:
        raise argparse.ArgumentTypeError(f"cannot write a timeline as '.{ext}': use one of "
                                         f"{', '.join('.' + f for f in PLOT_FORMATS)}")
    return path
