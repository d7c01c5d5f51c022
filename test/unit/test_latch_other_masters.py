"""A latch kept under another master's name is found, so the monitor can say so at start (the state
file is keyed by master: a ROS_MASTER_URI spelt otherwise for a remote master names another file,
and the protective stop would be lost without a word)."""
from rubass.actions.latches import Latch, LatchFile, default_path, other_masters


def test_a_latch_of_this_node_under_another_masters_name_is_found_only_while_ours_holds_none(tmp_path):
    ours = default_path(str(tmp_path), "/rubass", "robota.11311")
    theirs = default_path(str(tmp_path), "/rubass", "10.0.0.5.11311")
    assert other_masters(ours) == []  # no folder yet
    assert LatchFile(theirs, "s.rbs").save([Latch("behaviour 1 (line 9)", ("stop",))])
    assert other_masters(ours) == [theirs]
    assert LatchFile(ours, "s.rbs").save([Latch("behaviour 1 (line 9)", ("stop",))])
    assert other_masters(ours) == []  # ours holds one: nothing is lost


def test_released_files_other_nodes_and_foreign_files_are_not_named(tmp_path):
    ours = default_path(str(tmp_path), "/rubass", "")
    released = default_path(str(tmp_path), "/rubass", "12194")
    other_node = default_path(str(tmp_path), "/safety", "12195")
    assert LatchFile(released, "s.rbs").save([])
    assert LatchFile(other_node, "s.rbs").save([Latch("behaviour 1 (line 9)", ("stop",))])
    (tmp_path / "rubass" / "rubass.9.latches.json").write_text("not json")
    assert other_masters(ours) == []
