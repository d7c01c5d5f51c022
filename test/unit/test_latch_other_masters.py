"""A latch kept under another master's name is found, so the monitor can say so at start (the state
file is keyed by master: a ROS_MASTER_URI spelt otherwise for a remote master names another file,
and the protective stop would be lost without a word)."""
import json

from rubass.actions.latches import VERSION, Latch, LatchFile, adopt_unkeyed, default_path, load, other_masters


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


def test_an_earlier_versions_file_for_any_master_is_copied_to_this_masters_name(tmp_path):
    """Review finding: on upgrade, a monitor of a master at another port (or host) read a new file name
    and lost the stop latched under the old one."""
    unkeyed = default_path(str(tmp_path), "/rubass", "")
    keyed = default_path(str(tmp_path), "/rubass", "12194")
    old = {"format": "rubass-latches", "version": VERSION, "spec": "s.rbs",  # no "master": an earlier version's
           "latched": [{"holder": "behaviour 1 (line 9)", "actions": ["stop"]}]}
    (tmp_path / "rubass").mkdir()
    (tmp_path / "rubass" / "rubass.latches.json").write_text(json.dumps(old))
    assert adopt_unkeyed(keyed, unkeyed)
    assert load(keyed, {"stop": True})[0] == [Latch("behaviour 1 (line 9)", ("stop",))]
    assert load(unkeyed, {"stop": True})[0]  # copied, not moved
    assert not adopt_unkeyed(keyed, unkeyed)  # this master's file exists now


def test_a_file_this_version_wrote_for_the_default_master_is_not_adopted(tmp_path):
    unkeyed = default_path(str(tmp_path), "/rubass", "")
    keyed = default_path(str(tmp_path), "/rubass", "12194")
    assert LatchFile(unkeyed, "s.rbs", "http://localhost:11311").save([Latch("behaviour 1 (line 9)", ("stop",))])
    assert not adopt_unkeyed(keyed, unkeyed)
    assert other_masters(keyed) == [unkeyed]  # but said at start


def test_a_latch_under_another_masters_name_is_a_warn_in_the_status_until_reset(tmp_path):
    """Review finding: the only sign was a log line at start; /diagnostics said OK."""
    import os

    from conftest import ROOT

    from rubass.actions import status
    from rubass.actions.keeper import LatchKeeper
    from rubass.lang import check_text

    ours = default_path(str(tmp_path), "/rubass", "robota.11311")
    theirs = default_path(str(tmp_path), "/rubass", "10.0.0.5.11311")
    assert LatchFile(theirs, "s.rbs").save([Latch("behaviour 1 (line 9)", ("stop",))])
    keeper = LatchKeeper(LatchFile(ours, "s.rbs"), lambda level, text: None, lambda event: None)
    keeper.restore({}, {}, 0.0)
    spec = check_text("action primitive stop;\nentity a { rules: r: topic /x.data > 1; }\nif (a.r) then { stop; }\n",
                      os.path.join(ROOT, "x.rbs"), [os.path.join(ROOT, "docs", "examples", "actions.yaml")])

    def monitor_entry():
        return status.build(spec, {"a.r": False}, [], {}, {}, {}, dict(keeper.status(), master="connected"))[-1]

    e = monitor_entry()
    assert e.level == status.WARN and "LATCHED UNDER ANOTHER MASTER'S NAME" in e.message and theirs in e.message, e
    keeper.reset({}, 1.0)
    assert monitor_entry().level == status.OK
