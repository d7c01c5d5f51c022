"""YAML with line numbers: mappings and lists remember where they and their items are."""
from __future__ import annotations

from typing import Any, Dict, List, Optional

import yaml

from ..lang.errors import RubassError


class TestFileError(RubassError):
    """A test file that cannot be run; rendered `FILE:LINE: error: MESSAGE`."""

    def __init__(self, path: str, line: int, message: str, fatal: bool = False) -> None:
        super().__init__(message)
        self.path, self.line, self.message = path, line, message
        self.fatal = fatal  # nothing more of the file can be read or checked
        self.before: List["TestFileError"] = []  # errors found before this one stopped the reading
        self.also = False  # said even after another error at its line (it cannot follow from that one)

    def render(self) -> str:
        return f"{self.path}:{self.line}: error: {self.message}" if self.line else f"{self.path}: error: {self.message}"


class LDict(dict):  # type: ignore[type-arg]
    """A mapping with its own line and the line of each key's value (1-based)."""

    line = 0

    def __init__(self) -> None:
        super().__init__()
        self.lines: Dict[Any, int] = {}
        self.key_lines: Dict[Any, int] = {}

    def at(self, key: Any) -> int:
        """The line of a key's value (a block value starts below its key)."""
        return self.lines.get(key, self.line)

    def key_at(self, key: Any) -> int:
        """The line of the key itself."""
        return self.key_lines.get(key, self.at(key))


class LList(list):  # type: ignore[type-arg]
    """A list with its own line and the line of each item (1-based)."""

    line = 0

    def __init__(self) -> None:
        super().__init__()
        self.lines: List[int] = []

    def at(self, i: int) -> int:
        return self.lines[i] if i < len(self.lines) else self.line


class _Loader(yaml.SafeLoader):
    pass


def _mapping(loader: _Loader, node: yaml.MappingNode) -> LDict:
    loader.flatten_mapping(node)
    out = LDict()
    out.line = node.start_mark.line + 1
    for key_node, value_node in node.value:
        key = loader.construct_object(key_node, deep=True)
        try:
            hash(key)
        except TypeError:
            raise TestFileError("", key_node.start_mark.line + 1, "a mapping key must be a plain value") from None
        if key in out:
            raise TestFileError("", key_node.start_mark.line + 1, f"duplicate key '{key}'")
        out[key] = loader.construct_object(value_node, deep=True)
        out.lines[key] = value_node.start_mark.line + 1
        out.key_lines[key] = key_node.start_mark.line + 1
    return out


def _sequence(loader: _Loader, node: yaml.SequenceNode) -> LList:
    out = LList()
    out.line = node.start_mark.line + 1
    for item in node.value:
        out.append(loader.construct_object(item, deep=True))
        out.lines.append(item.start_mark.line + 1)
    return out


def whole_text(text: str) -> Optional[str]:
    """`text` with each escaped surrogate pair (`"\\uD83D\\uDE00"`) made its character; None when it holds a
    lone surrogate (`"\\uD800"`): no character, so it can be neither printed nor written as UTF-8."""
    try:
        text.encode("utf-8")
        return text
    except UnicodeEncodeError:
        pass
    try:
        return text.encode("utf-16-le", "surrogatepass").decode("utf-16-le")
    except UnicodeDecodeError:
        return None


def _str(loader: _Loader, node: yaml.ScalarNode) -> str:
    text = whole_text(loader.construct_scalar(node))
    if text is None:
        raise TestFileError("", node.start_mark.line + 1, "a text holds a lone surrogate (an escape such as "
                                                          "\\uD800 that is no character): write the character itself")
    return text


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _mapping)
_Loader.add_constructor("tag:yaml.org,2002:str", _str)
_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_SEQUENCE_TAG, _sequence)


def load(path: str) -> Any:
    """The document of a YAML file, or TestFileError with the place."""
    from ..lang.sourcefile import read_source

    src, diag = read_source(path, what="test file")  # a directory, a FIFO, bad bytes: at their line
    if src is None:
        raise TestFileError(path, diag.span.line if diag is not None else 0,
                            diag.message if diag is not None else "cannot read it")
    text = src.text
    try:
        return yaml.load(text, Loader=_Loader)  # noqa: S506 (a SafeLoader subclass)
    except TestFileError as exc:
        raise TestFileError(path, exc.line, exc.message) from None
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else 0
        raise TestFileError(path, line, f"not valid YAML: {exc.problem or exc.context}") from None
    except yaml.YAMLError as exc:
        raise TestFileError(path, 0, f"not valid YAML: {exc}") from None
