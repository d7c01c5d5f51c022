"""The whole front end under fuzzing: a few hundred cases here, thousands in bench/fuzz.py."""
import os
import sys

from hypothesis import HealthCheck, given, settings

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from fuzzing import LIBRARIES, SPECS, clean_errors_only, spec_and_library  # noqa: E402


def test_the_seeds_are_valid(tmp_path):
    """The mutations start from specs and libraries that check clean (else they prove less)."""
    assert len(SPECS) >= 4 and len(LIBRARIES) >= 3
    for spec in SPECS:
        lib = next(lib for lib in LIBRARIES if all(a in lib for a in _actions(spec)))
        assert clean_errors_only(str(tmp_path), spec, lib) == 0


def _actions(spec):
    import re

    return [a.strip() for decl in re.findall(r"action primitive ([^;]*);", spec) for a in decl.split(",")]


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                  HealthCheck.function_scoped_fixture])
@given(spec_and_library())
def test_mutated_specs_and_libraries_give_clean_errors_only(tmp_path, case):
    clean_errors_only(str(tmp_path), *case)
