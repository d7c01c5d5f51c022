"""Nothing in a spec or an action library can run a command (issue #7): YAML tags are never
constructed, custom plugins cannot name the standard library or a non-class, imports read
regular files only."""
import os

import pytest

from rubass.lang import SpecError, check_text
from rubass.lang.library import ActionDef, parse_library
from rubass.lang.source import Source
from rubass.actions.base import ActionSetupError, make_plugin


@pytest.mark.parametrize("plugin", ["subprocess:Popen", "os:system", "antigravity:x", "webbrowser:open",
                                    "pty:spawn", "os.path:join", "multiprocessing.popen_fork:Popen"])
def test_a_custom_plugin_from_the_standard_library_is_refused_before_import(plugin):
    with pytest.raises(ActionSetupError, match="standard library"):
        make_plugin(ActionDef("stop", plugin, {}))


def test_a_custom_plugin_that_is_not_a_plugin_class_is_refused_before_it_is_called(tmp_path, monkeypatch):
    marker = tmp_path / "ran"
    (tmp_path / "robot_plugins.py").write_text(
        f"def run(name, params):\n    open({str(marker)!r}, 'w').close()\n"
        f"class Half:\n    def __init__(self, name, params):\n        open({str(marker)!r}, 'w').close()\n"
        f"    def start(self, ctx):\n        pass\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    for plugin in ("robot_plugins:run", "robot_plugins:Half"):
        with pytest.raises(ActionSetupError, match="is not a plugin class"):
            make_plugin(ActionDef("stop", plugin, {}))
    assert not marker.exists()


@pytest.mark.parametrize("text", [
    "actions: !!python/object/apply:os.system ['touch {m}']\n",
    "actions:\n  stop: !!python/object/apply:os.system ['touch {m}']\n",
    "actions:\n  stop: {{plugin: !!python/object/apply:os.system ['touch {m}'], level: warn}}\n",
    "actions:\n  stop: {{plugin: log, level: !!python/name:os.system }}\n",
    "actions:\n  stop: {{plugin: mypkg.mod:Cls, arg: !!python/object/new:subprocess.Popen [['touch', '{m}']]}}\n",
])
def test_yaml_tags_are_never_constructed(tmp_path, text):
    marker = tmp_path / "ran"
    actions, diags = parse_library(Source("lib.yaml", text.format(m=marker)))
    assert actions == {} and diags and all(d.message for d in diags)
    assert not marker.exists()


def test_an_import_of_a_fifo_or_a_device_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "lib.yaml"
    os.mkfifo(fifo)  # opening it for reading would wait for a writer forever
    for path in (str(fifo), "/dev/zero"):
        with pytest.raises(SpecError) as exc:
            check_text(f'import "{path}";\n', str(tmp_path / "s.rbs"))
        assert "not a regular file" in exc.value.render()


def test_a_tag_is_a_clean_error_at_its_place():
    actions, diags = parse_library(Source("lib.yaml", "actions:\n  stop: {plugin: log, level: !!python/name:os.system }\n"))
    assert actions == {} and len(diags) == 1
    assert diags[0].render().startswith("lib.yaml:2:30: error: YAML tag 'tag:yaml.org,2002:python/name:os.system' "
                                        "is not allowed")
