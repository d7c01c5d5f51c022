"""Short garbage-collector pauses for the monitor. A full collection scans every object alive:
in a running monitor (~50,000 objects: rospy, the message classes, the spec and its engine) it
held the GIL for 12-32 ms on this 2-core VM, once a second or so, and a stop dispatched just
before it reached its actions that much later (`rubass experiments`, rows E_B and M_L). What is
alive once the monitor enforces a spec lives as long as that spec, so it is frozen out of the
collector's scans; the collections that remain scan only what was made since.

A spec and its engine hold no reference cycles (test_reload_garbage.py): when a reload replaces
them, reference counting frees them, frozen or not."""
from __future__ import annotations

import gc


def freeze_heap() -> int:
    """Collect what is garbage now, then freeze everything alive; returns the frozen count."""
    gc.collect()
    gc.freeze()
    return gc.get_freeze_count()
