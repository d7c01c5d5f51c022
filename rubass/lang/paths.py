"""Resolving import paths: relative to the spec, absolute, or package://PKG/sub/path."""
from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from typing import Dict, Iterable, Mapping, Optional

from .errors import RubassError

_PACKAGE_URL = re.compile(r"package://([^/]+)/(.*)")


class PathError(RubassError):
    """An import path that cannot be resolved; the message says why."""


def find_package(name: str, env: Optional[Mapping[str, str]] = None) -> Optional[str]:
    """The folder of ROS package `name`, searched as rospack does along ROS_PACKAGE_PATH."""
    env = os.environ if env is None else env
    for root in [p for p in env.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]:
        found = _packages_under(root).get(name)
        if found:
            return found
    return None


_CACHE: Dict[str, Dict[str, str]] = {}


def _packages_under(root: str) -> Dict[str, str]:
    if root not in _CACHE:
        found: Dict[str, str] = {}
        for dirpath, dirnames, filenames in os.walk(root, followlinks=True):
            if "package.xml" in filenames:
                name = _package_name(os.path.join(dirpath, "package.xml"))
                if name:
                    found.setdefault(name, dirpath)
                dirnames[:] = []  # packages do not nest
            elif "CATKIN_IGNORE" in filenames:
                dirnames[:] = []
            else:
                dirnames[:] = [d for d in dirnames if not d.startswith(".")]
        _CACHE[root] = found
    return _CACHE[root]


def _package_name(path: str) -> Optional[str]:
    try:
        el = ET.parse(path).getroot().find("name")
    except (ET.ParseError, OSError):
        return None
    return el.text.strip() if el is not None and el.text else None


def resolve(path: str, base_dir: str, env: Optional[Mapping[str, str]] = None) -> str:
    """An absolute file path for an import written in a spec in base_dir."""
    m = _PACKAGE_URL.fullmatch(path)
    if m:
        pkg = find_package(m.group(1), env)
        if pkg is None:
            raise PathError(f"ROS package '{m.group(1)}' not found on ROS_PACKAGE_PATH "
                            f"(source the workspace's setup.bash)")
        return os.path.normpath(os.path.join(pkg, m.group(2)))
    if path.startswith("package://"):
        raise PathError("a package path is written 'package://PKG/sub/path'")
    if not path:
        raise PathError("the import path is empty")
    return os.path.normpath(path if os.path.isabs(path) else os.path.join(base_dir, path))


def file_arg(path: str) -> str:
    """A spec or library named on a command line: `package://PKG/sub/path` as the file it names when the
    package is found (left as written otherwise: reading it then says why), any other path as given."""
    if path.startswith("package://"):
        try:
            return resolve(path, os.getcwd())
        except (PathError, OSError):
            return path
    return path


def clear_cache(roots: Iterable[str] = ()) -> None:
    """Forget scanned package folders (all of them when roots is empty)."""
    if not roots:
        _CACHE.clear()
    for r in roots:
        _CACHE.pop(r, None)
