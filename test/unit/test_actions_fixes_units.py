"""Acceptance fixes, pure parts: a release that did nothing resolves no failed start; NaN in a library
message and serial text with no byte are library errors at their place."""
import time

from rubass.actions.base import ActionPlugin, Context
from rubass.actions.runner import ActionRunner
from rubass.actions.status import NOTHING_DONE, RESOLVED
from rubass.lang.libcheck import check_library_types, serial_text_problem
from rubass.lang.library import ActionDef, parse_library
from rubass.lang.msgdef import Registry, parse_msg
from rubass.lang.source import Source, SourceSet


class Brake(ActionPlugin):
    """A service-like action: the start fails (the service is missing); the release calls nothing
    unless `release_does` (then it succeeds)."""

    def __init__(self, release_does=False):
        super().__init__(ActionDef("brake2", "fake:Fake", {}))
        self.release_does = release_does
        self.calls = []

    def start(self, ctx):
        self.calls.append("start")
        raise IOError("service /nobrake does not exist (not advertised on the master)")

    def release(self, ctx):
        self.calls.append("release")
        return None if self.release_does else NOTHING_DONE


def run_start_then_release(plugin):
    r = ActionRunner(plugin, lambda level, text: None)
    r.start_thread()
    try:
        r.submit("start", Context(1, 3))
        end = time.monotonic() + 3
        while not r.stats.failures and time.monotonic() < end:
            time.sleep(0.01)
        r.submit("release", Context(1, 3))
        while "release" not in plugin.calls and time.monotonic() < end:
            time.sleep(0.01)
        time.sleep(0.3)  # no retry of the start after its release
        starts = plugin.calls.count("start")
        time.sleep(0.6)
        assert plugin.calls.count("start") == starts, "a superseded start is not retried"
        return r.stats
    finally:
        r.stop()


def test_a_release_that_did_nothing_leaves_the_failed_start_shown():
    stats = run_start_then_release(Brake())
    assert stats.failing == "start", stats
    assert not stats.last_error.startswith(RESOLVED), stats.last_error
    assert "does not exist" in stats.last_error
    assert "no longer retried: released before an attempt succeeded" in stats.last_error
    assert stats.calls == 0, "nothing succeeded, nothing counted as a call"


def test_a_release_that_really_succeeded_still_resolves_it():
    stats = run_start_then_release(Brake(release_does=True))
    assert stats.failing == "" and stats.last_error.startswith(RESOLVED), stats


def registry():
    r = Registry()
    r.add(parse_msg("geometry_msgs/Twist", "Vector3 linear\nVector3 angular\n"))
    r.add(parse_msg("geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"))
    return r


def check(text):
    sources = SourceSet()
    src = Source("lib.yaml", text)
    sources.add(src)
    actions, diags = parse_library(src)
    assert diags == []
    return [f"{d.span.file}:{d.span.line}:{d.span.col}: {d.message}"
            for d in check_library_types(actions, sources, registry(), "the test registry")]


def test_nan_in_a_library_message_is_an_error_at_its_place():
    lib = ("actions:\n  stop:\n    plugin: publish\n    topic: /cmd\n    type: geometry_msgs/Twist\n"
           "    message: {linear: {x: .nan}, angular: {z: .NaN}}\n    on_release: {linear: {y: .nan}}\n")
    assert check(lib) == [
        "lib.yaml:6:27: action 'stop': 'message.linear.x' is a float64: a command must be a number (NaN is not one), got nan",
        "lib.yaml:6:47: action 'stop': 'message.angular.z' is a float64: a command must be a number (NaN is not one), got nan",
        "lib.yaml:7:30: action 'stop': 'on_release.linear.y' is a float64: a command must be a number (NaN is not one), got nan"]
    assert check(lib.replace(".nan", "0.0").replace(".NaN", "-1.5")) == []


def test_serial_text_with_a_character_that_has_no_byte_is_an_error_at_its_value():
    lib = ('actions:\n  board:\n    plugin: serial\n    port: /dev/null\n    on_start: "STOP\\u20ac\\n"\n'
           '    on_release: "R\\xff\\x00\\n"\n')
    out = check(lib)
    assert out == ["lib.yaml:5:15: action 'board': 'on_start': '€' (U+20AC) cannot be sent: serial text is sent "
                   "as Latin-1, one byte per character (\\x00 to \\xff); write the bytes the board expects as "
                   "\\xNN escapes"], out
    assert check(lib.replace("\\u20ac", "\\x80")) == []
    assert serial_text_problem("S\n\xff") is None and "U+0100" in serial_text_problem("\u0100")
