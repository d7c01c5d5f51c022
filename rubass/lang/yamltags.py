"""YAML tags: which nodes of a composed document a safe loader cannot build (python/object,
custom '!tags'), so that a file is reported as an error rather than a loader traceback."""
from __future__ import annotations

from typing import AbstractSet, Any, Dict, Iterator, List, Set, Tuple

import yaml

_CORE = "tag:yaml.org,2002:"
PLAIN_TAGS = frozenset(_CORE + t for t in ("str", "int", "float", "bool", "null", "seq", "map"))
SAFE_TAGS = PLAIN_TAGS | {_CORE + t for t in ("binary", "timestamp", "set", "omap", "pairs", "merge", "value")}


def nodes_once(root: yaml.Node) -> Iterator[yaml.Node]:
    """Every node of a composed document, each once (alias bombs are DAGs); a node's children are
    read after it is yielded, so a caller may rewrite a mapping's value (merge keys) on the way."""
    seen, todo = set(), [root]
    while todo:
        node = todo.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        yield node
        if isinstance(node, yaml.MappingNode):
            todo += [n for pair in node.value for n in pair]
        elif isinstance(node, yaml.SequenceNode):
            todo += list(node.value)


def foreign_tags(root: yaml.Node, allowed: AbstractSet[str] = SAFE_TAGS) -> List[yaml.Node]:
    """The nodes whose tag is not allowed, in file order."""
    return sorted((n for n in nodes_once(root) if n.tag not in allowed), key=lambda n: n.start_mark.index)


def plain_value(node: yaml.Node) -> Any:
    """The Python value of a composed node (a safe loader builds it). The loader is disposed of
    after: an undisposed loader refers to itself, so it, the node and the whole file it read
    would wait for the cyclic garbage collector (a reload's garbage would pile up until then)."""
    loader = yaml.SafeLoader("")
    try:
        return loader.construct_object(node, deep=True)
    finally:
        loader.dispose()


MERGE = _CORE + "merge"


def resolve_merges(root: yaml.Node) -> List[yaml.Node]:
    """Apply YAML merge keys (`<<: *base`, `<<: [*a, *b]`) in place, in every mapping of a
    composed document; the nodes of merge keys whose value is no mapping (or list of them).

    A key written in the mapping wins over a merged one, and an earlier merged mapping over a
    later one, as YAML says. Each mapping is merged once and its keys are kept once, so a file
    of aliases that merge each other many times (an alias bomb) stays as small as its text.
    """
    bad: List[yaml.Node] = []
    done: Set[int] = set()
    for node in nodes_once(root):
        if isinstance(node, yaml.MappingNode):
            _merge(node, done, bad)
    return bad


def _merge(node: yaml.MappingNode, done: Set[int], bad: List[yaml.Node]) -> None:
    """resolve_merges for one mapping, its merged mappings first (a module function: a nested
    recursive one would be a reference cycle, garbage at every reload)."""
    if id(node) in done:
        return
    done.add(id(node))
    own: List[Any] = []
    merged: List[Any] = []
    for key, value in node.value:
        if key.tag != MERGE:
            own.append((key, value))
            continue
        sources = value.value if isinstance(value, yaml.SequenceNode) else [value]
        for src in sources:
            if not isinstance(src, yaml.MappingNode):
                bad.append(value)
                break
            _merge(src, done, bad)
            merged += src.value
    seen = {k.value for k, _ in own if isinstance(k, yaml.ScalarNode)}
    for key, value in merged:
        name = key.value if isinstance(key, yaml.ScalarNode) else None
        if name is None or name not in seen:
            seen.add(name)
            own.append((key, value))
    node.value = own


def duplicate_keys(root: yaml.Node) -> List[Tuple[yaml.Node, yaml.Node, yaml.Node]]:
    """(mapping, second key, first key) for each scalar key written again in one mapping, in
    file order (YAML loaders keep the last silently). Merge keys ('<<') are not counted: call
    this before resolve_merges. Each mapping is looked at once (alias bombs are DAGs)."""
    out: List[Tuple[yaml.Node, yaml.Node, yaml.Node]] = []
    for node in nodes_once(root):
        if not isinstance(node, yaml.MappingNode):
            continue
        first: Dict[Any, yaml.Node] = {}
        for key, _ in node.value:
            if not isinstance(key, yaml.ScalarNode) or key.tag == MERGE:
                continue
            ident = (key.tag, key.value)
            if ident in first:
                out.append((node, key, first[ident]))
            else:
                first[ident] = key
    return sorted(out, key=lambda t: t[1].start_mark.index)
