"""Running test files: each file's spec, its tests' outcomes, or the error that stopped it."""
from __future__ import annotations

import difflib
import os
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Set

from ..lang import SpecError, load_spec
from ..lang.model import CheckedSpec
from .coverage import traced, unknown_covers
from .declared import declared_model, per_test_models
from .cases import Case, TestFile
from .format import read_test_file
from .runner import Outcome, execute, prepare_all
from .yamlpos import TestFileError


@dataclass
class FileResult:
    path: str
    spec_path: str = ""
    spec: Optional[CheckedSpec] = None
    outcomes: List[Outcome] = field(default_factory=list)
    error: str = ""  # `FILE:LINE: error: …` when the file could not run
    error_count: int = 0  # how many errors `error` says (a spec's own errors count as the one at `spec:`)
    warnings: List[str] = field(default_factory=list)


def run_file(path: str, extra_actions: Sequence[str] = ()) -> FileResult:
    """Every test of one file; on errors none of its tests runs and `error` gives every one of them,
    in line order (`FILE:LINE: error: …` each)."""
    result = FileResult(path)
    try:
        tf = read_test_file(path)
        errors: List[TestFileError] = list(tf.errors)
        result.spec_path = tf.spec
        spec = _load_spec(tf, list(tf.actions) + list(extra_actions), errors) if tf.spec else None
        result.spec = spec
        prepared = []
        if spec is not None:
            for c in tf.cases:
                p = prepare_all(spec, c, path, result.warnings, errors)
                if p is not None:
                    prepared.append(p)
                    if not c.expects:
                        result.warnings.append(_expects_nothing(c, path))
            result.warnings += _unknown_covers(spec, tf, path)
        if errors:
            rendered = _rendered(errors)
            result.error, result.error_count = "\n".join(rendered), len(rendered)
            return result
    except TestFileError as exc:  # the file cannot be read at all
        rendered = _rendered(exc.before + [exc])
        result.error, result.error_count = "\n".join(rendered), len(rendered)
        return result
    except Exception as exc:  # a bug must not hide the other files' results behind a traceback
        result.error = f"{path}: error: internal error while reading the tests: {type(exc).__name__}: {exc}"
        result.error_count = 1
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


def _rendered(errors: List[TestFileError]) -> List[str]:
    """The first error of each line, in line order (a second one at a line mostly follows from the first:
    `{at: 2 s, strat: x}` lacks a start because of its typo), and those that cannot follow from it (`also`:
    a negative `at` beside that typo)."""
    out: Dict[int, List[str]] = {}
    for e in sorted(errors, key=lambda e: e.line):
        said = out.setdefault(e.line, [])
        if not said or (e.also and e.render() not in said):
            said.append(e.render())
    return [text for line in sorted(out) for text in out[line]]


def _load_spec(tf: TestFile, actions: List[str], errors: List[TestFileError]) -> Optional[CheckedSpec]:
    """The spec to run (checked against the file's `model:` when it names one), then checked against the
    types the file's topics declare, with their standard units, as `rubass replay` checks it against a
    recording's (the spec that runs is the one the monitor would run); its errors as one error at the
    `spec:` line. A topic two tests type differently is checked with each test's own types: each error
    once, naming the first test whose types show it."""
    model = declared_model(tf)
    try:
        spec = load_spec(tf.spec, actions, model=model if tf.model is not None else None)
    except SpecError as exc:
        errors.append(TestFileError(tf.path, tf.spec_line, _spec_error(tf.spec, "cannot be used", exc)))
        return None
    said: Set[str] = set()
    checks = [("this file declares", model)] if model is not None and tf.model is None else []
    checks += [(f"test '{case.name}' (line {case.line}) declares", m) for case, m in per_test_models(tf)]
    for whose, m in checks:
        try:
            load_spec(tf.spec, actions, model=m)
        except SpecError as exc:
            new = [d for d in exc.diagnostics if d.render(exc.sources) not in said]
            said.update(d.render(exc.sources) for d in new)
            if new:
                why = f"does not fit the types of the topics {whose} (as `rubass check --bag` says of a recording " \
                      f"of them)"
                err = TestFileError(tf.path, tf.spec_line, _spec_error(tf.spec, why, SpecError(new, exc.sources)))
                err.also = True  # each test's errors are its own
                errors.append(err)
    return spec  # with errors, the file does not run; its tests are still checked against the spec


def _spec_error(path: str, why: str, exc: SpecError) -> str:
    """`spec robot.rbs WHY:` and the spec's errors, its path as the user sees it (relative below here)."""
    shown = shown_path(path)
    text = "\n".join(shown + line[len(path):] if line.startswith(path + ":") else line
                     for line in exc.render().splitlines())
    return f"spec {shown} {why}:\n{text}"


def _expects_nothing(case: Case, path: str) -> str:
    """The warning for a test with no expectation: it runs and passes, but proves nothing, so its
    `covers` count in no coverage (docs/testing.md)."""
    covers = "; its covers do not count" if case.covers else ""
    return f"{path}:{case.line}: warning: test '{case.name}' expects nothing, so it proves nothing{covers}"


def _unknown_covers(spec: CheckedSpec, tf: TestFile, path: str) -> List[str]:
    """A warning for each `covers` value that is no @id or @hazard of the spec, with the closest one."""
    ids, hazards = traced(spec)
    out = []
    for c in tf.cases:
        unknown = set(unknown_covers(spec, c.covers))
        for k, name in enumerate(c.covers):
            if name in unknown:
                line = c.covers_lines[k] if k < len(c.covers_lines) else c.line
                out.append(f"{path}:{line}: warning: test '{c.name}' covers '{name}', which is no @id or @hazard "
                           f"of the spec{_suggestion(name, ids + hazards)}")
    return out


def _suggestion(name: str, known: List[str]) -> str:
    """`; did you mean 'SR-1'?` for a covers value: the same name in other case first (`sr-1`, `h1`), else
    the closest one, compared case-insensitively."""
    by_case = {k.lower(): k for k in reversed(known)}  # the first spelling of each
    if name.lower() in by_case:
        return f"; did you mean '{by_case[name.lower()]}'?"
    close = difflib.get_close_matches(name.lower(), sorted(by_case), n=1, cutoff=0.6)  # as did_you_mean
    return f"; did you mean '{by_case[close[0]]}'?" if close else ""


def shown_path(path: str) -> str:
    """A path as the user sees it: relative below the current directory, else absolute."""
    rel = os.path.relpath(path)
    return os.path.abspath(path) if rel == ".." or rel.startswith(".." + os.sep) else rel
