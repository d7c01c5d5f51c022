"""Physical units: the table of LANGUAGE.md §7, normalised to SI, with dimensions."""
from __future__ import annotations

import math
from fractions import Fraction
from typing import Dict, Optional, Tuple, Union

from .errors import a_noun

# A dimension is a sorted tuple of (base, exponent); bases: m, s, rad, B, and V (voltage),
# A (current), degC (temperature), Pa (pressure), geo_deg (latitude/longitude, see GEO_DEGREE).
# An exponent is a whole number, or a Fraction where sqrt() halved an odd one (sqrt(1 m) is m^(1/2):
# no SI dimension, but sqrt(2 m) * sqrt(1 m/s^2) is a speed again).
Exponent = Union[int, Fraction]
Dimension = Tuple[Tuple[str, Exponent], ...]

DIMENSIONLESS: Dimension = ()


def _whole(exp: Exponent) -> Exponent:
    return int(exp) if isinstance(exp, Fraction) and exp.denominator == 1 else exp


def dim(**exps: Exponent) -> Dimension:
    """Build a dimension from base exponents, e.g. dim(m=1, s=-1)."""
    return tuple(sorted((k, _whole(v)) for k, v in exps.items() if v))


def dim_mul(a: Dimension, b: Dimension, sign: int = 1) -> Dimension:
    """The dimension of a*b (sign=1) or a/b (sign=-1)."""
    out: Dict[str, Exponent] = dict(a)
    for base, exp in b:
        out[base] = out.get(base, 0) + sign * exp
    return dim(**out)


def dim_sqrt(a: Dimension) -> Dimension:
    """The dimension of sqrt(a): every exponent halved."""
    return dim(**{base: Fraction(exp) / 2 for base, exp in a})


TIME = dim(s=1)
LENGTH = dim(m=1)
SPEED = dim(m=1, s=-1)
FREQUENCY = dim(s=-1)
MEMORY = dim(B=1)
# what count() and len() give: a number of things, compared with plain numbers only
COUNT: Dimension = (("count", 1),)
VOLTAGE = dim(V=1)
CURRENT = dim(A=1)
TEMPERATURE = dim(degC=1)  # Celsius only: no kelvin, so no offset to convert
PRESSURE = dim(Pa=1)
# NavSatFix latitude and longitude are degrees, not SI radians: a dimension of their own, so that
# `topic /fix.latitude > 45 deg` (45 deg is 0.785 rad) is an error rather than a silent mismatch.
GEO_DEGREE = dim(geo_deg=1)

_NAMES = {
    (): "share",
    TIME: "time",
    LENGTH: "length",
    SPEED: "speed",
    dim(m=1, s=-2): "acceleration",
    dim(rad=1): "angle",
    dim(rad=1, s=-1): "angular speed",
    FREQUENCY: "frequency",
    MEMORY: "memory",
    VOLTAGE: "voltage",
    CURRENT: "current",
    TEMPERATURE: "temperature",
    PRESSURE: "pressure",
    dim(V=1, A=1): "power",
    GEO_DEGREE: "latitude/longitude in degrees (compare with a bare number)",
    dim(m=2): "area",
    dim(rad=1, s=-2): "angular acceleration",
}

# unit -> (factor to SI, dimension)
UNITS: Dict[str, Tuple[float, Dimension]] = {
    "s": (1.0, TIME), "sec": (1.0, TIME), "ms": (1e-3, TIME), "us": (1e-6, TIME),
    "min": (60.0, TIME), "h": (3600.0, TIME),
    "m": (1.0, LENGTH), "cm": (1e-2, LENGTH), "mm": (1e-3, LENGTH), "km": (1e3, LENGTH),
    "m/s": (1.0, SPEED), "cm/s": (1e-2, SPEED), "km/h": (1000.0 / 3600.0, SPEED),
    "m/s^2": (1.0, dim(m=1, s=-2)),
    "rad": (1.0, dim(rad=1)), "deg": (3.141592653589793 / 180.0, dim(rad=1)),
    "rad/s": (1.0, dim(rad=1, s=-1)), "deg/s": (3.141592653589793 / 180.0, dim(rad=1, s=-1)),
    "Hz": (1.0, FREQUENCY), "kHz": (1e3, FREQUENCY),
    "%": (1e-2, DIMENSIONLESS),
    "B": (1.0, MEMORY), "kB": (1e3, MEMORY), "MB": (1e6, MEMORY), "GB": (1e9, MEMORY),
    "KiB": (1024.0, MEMORY), "MiB": (1024.0 ** 2, MEMORY), "GiB": (1024.0 ** 3, MEMORY),
    "V": (1.0, VOLTAGE), "mV": (1e-3, VOLTAGE),
    "A": (1.0, CURRENT), "mA": (1e-3, CURRENT),
    "degC": (1.0, TEMPERATURE), "\u00b0C": (1.0, TEMPERATURE),  # '°C' only in YAML: a spec writes degC
    "Pa": (1.0, PRESSURE), "hPa": (1e2, PRESSURE), "kPa": (1e3, PRESSURE),
    "rad/s^2": (1.0, dim(rad=1, s=-2)),
}


def _rational(factor: float) -> Optional[Tuple[int, int]]:
    """(n, d) with n / d == factor exactly, small, when there is one (not for deg's pi/180)."""
    from fractions import Fraction

    f = Fraction(factor).limit_denominator(10 ** 6)
    return (f.numerator, f.denominator) if f.denominator > 1 and f.numerator / f.denominator == factor else None


_RATIONAL = {u: r for u, (f, _) in UNITS.items() for r in [_rational(f)] if r is not None}


def to_si(value: float, unit: str) -> float:
    """`value` in `unit` (a key of UNITS) in SI units, as the decimal a person means where a division
    gives it: 70 % is 0.7 (70 * 0.01 is 0.7000000000000001, and `cpu(node n) >= 70 %` would be false at
    0.7), 36 km/h is 10 m/s."""
    factor = UNITS[unit][0]
    r = _RATIONAL.get(unit)
    if r is not None:
        exact = value * r[0] / r[1]
        if math.isfinite(exact):
            return exact
    return value * factor


def dimension_name(d: Dimension) -> str:
    """A readable name: 'time', 'speed', or a formula such as 'm^2'."""
    if d == COUNT:
        return "count"
    if d in _NAMES:
        return _NAMES[d]
    shown = {"geo_deg": "deg(lat/lon)"}  # a base of its own (GEO_DEGREE), not a unit a spec writes
    return "*".join(f"{shown.get(base, base)}" + ("" if exp == 1 else f"^({exp})" if isinstance(exp, Fraction)
                                                  else f"^{exp}") for base, exp in d)


def parse_quantity(text: str) -> Optional[Tuple[float, Dimension]]:
    """'20 Hz', '0.5s', '3' -> (SI value, dimension); None when it is not a quantity.

    A bare number gets the dimension None's stand-in DIMENSIONLESS; used for YAML fields.
    """
    import re

    m = re.fullmatch(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S*)\s*", text)
    if not m:
        return None
    value = float(m.group(1))
    if not m.group(2):
        return (value, DIMENSIONLESS) if math.isfinite(value) else None
    unit = UNITS.get(m.group(2))
    if unit is None:
        return None
    si = to_si(value, m.group(2))
    if not math.isfinite(si) or (si == 0.0 and value != 0.0):  # 1e308 h is no timeout; 1e-322 us no zero
        return None
    return si, unit[1]


# other spellings of units, to suggest the unit itself ('sec' is a unit too, but 'm/sec' is not)
_SPELLINGS = {"sec": "s", "secs": "s", "second": "s", "seconds": "s", "msec": "ms", "hr": "h", "hrs": "h",
              "hour": "h", "hours": "h", "meter": "m", "meters": "m", "metre": "m", "metres": "m",
              "degree": "deg", "degrees": "deg", "radian": "rad", "radians": "rad", "hz": "Hz", "mins": "min",
              "mps": "m/s", "kph": "km/h", "kmh": "km/h", "C": "degC", "celsius": "degC", "volt": "V",
              "volts": "V", "v": "V", "amp": "A", "amps": "A", "ampere": "A", "amperes": "A", "pascal": "Pa", "degc": "degC"}
_WRITABLE = [u for u in UNITS if u.isascii()]  # what a spec can write ('°C' is for YAML; the spec writes degC)


def _unit_part(text: str) -> Optional[Tuple[float, Dimension]]:
    """'sec' or 's^2' (a part of a compound unit) -> (factor, dimension), None when unknown."""
    name, _, power = text.partition("^")
    if power and not power.isdigit():
        return None
    name = _SPELLINGS.get(name, _SPELLINGS.get(name.lower(), name))
    if "/" in name or name not in UNITS:
        return None
    factor, d = UNITS[name]
    n = int(power) if power else 1
    return factor ** n, tuple((b, e * n) for b, e in d)


def _compound(unit: str) -> Optional[Tuple[float, Dimension]]:
    """'m/sec' -> the factor and dimension it means, None when a part is unknown."""
    parts = unit.split("/")
    if len(parts) != 2:
        return None
    top, bottom = _unit_part(parts[0]), _unit_part(parts[1])
    if top is None or bottom is None:
        return None
    return top[0] / bottom[0], dim_mul(top[1], bottom[1], -1)


def unit_suggestion(unit: str) -> str:
    """A suggestion suffix for an unknown unit, as errors.did_you_mean gives one ('' when nothing is
    close). A compound unit is suggested whole: 'm/sec' -> 'm/s', not the 'sec' a spelling match finds."""
    import difflib

    import re

    if any(not re.fullmatch(r"0*[1-9]\d*", power) for power in re.findall(r"\^([^/*]*)", unit)):
        return ""  # 's^0', 's^-1', 's^x': no unit of rubass means it, and none is as good as a wrong one
    if unit == "K" or unit.lower() == "kelvin":
        return "; rubass has no kelvin: a temperature is written in degC"
    meant = _compound(unit) if "/" in unit else _unit_part(unit) if "^" in unit else None
    if meant is not None:  # its dimension is known: only a unit of that dimension is suggested
        same = [u for u in _WRITABLE if UNITS[u][1] == meant[1]]
        exact = [u for u in same if abs(UNITS[u][0] - meant[0]) <= 1e-9 * meant[0]]
        if exact:
            return f"; did you mean '{exact[0]}'?"
        if same:
            return f"; {a_noun(dimension_name(meant[1]))} is written in {', '.join(same)}"
        return ""  # 's^2/m': the inverse 'm/s^2' is spelt alike but means something else
    alone = _SPELLINGS.get(unit, _SPELLINGS.get(unit.lower()))
    if alone is not None:
        return f"; did you mean '{alone}'?"
    pool = sorted(u for u in _WRITABLE if ("/" in u) == ("/" in unit) and _parts_agree(unit, u)) or \
        sorted(u for u in _WRITABLE if _parts_agree(unit, u))
    close = difflib.get_close_matches(unit, pool, n=1, cutoff=0.6)
    return f"; did you mean '{close[0]}'?" if close else ""


def _parts_agree(unit: str, candidate: str) -> bool:
    """Whether `candidate` may be what `unit` meant: each part of `unit` rubass reads ('m' of 'm/s2') has the
    dimension of the candidate's part in its place (so 's2/m' is never 'm/s^2')."""
    mine, theirs = unit.split("/"), candidate.split("/")
    if len(mine) != len(theirs):
        return False  # 'm/s/s' is no 'm/s'
    for a, b in zip(mine, theirs):
        known, other = _unit_part(a), UNITS.get(b) or _unit_part(b)
        if known is not None and (other is None or other[1] != known[1]):
            return False
    return True
