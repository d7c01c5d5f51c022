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
from ..lang.paths import file_arg
from ..lang.topicnames import resolve, spellings


def register(sub: "argparse._SubParsersAction[argparse.ArgumentParser]") -> None:
    p = sub.add_parser("replay", help="run a spec over a ROS 1 recording (no master needed)",
                       description="Evaluate SPEC over the messages of BAG at their recorded times, "
                                   "with ticks at the monitor's rate in between.")
    p.add_argument("spec", metavar="SPEC", type=file_arg)
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
    """The nodes that a monitor's recorded ~node_samples cover, resolved as that monitor resolved them."""
    from .run import monitor_of, resolve_node

    out: Set[str] = set()
    for _, topic, msg in samples:
        try:
            out.add(resolve_node(str(json.loads(msg.data)["node"]), monitor_of(topic)))
        except (ValueError, KeyError, TypeError, AttributeError):
            continue
    return out


def bag_type_errors(spec: Any, spec_path: str, actions: Sequence[str], bag: Any, bag_path: str, info: Any,
                    decode: Set[str], prog: str) -> List[str]:
    """The errors of SPEC read against the recording's types, each a complete line to print: an array used
    as a number, a wrong field path, a unit mismatch… at the spec's line, as `rubass check --bag` reports
    them (issue 20.6); a field the recording's classes lack. Every type recorded on a topic is checked
    (a topic may have connections of several types). Empty when the spec can read the recording.
    `rubass replay` and `rubass report --bag` both refuse a recording with such errors."""
    return bag_check(spec, spec_path, actions, bag, bag_path, info, decode, prog)[0]


def bag_check(spec: Any, spec_path: str, actions: Sequence[str], bag: Any, bag_path: str, info: Any,
              decode: Set[str], prog: str) -> Tuple[List[str], List[str]]:
    """(errors, warnings) of SPEC against the recording (bag_type_errors): the spec's errors as `rubass check
    --bag` gives them (load_spec_against), then fields its classes lack; the warnings are the spec's, as
    it prints them (in the order of the text), e.g. a stamp_age() that is always unknown."""
    from ..lang.errors import in_text_order
    from ..ros.bag import BagError, message_classes
    from ..ros.model_sources import bag_model, load_spec_against
    from ..ros.msgtypes import check_path

    try:
        classes = message_classes(bag, sorted(decode))
    except BagError as exc:
        return [f"{prog}: error: {exc}"], []
    try:  # the recording's types as a system model, and every other type recorded on one of its topics
        checked = load_spec_against(spec_path, list(actions), bag_model(bag_path, strict=False), bag_path)
    except SpecError as exc:  # each error against another type names it (as `rubass check --bag` says it)
        return [exc.render()], []
    except BagError as exc:
        return [f"{prog}: error: {exc}"], []
    warnings = [d.render(checked.sources) for d in in_text_order(checked.warnings)]
    errors: List[str] = []
    types = {t: [(getattr(c, '_type', info.types[t]), c)] for t, c in classes.items()}  # topic -> (type, class)…
    for topic, type_name, conn in _other_types(bag, info, decode):
        try:
            types.setdefault(topic, []).append((type_name, _class_of(conn)))
        except ValueError as exc:
            errors.append(f"{prog}: error: {bag_path}: topic {topic}: {exc}")
    readers = [((t, p), owners) for t, paths in spec.field_readers(implicit=False).items() for p, owners in paths.items()]
    for (topic, path), owners in sorted(readers, key=str):
        for type_name, cls in types.get(resolve(topic), ()):
            problem = check_path(cls, path)
            if problem:
                field = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in path)
                line = f"{prog}: error: {' and '.join(owners)} reads {topic}{field}, but in {type_name}: {problem}"
                if line not in errors:
                    errors.append(line)
    return errors, warnings


def _other_types(bag: Any, info: Any, topics: Set[str]) -> List[Tuple[str, str, Any]]:
    """(topic, type, a connection of it) for each type recorded on one of `topics` besides its first."""
    out: List[Tuple[str, str, Any]] = []
    seen = {(t, info.types.get(t)) for t in topics}
    for conn in getattr(bag, "_connections", {}).values():  # both readers keep the connections here
        if conn.topic in topics and (conn.topic, conn.datatype) not in seen:
            seen.add((conn.topic, conn.datatype))
            out.append((conn.topic, conn.datatype, conn))
    return sorted(out, key=lambda x: (x[0], x[1]))


def _class_of(conn: Any) -> Any:
    """A connection's message class, from its recorded definition; ValueError if there is none."""
    from ..ros.bagrecords import message_class

    try:
        return message_class(conn)
    except ImportError as exc:
        raise ValueError(f"{conn.datatype} needs ROS 1's Python message support, which this interpreter "
                         f"({sys.executable}) cannot import ({exc}): run rubass with /usr/bin/python3") from None
    except Exception as exc:  # genmsg errors on a broken recorded definition
        raise ValueError(f"no message class for {conn.datatype} ({exc.__class__.__name__}: {exc})") from None


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


def is_bag(path: str) -> bool:
    """Whether a file begins as a ROS 1 bag does (`#ROSBAG V`)."""
    try:
        with open(path, "rb") as fh:
            return fh.read(9) == b"#ROSBAG V"
    except OSError:
        return False  # the spec's loader says why it cannot be read


def run(args: argparse.Namespace) -> int:
    if is_bag(args.spec):
        print(f"rubass replay: error: {args.spec} is a ROS bag, not a spec (usage: rubass replay SPEC BAG)",
              file=sys.stderr)
        return 1
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
        elif spec.nodes:
            if not node_topics:  # the monitor samples the latest report at its own rate, not at each arrival
                print("rubass replay: warning: the recording has the agents' reports (/rubass/agent_samples) but "
                      "not the monitor's ~node_samples: each report counts from the instant it came, where the "
                      "monitor read the latest at its own ~node_rate, so a `for` over cpu() or memory() near its "
                      "edge may start or release at other instants, and a node the monitor found dead reads "
                      "unknown (docs/multihost.md); record ~node_samples too", file=sys.stderr)
            try:
                _warn_unsampled(spec.nodes, bag, node_topics, agent_topics)
            except BagError as exc:
                print(f"rubass replay: error: {exc}", file=sys.stderr)
                return 1
        present = [t for t in topic_map if t in info.types]
        decode: Set[str] = {t for t in present if any(spec.topics[n].needs_data for n in topic_map[t])}
        errors, warnings = bag_check(spec, args.spec, args.actions, bag, args.bag, info, decode, "rubass replay")
        if warnings or errors:
            print("\n".join(warnings + errors), file=sys.stderr)
        if errors:
            return 1
        from .run import replay

        if info.end - info.start > DAY:
            try:
                _warn_span(spec, bag, info, args.rate)
            except BagError as exc:
                print(f"rubass replay: error: {exc}", file=sys.stderr)
                return 1
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


DAY = 86400.0


def _warn_unsampled(nodes: Iterable[str], bag: Any, node_topics: List[str], agent_topics: List[str]) -> None:
    for text in unsampled_warnings(nodes, bag, node_topics, agent_topics):
        print(f"rubass replay: warning: {text}", file=sys.stderr)


def unsampled_warnings(nodes: Iterable[str], bag: Any, node_topics: List[str], agent_topics: List[str]) -> List[str]:
    """A warning for each node of the spec that no recorded node sample (a monitor's or an agent's) covers:
    its alive(), cpu() and memory() stay unknown in the replay. BagError if the bag cannot be read."""
    from ..ros.agentbook import decode as decode_report
    from ..ros.bag import read
    from .run import resolve_node

    covered = _sampled_nodes(read(bag, node_topics, set(node_topics)))
    for _, _, msg in read(bag, agent_topics, set(agent_topics)):
        try:
            covered.update(resolve_node(n) for n in decode_report(msg.data).nodes)
        except (ValueError, AttributeError):
            continue
    return [f"the recording has node samples, but none of node {node} ({resolve_node(node)}); its alive(), "
            f"cpu() and memory() stay unknown" for node in sorted(nodes) if resolve_node(node) not in covered]


def _warn_span(spec: Any, bag: Any, info: Any, rate: float) -> None:
    """A warning for a recording that spans more than a day (often one stray timestamp): its span, its
    longest gap between two messages and about how long the ticks across it take. It reads the bag's
    timestamps once (no message is decoded); BagError if it cannot."""
    import time

    from ..engine import Engine
    from ..ros.bag import read

    last, gap = info.start, (0.0, info.start, info.start)
    for stamp, _, _ in read(bag, sorted(info.types), set()):
        if stamp - last > gap[0]:
            gap = (stamp - last, last, stamp)
        last = stamp
    engine, n = Engine(spec, 0.0), 2000  # a tick's cost, measured on the spec itself
    began = time.process_time()
    for i in range(1, n + 1):
        engine.on_tick(i / rate)
    per_tick = (time.process_time() - began) / n
    print(f"rubass replay: warning: the recording spans {_span(info.end - info.start)}; its longest gap, "
          f"{_span(gap[0])} with no message, is from {gap[1]:.3f} to {gap[2]:.3f} (bag time, s): ticking "
          f"across it at {rate:g} Hz takes about {_span(gap[0] * rate * per_tick)} (a stray timestamp? "
          f"`rosbag filter` can cut it out)", file=sys.stderr)


def _span(seconds: float) -> str:
    """A duration for people: 3.2 s, 5.0 min, 2.1 h, 20454.9 days."""
    for unit, size in (("days", DAY), ("h", 3600.0), ("min", 60.0)):
        if seconds >= 2 * size:
            return f"{seconds / size:.1f} {unit}"
    return f"{seconds:.1f} s"


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
