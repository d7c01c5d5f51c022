"""Shared test helpers: paths to the repository, the shared data, and spec writers."""
import os
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared")
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)


@pytest.fixture
def write(tmp_path):
    """write(name, text) -> path of a new file in a temporary folder."""

    def _write(name, text):
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(text, bytes):
            path.write_bytes(text)
        else:
            path.write_text(text, encoding="utf-8")
        return str(path)

    return _write


def shared_path(*parts):
    """A path under ../shared, or skip the test when shared/ is absent (a user's clone)."""
    path = os.path.join(SHARED, *parts)
    if not os.path.exists(path):
        pytest.skip(f"{path} is absent (shared/ is only beside the project in development)")
    return path


@pytest.fixture
def ros(tmp_path):
    """A private rosmaster on a free port for this test, stopped by PID afterwards (see rosharness)."""
    integration = os.path.join(ROOT, "test", "integration")
    if integration not in sys.path:
        sys.path.insert(0, integration)
    from rosharness import Ros

    r = Ros(tmp_path)
    yield r
    r.stop()


class Clock:
    """A clock the test sets by hand (clock.t), for EngineLoop and the monitor's parts."""

    def __init__(self, t=100.0):
        self.t = t

    def __call__(self):
        return self.t
