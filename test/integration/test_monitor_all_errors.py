"""The monitor reports every error of a spec at start and at a reload, as `rubass check` prints them
(found by an acceptance sweep: a NaN in a library's message, checked against the installed
definitions, was logged only once the spec's own error was fixed, a reload at a time)."""
import time

import pytest
import yaml
from rosharness import wait_log

pytestmark = [pytest.mark.ros]

GOOD_LIB = ("actions:\n  stop: {plugin: publish, topic: /cmd_vel_safety, type: geometry_msgs/Twist, message: {}}\n"
            "  crawl: {plugin: limit, input: /nav_vel, topic: /cmd_vel_crawl, linear_x: [-0.1 m/s, 0.15 m/s]}\n")
BAD_LIB = GOOD_LIB.replace("message: {}", "message: {linear: {x: .nan}}")
GOOD = ('import "lib.yaml";\naction primitive stop, crawl;\nentity e { rules: fast: topic /v.data > 1; }\n'
        "if (e.fast) then { stop; crawl; }\n")
BAD = GOOD.replace("crawl; }", "crawl(0.05 m/s); }")
SPEC_ERROR = "s.rbs:4:26: error: action 'crawl' takes no arguments"
LIB_ERROR = "lib.yaml:2:100: error: action 'stop': 'message.linear.x' is a float64: a command must be a number"


def test_at_start_the_specs_and_its_librarys_errors_are_logged_together(ros, tmp_path):
    (tmp_path / "lib.yaml").write_text(BAD_LIB)
    (tmp_path / "s.rbs").write_text(BAD)
    mon = ros.monitor(str(tmp_path / "s.rbs"))
    wait_log(mon, ros, "NOT ENFORCING ANY RULE")
    log = ros.log(mon)
    assert SPEC_ERROR in log and LIB_ERROR in log, log


def test_a_rejected_reload_gives_the_specs_and_its_librarys_errors_together(ros, tmp_path):
    (tmp_path / "lib.yaml").write_text(GOOD_LIB)
    (tmp_path / "s.rbs").write_text(GOOD)
    ros.monitor(str(tmp_path / "s.rbs"))
    (tmp_path / "lib.yaml").write_text(BAD_LIB)
    (tmp_path / "s.rbs").write_text(BAD)
    time.sleep(0.1)
    answer = yaml.safe_load(ros.call("/rubass/reload").stdout)
    assert answer["success"] is False
    assert SPEC_ERROR in answer["message"] and LIB_ERROR in answer["message"], answer["message"]
