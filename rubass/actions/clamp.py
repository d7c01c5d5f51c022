"""Clamping a velocity command into a `limit` action's ranges (LANGUAGE.md §16). Pure."""
from __future__ import annotations

from typing import Any, Dict, Optional, Tuple

Range = Tuple[float, float]
AXES: Dict[str, Tuple[str, str]] = {f"{part}_{c}": (part, c) for part in ("linear", "angular") for c in "xyz"}


def clamp(value: float, lo: float, hi: float) -> float:
    """value within [lo, hi]; NaN is no command, so it becomes the allowed value nearest zero."""
    if value != value:
        value = 0.0
    return lo if value < lo else hi if value > hi else value


def clamp_twist(twist: Any, ranges: Dict[str, Optional[Range]]) -> Any:
    """Clamp the named axes of a Twist-like object (twist.linear.x, …) in place; others pass."""
    for axis, bounds in ranges.items():
        if bounds is not None:
            part, c = AXES[axis]
            vec = getattr(twist, part)
            setattr(vec, c, clamp(float(getattr(vec, c)), bounds[0], bounds[1]))
    return twist
