"""A log action's line prints a call's arguments as written (re-sweep finding)."""
import pytest

pytest.importorskip("rospy")


def test_a_log_line_prints_whole_numbers_as_written():
    """Re-sweep finding: `warn("left", 3, "zone")` logged "left 3.0 zone"."""
    from rubass.actions.base import Context
    from rubass.ros.actions.log import LogPlugin

    p = LogPlugin.__new__(LogPlugin)
    p.params = {}
    text = p._text(Context(1, 3, args=("left", 3.0, "zone", 0.25, True)), "started")
    assert text.startswith("left 3 zone 0.25 True: "), text
