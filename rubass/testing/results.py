"""Running test files: each file's spec, its tests' outcomes, or the error that stopped it."""
from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from typing import List, Optional, Sequence

from ..lang import SpecError, load_spec
from ..lang.model import CheckedSpec
from .coverage import unknown_covers
from .format import read_test_file
from .runner import Outcome, execute, prepare
from .yamlpos import TestFileError


@dataclass
class FileResult:
    path: str
    spec_path: str = ""
    spec: Optional[CheckedSpec] = None
    outcomes: List[Outcome] = field(default_factory=list)
    error: str = ""  # `FILE:LINE: error: …` when the file could not run
    warnings: List[str] = field(default_factory=list)


def run_file(path: str, extra_actions: Sequence[str] = ()) -> FileResult:
    """Every test of one file; on an error none of its tests runs and `error` says where."""
    result = FileResult(path)
    try:
        tf = read_test_file(path)
        result.spec_path = tf.spec
        try:
            spec = load_spec(tf.spec, list(tf.actions) + list(extra_actions), model=tf.model)
        except SpecError as exc:
            raise TestFileError(path, tf.spec_line, f"spec {tf.spec} cannot be used:\n{exc.render()}") from None
        result.spec = spec
        prepared = [prepare(spec, c, path, result.warnings) for c in tf.cases]
        for c in tf.cases:
            unknown = set(unknown_covers(spec, c.covers))
            for k, name in enumerate(c.covers):
                if name in unknown:
                    line = c.covers_lines[k] if k < len(c.covers_lines) else c.line
                    result.warnings.append(f"{path}:{line}: warning: test '{c.name}' covers '{name}', "
                                           f"which is no @id or @hazard of the spec")
    except TestFileError as exc:
        result.error = exc.render()
        return result
    except Exception as exc:  # a bug must not hide the other files' results behind a traceback
        result.error = f"{path}: error: internal error while reading the tests: {type(exc).__name__}: {exc}"
        return result
    for p in prepared:
        t0 = time.perf_counter()
        try:
            outcome = execute(p)
        except Exception as exc:
            outcome = Outcome(p.case.name, p.case.line, list(p.case.covers), passed=False,
                              problems=[f"internal error while running: {type(exc).__name__}: {exc}"])
        outcome.elapsed = time.perf_counter() - t0
        result.outcomes.append(outcome)
    return result


def shown_path(path: str) -> str:
    """A path as the user sees it: relative below the current directory, else absolute."""
    rel = os.path.relpath(path)
    return os.path.abspath(path) if rel == ".." or rel.startswith(".." + os.sep) else rel
