"""`rubass test`: rule unit tests from YAML files, run on the same engine as replay (TESTING.md)."""
