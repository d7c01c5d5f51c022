"""Source files and positions: what every error points at."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Dict, List, Tuple


@dataclass(frozen=True)
class Span:
    """A place in a source file: 1-based line and column, and 0-based offsets."""

    file: str
    line: int
    col: int
    start: int = 0
    end: int = 0

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}"


NO_SPAN = Span("<none>", 0, 0)


class Source:
    """The text of one file, with offset to line/column mapping."""

    def __init__(self, name: str, text: str) -> None:
        self.name = name
        self.text = text
        self._line_starts: List[int] = [0]
        for i, ch in enumerate(text):
            if ch == "\n":
                self._line_starts.append(i + 1)

    def position(self, offset: int) -> Tuple[int, int]:
        """1-based (line, column) of an offset; columns count characters."""
        import bisect

        offset = max(0, min(offset, len(self.text)))
        idx = bisect.bisect_right(self._line_starts, offset) - 1
        return idx + 1, offset - self._line_starts[idx] + 1

    def span(self, start: int, end: int = -1) -> Span:
        line, col = self.position(start)
        return Span(self.name, line, col, start, start if end < 0 else end)

    def line_text(self, line: int) -> str:
        if line < 1 or line > len(self._line_starts):
            return ""
        start = self._line_starts[line - 1]
        stop = self.text.find("\n", start)
        return self.text[start:] if stop < 0 else self.text[start:stop]


class SourceSet:
    """Every file read in one run, so a diagnostic can quote its line."""

    def __init__(self) -> None:
        self._sources: Dict[str, Source] = {}

    def add(self, source: Source) -> Source:
        self._sources[source.name] = source
        return source

    def get(self, name: str) -> "Source | None":
        return self._sources.get(name)
