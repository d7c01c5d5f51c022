"""JUnit XML for a robot's CI: one testsuite per file, one testcase per test."""
from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from typing import List

from .results import FileResult, shown_path


def write_junit(results: List[FileResult], path: str) -> None:
    """Write JUnit XML; a file that could not run is a testsuite with one errored testcase."""
    root = ET.Element("testsuites", name="rubass test")
    total = failures = errors = 0
    for r in results:
        name = shown_path(r.path)
        suite = ET.SubElement(root, "testsuite", name=name)
        classname = os.path.basename(r.path).replace(".test.yaml", "").replace(".yaml", "")
        n_fail = 0
        for o in r.outcomes:
            case = ET.SubElement(suite, "testcase", classname=classname, name=o.name, time=f"{o.elapsed:.6f}")
            if o.covers:
                props = ET.SubElement(case, "properties")
                for c in o.covers:
                    ET.SubElement(props, "property", name="covers", value=c)
            if not o.passed:
                n_fail += 1
                fail = ET.SubElement(case, "failure", message=o.problems[0].splitlines()[0], type="expectation")
                fail.text = "\n".join(o.problems)
        if r.error:
            case = ET.SubElement(suite, "testcase", classname=classname, name="(file)", time="0")
            err = ET.SubElement(case, "error", message=r.error.splitlines()[0], type="file")
            err.text = r.error
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
    tree.write(path, encoding="utf-8", xml_declaration=True)
