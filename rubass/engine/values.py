"""Run-time values and Kleene logic: defined with the operator table in rubass.lang.values, so
constant folding and evaluation share one meaning (LANGUAGE.md §5)."""
from ..lang.values import UNKNOWN, Value, as_bool, as_num, k_and, k_not, k_or

__all__ = ["UNKNOWN", "Value", "as_bool", "as_num", "k_and", "k_not", "k_or"]
