"""hypothesis: REP 117 sectors (LANGUAGE.md §12) against the definition, element by element."""
import math

from hypothesis import given, settings
from hypothesis import strategies as st

from rubass.engine.arrays import _laser
from rubass.engine.values import UNKNOWN

READING = st.one_of(st.floats(0.0, 20.0), st.sampled_from([math.inf, -math.inf, math.nan, 0.05, 30.0]))


def reference(pick, ranges, lo, hi):
    valid = [0.0 if v == -math.inf else v for v in ranges if v == -math.inf or (v == v and lo <= v <= hi)]
    return float(pick(valid)) if valid else UNKNOWN


@settings(max_examples=400, deadline=None)
@given(ranges=st.lists(READING, max_size=40), lo=st.floats(0.0, 1.0), hi=st.floats(5.0, 25.0),
       use_max=st.booleans())
def test_sector_min_and_max_follow_rep_117(ranges, lo, hi, use_max):
    pick = max if use_max else min
    assert _laser(pick, tuple(ranges), (lo, hi)) == reference(pick, ranges, lo, hi)


def test_limits_a_driver_left_unset_are_ignored_not_a_blind_scan():
    """Acceptance finding: range_min = range_max = 0 (left unset by a driver) made every reading
    invalid, `min(ranges) < 0.5 m` unknown, and the stop released. Such bounds are ignored now;
    NaN and +inf readings stay no reading, -inf stays 0 m."""

    from rubass.engine.readings import laser_limits as _laser_limits

    ranges = (2.0, 0.3, math.nan, math.inf)
    for lo, hi in ((0.0, 0.0), (math.nan, math.nan), (0.1, math.inf), (0.5, 0.2), (-1.0, 30.0)):
        lim = _laser_limits({"range_min": lo, "range_max": hi})
        assert _laser(min, ranges, lim) == (0.3 if lo != 0.5 else 2.0), (lo, hi, lim)
        assert _laser(max, ranges, lim) == 2.0, (lo, hi, lim)
    assert _laser_limits({"range_min": 0.1, "range_max": 10.0}) == (0.1, 10.0)  # real limits kept
