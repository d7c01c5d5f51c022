"""docs/testing.md: its error examples are what `rubass test` prints for the page's own spec and file."""
import os
import re
import shutil

import pytest

from rubass.cli import main

from conftest import ROOT

PAGE = os.path.join(ROOT, "docs", "testing.md")


@pytest.fixture
def page(tmp_path, monkeypatch):
    """The page's spec and first test file in a folder that is the current one; make(old, new, spec_old,
    spec_new) writes the file (and spec) with one change and returns stdout + stderr of `rubass test`."""
    text = open(PAGE, encoding="utf-8").read()
    (spec,) = re.findall(r"```rubass\n(.*?)```", text, re.S)
    first = next(b for b in re.findall(r"```yaml\n(.*?)```", text, re.S) if b.startswith("spec:"))
    shutil.copy(os.path.join(ROOT, "docs", "examples", "actions.yaml"), tmp_path / "actions.yaml")
    monkeypatch.chdir(tmp_path)

    def make(changes=(), spec_changes=()):
        body, rbs = first, spec
        for old, new in changes:
            assert old in body
            body = body.replace(old, new)
        for old, new in spec_changes:
            assert old in rbs
            rbs = rbs.replace(old, new)
        (tmp_path / "robot.rbs").write_text(rbs)
        (tmp_path / "robot.test.yaml").write_text(body)
        code = main(["test", "robot.test.yaml"])
        return code

    return text, make


def _error_lines(err):
    return [line for line in err.splitlines() if ": error: " in line]


def _documented(text, start):
    return [line.strip() for line in text.splitlines() if line.strip().startswith(start)]


def test_the_field_error_example(page, capsys):
    text, make = page
    code = make([("field: twist.twist.linear.x", "field: twist.linear.x")])
    err = capsys.readouterr().err
    assert code == 2
    (said,) = _error_lines(err)
    assert said in _documented(text, "robot.test.yaml:11: error: /odom"), said


def test_the_declared_types_example(page, capsys):
    text, make = page
    code = make(spec_changes=[("linear.x > 0.5 m/s", "linear.x > 3 s")])
    err = capsys.readouterr().err
    assert code == 2
    said = _error_lines(err)
    assert said[0] in _documented(text, "robot.test.yaml:1: error: spec robot.rbs does not fit"), said
    assert said[1] in _documented(text, "robot.rbs:6:"), said


def test_the_every_error_example(page, capsys):
    text, make = page
    code = make([("start: overspeed}", "start: overspede}"), ("release: overspeed}", "relase: overspeed}")])
    err = capsys.readouterr().err
    assert code == 2
    said = _error_lines(err)
    documented = _documented(text, "robot.test.yaml:14: error:") + _documented(text, "robot.test.yaml:15: error:")
    assert said == documented


def test_the_page_links_the_vendored_contract():
    text = open(PAGE, encoding="utf-8").read()
    assert "](spec/TESTING.md)" in text and "](spec/LANGUAGE.md)" in text
    assert "$ rubass test" not in text  # how to run it is said, not a bare `rubass`
    assert "--actions" in text
