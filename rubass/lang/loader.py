"""One call from a file name to a checked spec: read, parse, load libraries, check."""
from __future__ import annotations

from typing import Optional, Sequence

from .checker import check
from .errors import SpecError
from .fieldmodel import FieldModel
from .grammar import parse_source
from .model import CheckedSpec
from .source import Source, SourceSet
from .sourcefile import read_source


def load_spec(path: str, extra_libraries: Sequence[str] = (), model: Optional[FieldModel] = None) -> CheckedSpec:
    """A checked spec, or SpecError carrying every error found (warnings stay on the result)."""
    sources = SourceSet()
    src, diag = read_source(path)
    if src is None:
        assert diag is not None
        raise SpecError([diag], sources)
    return check_source(src, extra_libraries, sources, model)


def check_source(src: Source, extra_libraries: Sequence[str] = (), sources: Optional[SourceSet] = None,
                 model: Optional[FieldModel] = None) -> CheckedSpec:
    """Parse and check text already read (the file name in src anchors relative imports)."""
    sources = sources or SourceSet()
    sources.add(src)
    try:
        spec = parse_source(src)
    except SpecError as exc:
        raise SpecError(exc.diagnostics, sources) from None
    checked, errors, warnings = check(spec, sources, extra_libraries, model)
    if checked is None:  # the warnings go beside the errors (SpecError.render)
        raise SpecError(errors, sources, warnings)
    return checked


def check_text(text: str, name: str = "<string>", extra_libraries: Sequence[str] = ()) -> CheckedSpec:
    """Parse and check spec text (tests and tools)."""
    return check_source(Source(name, text), extra_libraries)
