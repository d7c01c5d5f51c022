"""The running spec against the message types its topics turn out to carry (rubass/ros/livecheck.py):
a unit error on a topic field that no check could see before is found, logged once per spec, and
gone after a reload that fixes it."""
import threading
import time

from rubass.lang import load_spec
from rubass.ros.livecheck import LiveTypeCheck, live_errors

TWIST = ("geometry_msgs/Twist", "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n"
         "================================================================================\n"
         "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n")
HEAD = 'import "lib.yaml";\naction primitive stop;\n'
WRONG = HEAD + "entity base { rules: fast: topic /cmd_vel.linear.x > 3 s; }\nif (base.fast) then { stop; }\n"
RIGHT = HEAD + "entity base { rules: fast: topic cmd_vel.linear.x > 3 m/s; }\nif (base.fast) then { stop; }\n"


def _spec(write, text):
    write("lib.yaml", "actions:\n  stop: {plugin: log, level: warn}\n")
    return load_spec(write("s.rbs", text))


def test_a_unit_error_on_a_field_of_the_carried_type_is_found_at_its_place(write):
    spec = _spec(write, WRONG)
    errors = live_errors(spec, [], {"/cmd_vel": TWIST})
    assert len(errors) == 1 and errors[0].splitlines()[0].endswith("s.rbs:3:52: error: compares a speed with a time")


def test_right_units_another_topic_and_a_relative_spelling_give_nothing(write):
    assert live_errors(_spec(write, WRONG), [], {"/other": TWIST}) == []
    assert live_errors(_spec(write, RIGHT), [], {"cmd_vel": TWIST}) == []


def test_an_unreadable_definition_leaves_the_fields_unchecked(write):
    assert live_errors(_spec(write, WRONG), [], {"/cmd_vel": ("geometry_msgs/Twist", "not a ) definition")}) == []


def _wait(pred, timeout=5.0):
    end = time.monotonic() + timeout
    while not pred() and time.monotonic() < end:
        time.sleep(0.01)
    return pred()


def test_the_check_logs_each_error_once_per_spec_and_a_fixed_spec_clears_it(write):
    logged = []
    lock = threading.Lock()

    def log(level, text):
        with lock:
            logged.append((level, text))

    check = LiveTypeCheck(log)
    try:
        wrong = _spec(write, WRONG)
        check.use(wrong, [])
        check.note({"/cmd_vel": TWIST})
        assert _wait(lambda: check.errors)
        check.note({"/cmd_vel": TWIST, "/x": TWIST})  # another topic's type: checked again, not said again
        time.sleep(0.3)
        assert [lv for lv, _ in logged] == ["error"] and "compares a speed with a time" in logged[0][1]
        assert "still evaluated on the numbers as written" in logged[0][1]
        check.use(_spec(write, RIGHT), [])  # the reload that fixes it
        time.sleep(0.3)
        assert not check.errors and len(logged) == 1
        check.use(wrong, [])  # a new spec object is a new spec: its errors are said again
        assert _wait(lambda: len(logged) == 2)
    finally:
        check.close()


def test_a_result_found_at_a_reload_is_not_computed_again_for_the_same_types(write, monkeypatch):
    """A reload checks the new spec against the carried types before its swap; the check's thread then
    takes that result for the same spec and types instead of a second check of the whole spec."""
    import rubass.ros.livecheck as livecheck

    calls = []
    real = livecheck.live_errors
    monkeypatch.setattr(livecheck, "live_errors", lambda *a: calls.append(1) or real(*a))
    check = LiveTypeCheck(lambda level, text: None)
    try:
        right = _spec(write, RIGHT)
        check.known(right, {"/cmd_vel": TWIST}, [])
        check.use(right, [])
        check.note({"/cmd_vel": TWIST})
        time.sleep(0.3)
        assert calls == [] and check.errors == []
        check.note({"/cmd_vel": TWIST, "/x": TWIST})  # other types: checked
        assert _wait(lambda: calls == [1])
    finally:
        check.close()
