"""What the engine reads from a message besides its fields: the header stamp (for stamp_age)
and a LaserScan's range limits (REP 117)."""
from __future__ import annotations

import math
import sys
from typing import Any, Optional, Tuple

from ..lang import ast
from .fields import FieldError, extract
from .values import UNKNOWN

STAMP: Tuple[ast.PathElem, ...] = ("header", "stamp")


def stamp_seconds(value: Any) -> Any:
    """header.stamp as seconds; unknown for a zero stamp or one that cannot be read."""
    to_sec = getattr(value, "to_sec", None)  # genpy Time
    if callable(to_sec):
        value = float(to_sec())
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        value = float(value)
        return value if value > 0 and value == value else UNKNOWN
    if isinstance(value, dict):
        secs, nsecs = value.get("secs"), value.get("nsecs", 0)
        if isinstance(secs, (int, float)) and isinstance(nsecs, (int, float)):
            t = float(secs) + float(nsecs) * 1e-9
            return t if t > 0 else UNKNOWN
    return UNKNOWN


def laser_limits(msg: Any) -> Optional[Tuple[float, float]]:
    """(range_min, range_max) of a sensor_msgs/LaserScan (REP 117), None for any other type."""
    try:
        lo, hi = extract(msg, ("range_min",)), extract(msg, ("range_max",))
    except FieldError:
        return None
    # limits a driver left unset (0 and 0, NaN, inf) would make every reading invalid, the sector
    # unknown and its stop released: such a bound is ignored (readings count from 0 m, finite ones)
    lo = lo if type(lo) is float and math.isfinite(lo) and lo >= 0.0 else 0.0
    hi = hi if type(hi) is float and math.isfinite(hi) and hi > lo else sys.float_info.max
    return lo, hi
