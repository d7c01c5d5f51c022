"""Keep rospy's logging off the master.

rospy's /rosout handler reads the parameter `/rosout_disable_topics_generation` at every log
call, through its parameter cache; but the cache keeps only parameters that are set, so when it
is unset (as usual) every rospy log call is an XML-RPC request to the master, without a timeout.
With the master's host cut off, any thread that logs then blocks until the link is back: a
subscriber thread reporting a data error, the engine's thread running a fail-safe. Read the
parameter once, while the master answers, and keep the answer in the cache.
"""
from __future__ import annotations

import rospy

FLAG = "/rosout_disable_topics_generation"


def keep_rosout_flag() -> bool:
    """Cache the flag's value (False when unset); False when it cannot be (rospy changed)."""
    try:
        from rospy.impl.paramserver import get_param_server_cache

        value = rospy.get_param(FLAG, False)
        get_param_server_cache().set(FLAG, bool(value) if not isinstance(value, dict) else False)
        return True
    except Exception:  # noqa: BLE001 - a master that does not answer now, another rospy: logging as before
        return False
