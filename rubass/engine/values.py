"""Run-time values and Kleene logic: defined with the operator table in rubass.lang.values, so
constant folding and evaluation share one meaning (LANGUAGE.md §5)."""
from ..lang.values import UNKNOWN, Value, as_bool, as_num, k_and, k_not, k_or

__all__ = ["UNKNOWN", "UNREADABLE", "Value", "as_bool", "as_num", "k_and", "k_not", "k_or"]


class _Unreadable:
    """A message the shell received but could read none of the spec's fields in (a publisher of
    another type, a type that cannot be loaded): its fields are unknown, and it is no data, so
    age() and frequency() go on counting from the last message that could be read."""

    __slots__ = ()

    def __repr__(self) -> str:
        return "UNREADABLE"


UNREADABLE = _Unreadable()
