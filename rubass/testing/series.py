"""Compact series (promtool-style): `"0x10 0.6x20 0+0.1x5 _x3 nan"` -> one value or a gap per step.

Words: `V` one value; `VxN` V, N times; `A+BxN` N values A, A+B, …, A+(N-1)·B (`A-BxN` counts
down); `_` no message at that step, `_xN` N such steps. Values: numbers (a unit may follow with
no space: `20%`, `0.5m/s`), `nan`, `inf`, `-inf`, `true`, `false`, and quoted strings.
"""
from __future__ import annotations

import re
from typing import Any, List

from ..lang.errors import RubassError, a_noun
from ..lang.units import UNITS, dimension_name, unit_suggestion

GAP: Any = object()  # a step with no message

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_QUOTED = r'"(?:[^"\\]|\\.)*"|\'[^\']*\''
_WORD = re.compile(rf"(?:{_QUOTED})\S*|\S+")  # a quoted string with what follows it: '"a b"x3'
_QUOTED_WORD = re.compile(rf"({_QUOTED})(\S*)")
_RAMP = re.compile(rf"({_NUM})([-+](?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)x(\d+)")
_REPEAT = re.compile(r"(.+)x(\d+)")
_MAX_STEPS = 10_000_000
_BAD_COUNT = re.compile(rf".+x({_NUM})")  # xN with N a number that is no whole count


class SeriesError(RubassError, ValueError):
    """A word of a series that is not one of the forms; the message says which and why."""


UNKNOWN: Any = object()  # a field whose dimension no unit table gives: any unit is converted to SI


def _units_of(d: Any) -> str:
    return ", ".join(u for u, (_, ud) in UNITS.items() if ud == d)


def value(word: str, field_dim: Any = UNKNOWN, field: str = "the field") -> Any:
    """One value word as a message value (float, bool or str). A number with a unit is converted to SI;
    the unit must be of the field's dimension when it is known (`field_dim`, None: a number with none)."""
    low = word.lower()
    if low in ("nan", "inf", "-inf", "+inf"):
        return float(low)
    if low in ("true", "false"):
        return low == "true"
    if len(word) >= 2 and word[0] == word[-1] and word[0] in "\"'":
        inner = word[1:-1]
        return re.sub(r"\\(.)", r"\1", inner) if word[0] == '"' else inner
    m = re.fullmatch(rf"({_NUM})(\S*)", word)
    if m is None:
        raise SeriesError(f"'{word}' is not a value (a number, nan, inf, true, false or a quoted string)")
    number, unit = float(m.group(1)), m.group(2)
    if not unit:
        return number
    if not (unit[0].isalpha() or unit[0] in "%\u00b0"):  # '1,5', '0.5.5': no unit, no number
        raise SeriesError(f"'{word}' is not a value (a number, nan, inf, true, false or a quoted string)")
    known = field_dim is not UNKNOWN and field_dim is not None
    if unit not in UNITS:
        hint = f" (units of {a_noun(dimension_name(field_dim))}: {_units_of(field_dim)})" if known and _units_of(field_dim) \
            else ""
        meant = unit_suggestion(unit)
        meant = meant if meant.startswith("; did you mean") else ""
        raise SeriesError(f"'{word}': '{unit}' is not a unit rubass knows{meant}{hint}")
    factor, udim = UNITS[unit]
    if known and udim != field_dim:
        raise SeriesError(f"'{word}' is {a_noun(dimension_name(udim))} ({unit}), but {field} is "
                          f"{a_noun(dimension_name(field_dim))} (units: {_units_of(field_dim) or 'none'})")
    if field_dim is None:
        raise SeriesError(f"'{word}' has a unit ({unit}), but {field} is not a number with a unit: "
                          f"write the value alone")
    return number * factor


def expand(text: Any, field_dim: Any = UNKNOWN, field: str = "the field") -> List[Any]:
    """The steps of a series: values, or GAP where no message is sent. `field_dim`: the dimension of
    the field it sets (UNKNOWN when no table gives it; None for a number without unit, a bool or a
    string), against which a value's unit is checked."""
    if isinstance(text, list):
        out: List[Any] = []
        for item in text:
            out.extend(expand(item, field_dim, field) if isinstance(item, str)
                       else [item if item is not None else GAP])
        return out
    if isinstance(text, bool) or isinstance(text, (int, float)):
        return [float(text) if not isinstance(text, bool) else text]
    if not isinstance(text, str):
        raise SeriesError("values must be a string of words or a list")
    steps: List[Any] = []
    for word in _WORD.findall(text):
        steps.extend(_word(word, field_dim, field))
        if len(steps) > _MAX_STEPS:
            raise SeriesError(f"more than {_MAX_STEPS} steps")
    if not steps:
        raise SeriesError("a series needs at least one step")
    return steps


def _word(word: str, field_dim: Any, field: str) -> List[Any]:
    if word[0] in "\"'":
        m = _QUOTED_WORD.fullmatch(word)
        if m is None:  # an opening quote never closed
            raise SeriesError(f"'{word}': a quoted string needs its closing quote")
        text, rest = m.groups()
        if not rest:
            return [value(text)]  # an x inside the quotes is part of the string
        n = re.fullmatch(r"x(\d+)", rest)
        if n is None:
            raise SeriesError(f"'{rest}' after the string {text} is not xN (a string repeated N times)")
        return _repeat(word, value(text), int(n.group(1)))
    if word == "_":
        return [GAP]
    m = _RAMP.fullmatch(word)
    if m:
        a, b, n = float(m.group(1)), float(m.group(2)), _count(word, int(m.group(3)))
        return [round(a + k * b, 12) for k in range(n)]  # 0.1 * 3 is 0.3 here, as the author meant
    m = _REPEAT.fullmatch(word)
    if m:
        return _repeat(word, GAP if m.group(1) == "_" else value(m.group(1), field_dim, field), int(m.group(2)))
    m = _BAD_COUNT.fullmatch(word)
    if m:  # `0x1.5`, `0x-2`, `_x2e1`: a count, but not a whole one
        raise SeriesError(f"'{word}': N in xN (how many times) must be a whole number of at least 1, "
                          f"not {m.group(1)}")
    return [value(word, field_dim, field)]


def _count(word: str, n: int) -> int:
    """N of a word's xN: at least 1 (`0.6x0` would be no step at all, surely not what was meant)."""
    if n < 1:
        raise SeriesError(f"'{word}': N in xN must be at least 1 (`_xN` is N steps without a message)")
    if n > _MAX_STEPS:
        raise SeriesError(f"'{word}': more than {_MAX_STEPS} steps")
    return n


def _repeat(word: str, v: Any, n: int) -> List[Any]:
    _count(word, n)
    if n > _MAX_STEPS:
        raise SeriesError(f"'{word}': more than {_MAX_STEPS} steps")
    return [v] * n
