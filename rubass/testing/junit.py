"""JUnit XML for a robot's CI: one testsuite per file, one testcase per test."""
from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from typing import List

from .results import FileResult, shown_path


# characters XML 1.0 cannot hold, even escaped (control characters but tab, newline, return; surrogates…)
_INVALID = re.compile("[^\u0009\u000a\u000d\u0020-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def _x(text: str) -> str:
    """Text as XML can hold it: a character XML forbids becomes its escape, e.g. \\x01."""
    return _INVALID.sub(lambda m: m.group(0).encode("unicode_escape").decode("ascii"), str(text))


def _one_line(problem: str) -> str:
    """A problem on one line (a failure's message attribute): 'overspeed (line 12): expected: …; actual: …'."""
    parts = [re.sub(r"\s+", " ", p.strip()) for p in problem.splitlines() if p.strip()]
    return (parts[0] + " " + "; ".join(parts[1:])).strip() if len(parts) > 1 else (parts[0] if parts else "")


def write_junit(results: List[FileResult], path: str) -> None:
    """Write JUnit XML; a file that could not run is a testsuite with one errored testcase."""
    root = ET.Element("testsuites", name="rubass test")
    total = failures = errors = 0
    for r in results:
        name = shown_path(r.path)
        suite = ET.SubElement(root, "testsuite", name=_x(name))
        classname = os.path.basename(r.path).replace(".test.yaml", "").replace(".yaml", "")
        n_fail = 0
        for o in r.outcomes:
            case = ET.SubElement(suite, "testcase", classname=_x(classname), name=_x(o.name), time=f"{o.elapsed:.6f}")
            if o.covers:
                props = ET.SubElement(case, "properties")
                for c in o.covers:
                    ET.SubElement(props, "property", name="covers", value=_x(c))
            if not o.passed:
                n_fail += 1
                first = _one_line(o.problems[0]) if o.problems else "failed"
                fail = ET.SubElement(case, "failure", message=_x(first), type="expectation")
                fail.text = _x("\n".join(o.problems))
        if r.error:
            case = ET.SubElement(suite, "testcase", classname=_x(classname), name="(file)", time="0")
            err = ET.SubElement(case, "error", message=_x(r.error.splitlines()[0]), type="file")
            err.text = _x(r.error)
        suite.set("tests", str(len(r.outcomes) + (1 if r.error else 0)))
        suite.set("failures", str(n_fail))
        suite.set("errors", "1" if r.error else "0")
        suite.set("time", f"{sum(o.elapsed for o in r.outcomes):.6f}")
        total += len(r.outcomes) + (1 if r.error else 0)
        failures += n_fail
        errors += 1 if r.error else 0
    root.set("tests", str(total))
    root.set("failures", str(failures))
    root.set("errors", str(errors))
    tree = ET.ElementTree(root)
    make_parent(path)
    tree.write(path, encoding="utf-8", xml_declaration=True)


class FolderError(OSError):
    """The folder an output file goes in cannot be made; str() says which and why."""


def make_parent(path: str) -> None:
    """Create the folders `path` goes in (`out/` of `--junit out/tests.xml`); FolderError when one cannot be."""
    folder = os.path.dirname(path)
    if not folder or os.path.isdir(folder):
        return
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as exc:
        raise FolderError(f"cannot create the folder {folder}: {exc.strerror or exc}") from None
