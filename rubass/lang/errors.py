"""The error hierarchy: every spec or library problem is a Diagnostic with a place."""
from __future__ import annotations

import difflib
from dataclasses import dataclass, field
from typing import Dict, Iterable, List, Optional, Sequence

from .source import Span, SourceSet


@dataclass(frozen=True)
class Diagnostic:
    """One message about one place: an error or a warning."""

    span: Span
    message: str
    severity: str = "error"
    # the source line, for a file that could not be read as text (so it is in no SourceSet)
    line_text: str = field(default="", compare=False)
    # what it is about, for code that must know without reading the text: an action's name
    subject: str = field(default="", compare=False)

    def render(self, sources: Optional[SourceSet] = None) -> str:
        """Compiler-style text: header, the source line, a caret under the column."""
        if self.span.line <= 0:
            return f"{self.span.file}: {self.severity}: {self.message}"
        head = f"{self.span}: {self.severity}: {self.message}"
        src = sources.get(self.span.file) if sources else None
        if src is None and not self.line_text:
            return head
        line = src.line_text(self.span.line) if src is not None else self.line_text
        if len(line) > 200:
            lo = max(0, self.span.col - 100)
            line, col = line[lo:lo + 200], self.span.col - lo
        else:
            col = self.span.col
        line = line.expandtabs(1).replace("\r", " ")
        caret = " " * (max(col, 1) - 1) + "^"
        return f"{head}\n    {line}\n    {caret}"


class RubassError(Exception):
    """Base of every error rubass raises on purpose."""


class SpecError(RubassError):
    """A spec, or an action library it uses, has errors; carries all of them."""

    def __init__(self, diagnostics: Sequence[Diagnostic], sources: Optional[SourceSet] = None,
                 warnings: Sequence[Diagnostic] = ()) -> None:
        self.diagnostics: List[Diagnostic] = list(diagnostics)  # the errors
        self.warnings: List[Diagnostic] = [w for w in warnings if w not in self.diagnostics]
        self.sources = sources
        super().__init__(self.render())

    def render(self) -> str:
        """The errors, and the warnings beside them in the order of the text."""
        return "\n".join(d.render(self.sources) for d in self.in_order())

    def in_order(self) -> List[Diagnostic]:
        """Errors and warnings by file (in the errors' order of files) and position."""
        if not self.warnings:
            return self.diagnostics
        return in_text_order(self.diagnostics + self.warnings)


def in_text_order(diags: Sequence[Diagnostic]) -> List[Diagnostic]:
    """Diagnostics by file (files in the order they first come) and position in it."""
    files: Dict[str, int] = {}
    for d in diags:
        files.setdefault(d.span.file, len(files))
    return sorted(diags, key=lambda d: (files[d.span.file], d.span.line, d.span.col))


def counted(n: int, noun: str) -> str:
    """'1 rule', '2 rules' (a noun whose plural takes an s)."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def a_noun(noun: str) -> str:
    """The noun with its indefinite article: 'a time', 'an entity', 'an angle', 'a quantity in m*s'."""
    if any(c in noun for c in "*^") or not noun[:1].isalpha():  # a formula of units, such as m*s or m^3
        return f"a quantity in {noun}"
    low = noun.lower()
    vowel = low[:1] in "aeiou" and not low.startswith(("uni", "uint", "use", "usu", "one", "eu"))  # 'a unit'
    return ("an " if vowel else "a ") + noun


def did_you_mean(name: str, candidates: Iterable[str]) -> str:
    """A suggestion suffix for an unknown name, or '' when nothing is close."""
    close = difflib.get_close_matches(name, sorted(set(candidates)), n=1, cutoff=0.6)
    return f"; did you mean '{close[0]}'?" if close else ""
