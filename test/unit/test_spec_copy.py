"""docs/spec/ vendors the contract (LANGUAGE.md, TESTING.md) so that a clone holds what its docs cite;
each copy must stay byte-identical to ../shared/spec, its source, wherever that folder exists."""
import os

import pytest

from conftest import ROOT, SHARED

NAMES = ("LANGUAGE.md", "TESTING.md")


@pytest.mark.parametrize("name", NAMES)
def test_the_vendored_copy_exists_and_is_not_empty(name: str) -> None:
    path = os.path.join(ROOT, "docs", "spec", name)
    assert os.path.isfile(path), f"{path} is missing: docs and config/*.rbs cite it"
    assert os.path.getsize(path) > 1000


@pytest.mark.parametrize("name", NAMES)
def test_the_vendored_copy_is_byte_identical_to_shared_spec(name: str) -> None:
    source = os.path.join(SHARED, "spec", name)
    if not os.path.isfile(source):
        pytest.skip(f"{source} is absent (../shared/spec exists only beside the project in development): "
                    f"nothing to compare docs/spec/{name} with")
    with open(source, "rb") as fh:
        want = fh.read()
    with open(os.path.join(ROOT, "docs", "spec", name), "rb") as fh:
        got = fh.read()
    assert got == want, (f"docs/spec/{name} differs from {source}: copy it again "
                         f"(cp {source} docs/spec/{name})")
