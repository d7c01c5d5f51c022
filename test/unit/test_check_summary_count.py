"""`rubass check`'s last line: it counts every error printed above it (the spec's and its libraries'),
never a warning, and says '1 node', not '1 nodes'."""
import contextlib
import io
import os

import pytest

from rubass.cli import main

from conftest import ROOT

LIB_TYPO = """actions:
  stop:
    plugin: publish
    topic: /cmd_vel
    type: geometry_msgs/Twist
    message: {linear: {x: 0.0}, angualr: {z: 0.0}}
"""
SPEC = """import "actions.yaml";
action primitive stop;
entity base: driver {
  rules:
    too_fast: abs(topic /cmd_vel.linear.x) > 0.5;
}
if (base.too_fast) then { stop; }
"""


def needs_message_definitions():
    """The library's typo is found against the installed message definitions (ROS's Python)."""
    pytest.importorskip("geometry_msgs.msg", reason="no ROS message packages: the library typo is not checkable")


def run_check(*args):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["check", *args])
    return code, out.getvalue(), err.getvalue()


def summary_count(err, path):
    last = [line for line in err.splitlines() if line.startswith(path + ": ")][-1]
    return int(last.split(": ", 1)[1].split()[0]), last


def test_the_count_is_every_error_printed_spec_and_library(write):
    needs_message_definitions()
    write("actions.yaml", LIB_TYPO)
    # a spec error (a rule that does not exist) and the library's field typo: two errors
    path = write("safety.rbs", SPEC.replace("if (base.too_fast)", "if (base.too_fats)"))
    code, _, err = run_check(path)
    n, last = summary_count(err, path)
    assert code == 1 and err.count(": error: ") == 2 and n == 2 and last.endswith("2 errors"), err


def test_a_library_error_alone_is_counted_and_singular(write):
    needs_message_definitions()
    write("actions.yaml", LIB_TYPO)
    path = write("safety.rbs", SPEC)
    code, _, err = run_check(path)
    n, last = summary_count(err, path)
    assert code == 1 and err.count(": error: ") == 1 and n == 1 and last.endswith(": 1 error"), err


def test_the_ok_line_is_pluralised_by_count():
    code, out, _ = run_check(os.path.join(ROOT, "config", "fig2.rbs"),
                             "--actions", os.path.join(ROOT, "config", "fig2_actions.yaml"))
    assert code == 0 and "ok (1 rule, 1 behaviour, 2 topics, 0 nodes, 1 action)" in out, out
    code, out, _ = run_check(os.path.join(ROOT, "config", "kobuki.rbs"))
    assert code == 0 and "1 node," in out and "1 nodes" not in out, out


def test_quiet_prints_nothing_for_a_clean_spec_but_still_its_errors(write):
    needs_message_definitions()
    code, out, err = run_check("-q", os.path.join(ROOT, "config", "kobuki.rbs"))
    assert code == 0 and out == "" and err == ""
    write("actions.yaml", LIB_TYPO)
    path = write("safety.rbs", SPEC)
    code, out, err = run_check("--quiet", path)
    assert code == 1 and out == "" and ": error: " in err and err.rstrip().endswith(": 1 error")
