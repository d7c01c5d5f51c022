"""freeze_heap (rubass/ros/gcfreeze.py): what is alive leaves the cyclic collector's scans, and a
frozen spec and engine are still freed by reference counting when a reload drops them."""
import gc
import os
import weakref

from rubass.engine import Engine
from rubass.lang import load_spec
from rubass.ros.gcfreeze import freeze_heap

from conftest import ROOT


def test_after_the_freeze_a_full_collection_scans_only_what_was_made_since_and_frozen_specs_still_go():
    spec = load_spec(os.path.join(ROOT, "config", "kobuki.rbs"), [os.path.join(ROOT, "config", "kobuki_actions.yaml")])
    engine = Engine(spec, 0.0)
    engine.evaluate_all(0.0)
    gone = [weakref.ref(spec), weakref.ref(engine)]
    try:
        gc.collect()  # the garbage of earlier tests is not alive
        alive = len(gc.get_objects())
        frozen = freeze_heap()
        assert frozen >= alive * 0.9 and len(gc.get_objects()) < 100, "a full collection now scans ~nothing"
        made = [[i] for i in range(1000)]
        assert len(gc.get_objects()) >= 1000, "what is made after the freeze is scanned as usual"
        del made
        spec.topics  # noqa: B018 - still usable
        del spec, engine  # a reload drops them: frozen, they are freed by reference counting all the same
        assert [r() for r in gone] == [None, None]
    finally:
        gc.unfreeze()
