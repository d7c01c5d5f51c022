"""The risk-assessment table of `rubass report --hazards`, read with every error at its place.

`hazards: [{id: H1, title: …, severity: S2, exposure: F1, avoidance: P2, …}, …]`: each id a text, once; a
title; severity, exposure and avoidance (when given) the parameters of the ISO 13849-1 risk graph; any
other key a plain value shown beside the hazard. Every error is `FILE:LINE:COL: error: …`, all at once.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple

import yaml

from ..lang.errors import RubassError
from ..testing.yamlpos import whole_text

STR = "tag:yaml.org,2002:str"
NULL = "tag:yaml.org,2002:null"

# ISO 13849-1, the risk graph (annex A) that gives the required performance level PLr
LEVELS: Dict[str, Dict[str, str]] = {
    "severity": {"S1": "slight, normally reversible injury", "S2": "serious, irreversible injury or death"},
    "exposure": {"F1": "seldom to less often, or short exposure", "F2": "frequent to continuous, or long exposure"},
    "avoidance": {"P1": "possible under specific conditions", "P2": "scarcely possible"},
}


@dataclass
class Hazard:
    id: str
    title: str = ""
    details: Dict[str, str] = field(default_factory=dict)  # severity, exposure… from the risk table


class HazardsError(RubassError):
    """A risk table that cannot be used: every error, each `FILE:LINE:COL: error: …`."""

    def __init__(self, lines: List[str]) -> None:
        super().__init__("\n".join(lines))
        self.lines = lines


def read_hazards(path: str) -> List[Hazard]:
    """The hazards of a risk table, or HazardsError with every error of the file at its place."""
    try:
        with open(path, encoding="utf-8") as fh:
            text = fh.read()
    except OSError as exc:
        raise HazardsError([f"{path}: error: cannot read the risk table: {exc.strerror or exc}"]) from None
    except UnicodeDecodeError as exc:
        line = text_line(exc.object, exc.start) if isinstance(exc.object, bytes) else 1
        raise HazardsError([f"{path}:{line}:1: error: not a text file (bytes that are not UTF-8)"]) from None
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"{path}:{mark.line + 1}:{mark.column + 1}" if mark is not None else path
        ctx = exc.context_mark
        opened = (f" ({exc.context} at {ctx.line + 1}:{ctx.column + 1})" if exc.problem and exc.context and ctx is not None
                  else "")
        raise HazardsError([f"{where}: error: not valid YAML: {exc.problem or exc.context}{opened}"]) from None
    except yaml.YAMLError as exc:
        raise HazardsError([f"{path}: error: not valid YAML: {exc}"]) from None
    lone = _lone_surrogates(root)
    if lone:
        raise HazardsError([f"{path}:{n.start_mark.line + 1}:{n.start_mark.column + 1}: error: a text holds a lone "
                            f"surrogate (an escape such as \\uD800 that is no character): write the character itself"
                            for n in lone])
    reader = _Reader(path)
    out = reader.table(root)
    if reader.errors:
        n = len(reader.errors)
        raise HazardsError(reader.errors + ([f"{path}: {n} errors"] if n > 1 else []))
    return out


def _lone_surrogates(root: Optional[yaml.Node]) -> List[yaml.Node]:
    """The text scalars holding a lone surrogate (`"\\uD800"`): no character, the page could not be written;
    an escaped pair is made its character in place."""
    out: List[yaml.Node] = []
    stack = [root] if root is not None else []
    seen = set()
    while stack:
        node = stack.pop()
        if id(node) in seen:  # an alias: the node again
            continue
        seen.add(id(node))
        if isinstance(node, yaml.ScalarNode):
            text = whole_text(node.value)
            if text is None:
                out.append(node)
            else:
                node.value = text
        elif isinstance(node, yaml.MappingNode):
            stack.extend(n for pair in node.value for n in pair)
        elif isinstance(node, yaml.SequenceNode):
            stack.extend(node.value)
    return sorted(out, key=lambda n: (n.start_mark.line, n.start_mark.column))


def text_line(data: bytes, offset: int) -> int:
    return data[:offset].count(b"\n") + 1


class _Reader:
    def __init__(self, path: str) -> None:
        self.path = path
        self.found: List[Tuple[int, int, str]] = []

    @property
    def errors(self) -> List[str]:
        """The errors in the order of the text."""
        return [text for _, _, text in sorted(self.found, key=lambda f: (f[0], f[1]))]

    def at(self, node: Any) -> str:
        return f"{self.path}:{node.start_mark.line + 1}:{node.start_mark.column + 1}"

    def error(self, node: Any, message: str) -> None:
        self.found.append((node.start_mark.line, node.start_mark.column, f"{self.at(node)}: error: {message}"))

    def table(self, root: Optional[yaml.Node]) -> List[Hazard]:
        expected = "expected 'hazards:' with a list of hazards ({id: H1, title: …, severity: S2, …})"
        if root is None:
            self.found.append((0, 0, f"{self.path}:1:1: error: the risk table is empty: {expected}"))
            return []
        if not isinstance(root, yaml.MappingNode):
            self.error(root, f"{expected}, not {_kind(root)}")
            return []
        items: Optional[yaml.Node] = None
        for key, value in root.value:
            if getattr(key, "value", None) == "hazards":
                items = value
            else:
                self.error(key, f"unknown key '{getattr(key, 'value', '?')}': {expected}")
        if items is None:
            if not root.value:
                self.error(root, expected)
            return []
        if not isinstance(items, yaml.SequenceNode):
            self.error(items, f"expected 'hazards:' to be a list of hazards ({{id: H1, title: …}}), not {_kind(items)}")
            return []
        out: List[Hazard] = []
        first: Dict[str, str] = {}
        for i, item in enumerate(items.value):
            hazard, id_node = self.hazard(i + 1, item)
            if id_node is None:
                continue
            if id_node.value in first:
                self.error(id_node, f"hazard {id_node.value} is given twice; first at {first[id_node.value]} (each id "
                                    f"once: the matrix would not know which row is meant)")
                continue
            first[id_node.value] = self.at(id_node)
            if hazard is not None:
                out.append(hazard)
        return out

    def hazard(self, number: int, node: yaml.Node) -> Tuple[Optional[Hazard], Optional[yaml.Node]]:
        """The hazard (None when it has an error) and its id's node (None when it has no valid id)."""
        if not isinstance(node, yaml.MappingNode):
            self.error(node, f"hazard {number} must be a mapping {{id: H1, title: …}}, not {_kind(node)}")
            return None, None
        fields: Dict[str, Any] = {}
        for key, value in node.value:
            name = key.value if isinstance(key, yaml.ScalarNode) else None
            if not isinstance(name, str) or key.tag != STR:
                self.error(key, f"hazard {number}: a key must be a name (id, title, severity…), not {_kind(key)}")
                continue
            if name in fields:
                self.error(key, f"hazard {number}: '{name}' is given twice; first at {self.at(fields[name][0])}")
                continue
            fields[name] = (key, value)
        ok = True
        id_node = fields.get("id", (None, None))[1]
        if id_node is None:
            self.error(node, f"hazard {number} has no id (id: H…, the id that rules name with @hazard(\"H…\"))")
            ok = False
        elif not (isinstance(id_node, yaml.ScalarNode) and id_node.tag == STR and id_node.value.strip()):
            shown = id_node.value if isinstance(id_node, yaml.ScalarNode) and id_node.tag != STR else ""
            hint = f" ({shown}): write id: '{shown}' or id: H{shown}" if shown else ""
            kind = "an empty text" if id_node.tag == STR else _kind(id_node)
            self.error(id_node, f"hazard {number}: the id must be a text (as @hazard(\"…\") names it), not "
                                f"{kind}{hint}")
            ok = False
        title_node = fields.get("title", (None, None))[1]
        if title_node is None:
            self.error(node, f"hazard {number}{f' ({id_node.value})' if ok else ''} has no title (title: what can "
                             f"go wrong, as in the risk assessment)")
            ok = False
        elif not (isinstance(title_node, yaml.ScalarNode) and title_node.tag != NULL and title_node.value.strip()):
            self.error(title_node, f"hazard {number}: the title must be a text, not {_kind(title_node)}")
            ok = False
        details: Dict[str, str] = {}
        for name, (key, value) in fields.items():
            if name in ("id", "title"):
                continue
            if not isinstance(value, yaml.ScalarNode) or value.tag == NULL or not value.value.strip():
                self.error(value if value.tag != NULL else key,
                           f"hazard {number}: '{name}' must be a plain value shown beside the hazard, not "
                           f"{_kind(value)}")
                ok = False
                continue
            allowed = LEVELS.get(name)
            if allowed is not None and value.value not in allowed:
                self.error(value, f"hazard {number}: {name} '{value.value}' is not one of "
                                  f"{', '.join(f'{k} ({v})' for k, v in allowed.items())} (ISO 13849-1 risk graph)")
                ok = False
                continue
            details[name] = value.value
        good_id = id_node if id_node is not None and id_node.tag == STR and id_node.value.strip() else None
        if not ok:
            return None, good_id
        return Hazard(id_node.value, title_node.value, details), good_id


def _kind(node: yaml.Node) -> str:
    if isinstance(node, yaml.MappingNode):
        return "a mapping"
    if isinstance(node, yaml.SequenceNode):
        return "a list"
    if node.tag == NULL:
        return "empty"
    if node.tag == STR:
        return "a text" if node.value.strip() else "an empty text"  # `title: ""`, `plr: "  "`
    kind = node.tag.rsplit(":", 1)[-1]
    return {"int": "a number", "float": "a number", "bool": "true/false"}.get(kind, f"a {kind}")
