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
