"""A custom plugin that cannot be loaded is reported as `rubass check` reports a library error:
FILE:LINE:COL of its `plugin:` entry, the line and a caret (the monitor printed no place)."""
import pytest

from rubass.actions.base import ActionSetupError, make_plugin
from rubass.lang.library import parse_library
from rubass.lang.source import Source


def load(tmp_path, text):
    path = tmp_path / "lib.yaml"
    path.write_text(text)
    actions, diags = parse_library(Source(str(path), text))
    assert not diags, diags
    return str(path), actions


def test_a_plugin_module_that_cannot_be_imported_is_named_at_its_plugin_entry(tmp_path):
    path, actions = load(tmp_path, "actions:\n  log_it: {plugin: log}\n  board: {plugin: no_such_mod.x:Y, a: 1}\n")
    with pytest.raises(ActionSetupError) as exc:
        make_plugin(actions["board"])
    lines = str(exc.value).splitlines()
    assert lines[0] == (f"{path}:3:19: error: action 'board': cannot import plugin module 'no_such_mod.x': "
                        f"ModuleNotFoundError: No module named 'no_such_mod'")
    assert lines[1].strip() == "board: {plugin: no_such_mod.x:Y, a: 1}"
    assert lines[2].index("^") - lines[1].index("b") == 16  # under the plugin's value


def test_a_block_style_entry_is_found_on_its_own_line_and_not_in_the_next_action(tmp_path):
    path, actions = load(tmp_path, "actions:\n  horn:\n    # the robot's horn\n    level: 1\n"
                                   "    plugin: 'robot_pkg_missing.horn:Horn'\n"
                                   "  other:\n    plugin: robot_pkg_missing.horn:Horn\n")
    with pytest.raises(ActionSetupError, match=rf"^{path}:5:13: error: action 'horn': cannot import"):
        make_plugin(actions["horn"])
    with pytest.raises(ActionSetupError, match=rf"^{path}:7:13: error: action 'other': cannot import"):
        make_plugin(actions["other"])


def test_a_class_missing_from_its_module_and_a_failing_setup_are_named_at_their_entry(tmp_path, monkeypatch):
    (tmp_path / "robot_plug_place.py").write_text(
        "class Bad:\n    def __init__(self, name, params):\n        pass\n"
        "    def setup(self):\n        raise ValueError('no horn on this robot')\n"
        "    def start(self, ctx):\n        pass\n    def hold(self, ctx):\n        pass\n"
        "    def release(self, ctx):\n        pass\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    path, actions = load(tmp_path, "actions:\n  a: {plugin: 'robot_plug_place:Nope'}\n"
                                   "  b: {plugin: robot_plug_place:Bad}\n")
    with pytest.raises(ActionSetupError, match=rf"^{path}:2:15: error: action 'a': module 'robot_plug_place' has "
                                               "no class 'Nope'"):
        make_plugin(actions["a"])
    plugin = make_plugin(actions["b"])
    with pytest.raises(ActionSetupError, match=rf"^{path}:3:15: error: action 'b': robot_plug_place:Bad.setup\(\) "
                                               "failed: ValueError: no horn on this robot"):
        plugin.setup()


def test_a_merged_plugin_entry_is_named_where_the_anchor_gives_it(tmp_path):
    path, actions = load(tmp_path, "actions:\n  horn: &h\n    plugin: robot_pkg_missing.horn:Horn\n"
                                   "  horn2:\n    <<: *h\n    a: 2\n")
    with pytest.raises(ActionSetupError, match=rf"^{path}:3:13: error: action 'horn2': cannot import"):
        make_plugin(actions["horn2"])


def test_a_custom_plugin_may_say_how_long_its_calls_may_block(tmp_path, monkeypatch):
    """Its `call_timeout` attribute moves the runner's stuck bound (2 s beyond it), as a service's
    timeout does; without one, the bound is 2 s."""
    from rubass.actions.runner import STUCK_AFTER, ActionRunner

    (tmp_path / "robot_plug_slow.py").write_text(
        "class Slow:\n    call_timeout = 5.0\n    def __init__(self, name, params): pass\n"
        "    def start(self, ctx): pass\n    def hold(self, ctx): pass\n    def release(self, ctx): pass\n"
        "class Quick(Slow):\n    call_timeout = None\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    _, actions = load(tmp_path, "actions:\n  slow: {plugin: robot_plug_slow:Slow}\n  quick: {plugin: robot_plug_slow:Quick}\n")
    log = lambda level, text: None  # noqa: E731
    assert ActionRunner(make_plugin(actions["slow"]), log).stuck_after == STUCK_AFTER + 5.0
    assert ActionRunner(make_plugin(actions["quick"]), log).stuck_after == STUCK_AFTER
