"""YAML tags: which nodes of a composed document a safe loader cannot build (python/object,
custom '!tags'), so that a file is reported as an error rather than a loader traceback."""
from __future__ import annotations

from typing import AbstractSet, Any, List

import yaml

_CORE = "tag:yaml.org,2002:"
PLAIN_TAGS = frozenset(_CORE + t for t in ("str", "int", "float", "bool", "null", "seq", "map"))
SAFE_TAGS = PLAIN_TAGS | {_CORE + t for t in ("binary", "timestamp", "set", "omap", "pairs", "merge", "value")}


def foreign_tags(root: yaml.Node, allowed: AbstractSet[str] = SAFE_TAGS) -> List[yaml.Node]:
    """The nodes whose tag is not allowed, in file order; each node once (alias bombs are DAGs)."""
    seen, out, todo = set(), [], [root]
    while todo:
        node = todo.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if node.tag not in allowed:
            out.append(node)
        if isinstance(node, yaml.MappingNode):
            todo += [n for pair in node.value for n in pair]
        elif isinstance(node, yaml.SequenceNode):
            todo += list(node.value)
    return sorted(out, key=lambda n: n.start_mark.index)


def plain_value(node: yaml.Node) -> Any:
    """The Python value of a composed node (a safe loader builds it). The loader is disposed of
    after: an undisposed loader refers to itself, so it, the node and the whole file it read
    would wait for the cyclic garbage collector (a reload's garbage would pile up until then)."""
    loader = yaml.SafeLoader("")
    try:
        return loader.construct_object(node, deep=True)
    finally:
        loader.dispose()
