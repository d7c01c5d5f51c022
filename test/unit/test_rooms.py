"""The house (style.md): the language, the engine and the actions are pure, and import only
from the rooms above them; the ROS shell and the experiments sit apart."""
import ast as pyast
import glob
import os
import subprocess
import sys

import pytest

from conftest import ROOT

PURE = ("lang", "engine", "actions")
ROS_MODULES = ("rospy", "rosgraph", "rosbag", "genpy", "roslib", "serial", "psutil", "std_msgs", "sensor_msgs",
               "geometry_msgs", "nav_msgs", "diagnostic_msgs", "std_srvs")
ORDER = {"lang": 0, "engine": 1, "actions": 2}


def imports(path):
    tree = pyast.parse(open(path, encoding="utf-8").read())
    for node in pyast.walk(tree):
        if isinstance(node, pyast.Import):
            for a in node.names:
                yield 0, a.name
        elif isinstance(node, pyast.ImportFrom):
            yield node.level, node.module or ""


@pytest.mark.parametrize("room", PURE)
def test_pure_rooms_import_no_ros_and_only_rooms_above(room):
    for path in glob.glob(os.path.join(ROOT, "rubass", room, "*.py")):
        for level, name in imports(path):
            top = name.split(".")[0]
            assert level or top not in ROS_MODULES, f"{path} imports {name}"
            if level == 2 and top:  # from ..X: another room of the package
                assert top in ORDER and ORDER[top] <= ORDER[room], f"{path} imports from the room '{top}'"


def test_the_core_imports_with_ros_absent():
    code = ("import sys\n"
            "class Block:\n"
            "    def find_module(self, name, path=None):\n"
            "        return self if name.split('.')[0] in %r else None\n"
            "    def find_spec(self, name, path=None, target=None):\n"
            "        if name.split('.')[0] in %r: raise ImportError('blocked: ' + name)\n"
            "sys.meta_path.insert(0, Block())\n"
            "import rubass.lang, rubass.engine, rubass.actions.dispatch, rubass.actions.runner, "
            "rubass.actions.status, rubass.actions.keeper, rubass.actions.overload, rubass.actions.errorguard, "
            "rubass.actions.arbitration, rubass.actions.base\n" % (ROS_MODULES, ROS_MODULES))
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


def test_one_table_names_every_built_in_plugin():
    from rubass.actions.base import BUILTIN
    from rubass.lang.library import BUILTIN_PLUGINS

    assert sorted(BUILTIN) == sorted(BUILTIN_PLUGINS)
    assert all(v.startswith("rubass.ros.actions.") for v in BUILTIN.values())
