"""The rule engine: evaluates a checked spec over time. Imports no ROS and reads no clock."""
from .engine import Engine, Event
from .values import UNKNOWN

__all__ = ["Engine", "Event", "UNKNOWN"]
