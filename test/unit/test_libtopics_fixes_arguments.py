"""Arguments to an action whose plugin ignores them are a check error at the call (acceptance:
`crawl(0.05 m/s)` checked ok and still clamped at 0.15 m/s). Only log actions and custom plugins
use a call's arguments (rubass/ros/actions/log.py; a custom plugin's ctx.args)."""
import subprocess
import sys

import pytest

from rubass.lang import SpecError
from rubass.lang.libcheck import ARGUMENT_PLUGINS, argument_problem
from rubass.lang.loader import load_spec

LIB = """actions:
  stop: {plugin: publish, topic: /safe, type: geometry_msgs/Twist, priority: 3}
  crawl: {plugin: limit, input: /nav, topic: /safe, linear_x: [-0.1 m/s, 0.15 m/s], priority: 1}
  board: {plugin: serial, port: /dev/null, on_start: "S\\n"}
  brk: {plugin: service, service: /b, type: std_srvs/Trigger}
  warn: {plugin: log}
  horn: {plugin: my_robot.safety:Horn}
"""
HEAD = 'import "lib.yaml";\naction primitive stop, crawl, board, brk, warn, horn;\nentity e { rules: r: topic /x.data > 1; }\n'


def check(tmp_path, then):
    (tmp_path / "lib.yaml").write_text(LIB)
    path = tmp_path / "s.rbs"
    path.write_text(HEAD + f"if (e.r) then {{ {then} }}\n")
    try:
        load_spec(str(path))
        return []
    except SpecError as exc:
        return [(d.span.line, d.span.col, d.message) for d in exc.diagnostics]


@pytest.mark.parametrize("call,plugin", [("crawl(0.05 m/s);", "limit"), ('stop("why");', "publish"),
                                         ("board(1);", "serial"), ("brk(true);", "service")])
def test_arguments_to_an_action_whose_plugin_ignores_them_are_an_error_at_the_call(tmp_path, call, plugin):
    name = call.split("(")[0]
    line = next(i for i, text in enumerate(LIB.splitlines(), 1) if text.startswith(f"  {name}:"))
    got = check(tmp_path, "warn; " + call)
    assert got == [(4, 23, f"action '{name}' takes no arguments: its plugin '{plugin}' ignores them (it does what "
                           f"its library entry says, {tmp_path / 'lib.yaml'}:{line}:3); "
                           f"only log actions (the text of their line) and custom plugins (ctx.args) use arguments: "
                           f"write '{name};', or change the library")]


def test_log_and_custom_plugins_take_arguments_and_bare_calls_are_fine(tmp_path):
    assert check(tmp_path, 'warn("left the zone", 2); horn("loud", 3); stop; crawl; board; brk;') == []
    assert ARGUMENT_PLUGINS == ("log",)


def test_every_call_with_ignored_arguments_is_reported_in_one_run(tmp_path):
    (tmp_path / "lib.yaml").write_text(LIB)
    (tmp_path / "s.rbs").write_text(HEAD + "if (e.r) then { crawl(0.05 m/s); stop(\"why\"); board(1); }\n")
    r = subprocess.run([sys.executable, "-m", "rubass", "check", str(tmp_path / "s.rbs")], capture_output=True,
                       text=True)
    out = r.stdout + r.stderr
    assert r.returncode != 0
    assert [line.split(": error:")[0].rsplit(":", 2)[1:] for line in out.splitlines() if ": error:" in line] == \
        [["4", "17"], ["4", "34"], ["4", "47"]], out


def test_no_arguments_no_problem():
    from rubass.lang.library import ActionDef
    from rubass.lang.source import Span

    a = ActionDef("stop", "publish", {"topic": "/s", "type": "std_msgs/Empty"})
    assert argument_problem(a, 0, Span("s.rbs", 1, 1)) is None
    assert argument_problem(a, 2, Span("s.rbs", 1, 1)).span == Span("s.rbs", 1, 1)


def test_the_docs_quote_the_error_as_it_is(tmp_path):
    import os

    from conftest import ROOT

    text = open(os.path.join(ROOT, "docs", "actions.md"), encoding="utf-8").read()
    (tmp_path / "lib.yaml").write_text(LIB)
    (tmp_path / "safety.rbs").write_text(HEAD + "if (e.r) then { crawl(0.05 m/s); }\n")
    with pytest.raises(SpecError) as exc:
        load_spec(str(tmp_path / "safety.rbs"))
    d = exc.value.diagnostics[0]
    line = f"{d.span}: error: {d.message}".replace(f"{tmp_path}/", "")
    assert line + "\n" in text
