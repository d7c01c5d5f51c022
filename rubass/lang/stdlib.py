"""Whether a Python module is part of the standard library, found without importing it: a
custom action plugin must be the robot's own code, never the standard library's (a library
naming 'subprocess:Popen' or 'os:system' could run commands)."""
from __future__ import annotations

import importlib.util
import os
import sys
import sysconfig


def is_standard_library(module_name: str) -> bool:
    """Whether the top-level package of `module_name` is Python's own (nothing is imported)."""
    top = module_name.split(".")[0]
    names = getattr(sys, "stdlib_module_names", None)  # Python 3.10+
    if names is not None:
        return top in names
    if top in sys.builtin_module_names:
        return True
    try:
        spec = importlib.util.find_spec(top)
    except (ImportError, ValueError):
        return False
    origin = getattr(spec, "origin", None) or ""
    stdlib = os.path.realpath(sysconfig.get_paths()["stdlib"])
    path = os.path.realpath(origin)
    return path.startswith(stdlib + os.sep) and "-packages" not in path
