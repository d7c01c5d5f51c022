"""The latch state file (issue 13, item 6): round trip, atomic write, corrupt and foreign files."""
import json
import os

from rubass.actions.latches import Latch, LatchFile, default_path, load

DECLARED = {"stop": True, "brake": False, "warn": False}


def test_default_path_is_under_ros_home_and_named_after_the_node(tmp_path):
    assert default_path(str(tmp_path), "/ns/rubass") == str(tmp_path / "rubass" / "ns_rubass.latches.json")
    assert default_path(None, "/rubass").endswith(os.path.join(".ros", "rubass", "rubass.latches.json"))


def test_round_trip_and_no_file_means_nothing_latched(tmp_path):
    path = str(tmp_path / "d" / "s.json")
    assert load(path, DECLARED) == ([], [])
    f = LatchFile(path, "/s.rbs")
    assert f.save([Latch("behaviour 1 (line 4)", ("stop",))])
    assert load(path, DECLARED) == ([Latch("behaviour 1 (line 4)", ("stop",))], [])
    assert not [n for n in os.listdir(tmp_path / "d") if n.endswith(".tmp")]
    assert f.save([]) and load(path, DECLARED) == ([], [])


def test_a_write_that_fails_is_reported_not_raised(tmp_path):
    (tmp_path / "file").write_text("x")
    f = LatchFile(str(tmp_path / "file" / "s.json"))
    assert not f.save([Latch("b", ("stop",))])
    assert "cannot write the latch state" in f.error


def test_a_truncated_file_latches_the_actions_it_names(tmp_path):
    path = tmp_path / "s.json"
    path.write_text('{"format": "rubass-latches", "version": 1, "latched": [{"holder": "b", "actions": ["brake"')
    latches, problems = load(str(path), DECLARED)
    assert latches == [Latch("restored from a damaged latch state file", ("brake",))]
    assert "corrupt or foreign" in problems[0] and "treated as latched: brake" in problems[0]


def test_garbage_naming_nothing_latches_every_latched_action(tmp_path):
    path = tmp_path / "s.json"
    path.write_bytes(b"\x00\xff\xfe")
    latches, problems = load(str(path), DECLARED)
    assert latches[0].actions == ("stop",) and problems


def test_a_foreign_file_and_undeclared_actions_are_reported(tmp_path):
    path = tmp_path / "s.json"
    path.write_text(json.dumps({"format": "rubass-latches", "version": 99,
                                "latched": [{"holder": "b", "actions": ["stop"]}]}))
    latches, problems = load(str(path), DECLARED)
    assert latches[0].actions == ("stop",) and "another version" in problems[0]
    path.write_text(json.dumps({"format": "rubass-latches", "version": 1,
                                "latched": [{"holder": "b", "actions": ["stop", "halt"]}]}))
    latches, problems = load(str(path), DECLARED)
    assert latches == [Latch("b", ("stop",))] and "halt" in problems[0] and "cannot hold" in problems[0]


def test_a_latch_file_under_the_former_default_name_is_adopted_once(tmp_path):
    """A plain rosrun monitor was /rubass_monitor; it is /rubass now: its latched stop must survive."""
    from rubass.actions.latches import adopt_old_default, default_path

    home = str(tmp_path)
    new, old = default_path(home, "/rubass"), default_path(home, "/rubass_monitor")
    os.makedirs(os.path.dirname(old))
    with open(old, "w") as fh:
        fh.write("{}")
    assert adopt_old_default(new, old) and os.path.isfile(new) and not os.path.exists(old)
    with open(old, "w") as fh:
        fh.write("{}")
    assert not adopt_old_default(new, old), "a file under the new name is never replaced"
    assert adopt_old_default(str(tmp_path / "x.json"), str(tmp_path / "none.json")) is False


def test_a_latch_state_that_could_not_be_written_is_written_once_the_disk_is_free(tmp_path):
    """An acceptance sweep: a latched stop that started while the disk was full was never written
    after the disk was freed (writes happened only on changes), so a kill -9 later restarted without
    it: the robot went again without ~reset. The keeper tries again at the ticks, once a second."""
    from rubass.actions.keeper import RETRY, LatchKeeper
    from rubass.engine import Engine
    from rubass.lang import check_text

    from conftest import ROOT
    spec = check_text("action primitive stop;\nentity e { rules: r: topic /v.data > 1; }\nif (e.r) then { stop; }\n",
                      str(tmp_path / "s.rbs"), [os.path.join(ROOT, "docs", "examples", "actions.yaml")])
    engine = Engine(spec, 0.0)
    engine.evaluate_all(0.0)
    full = tmp_path / "full"
    full.write_text("a file where the folder should be: every write fails")
    logs = []
    keeper = LatchKeeper(LatchFile(str(full / "latch.json")), lambda level, text: logs.append((level, text)),
                         lambda record: None)
    engine.on_message("/v", 1.0, {"data": 2.0})  # the latched stop starts
    keeper.save(engine, [], [])
    assert keeper.file.error.endswith(f"{full} is not a folder") and logs[-1][0] == "error"  # not "File exists"
    keeper.retry(engine, [], [], 1.5)
    assert keeper.file.error  # still full
    full.unlink()  # the disk is freed
    keeper.retry(engine, [], [], 1.5 + RETRY / 2)
    assert keeper.file.error, "at most once a second"
    keeper.retry(engine, [], [], 1.5 + RETRY)
    assert not keeper.file.error and logs[-1][0] == "info"
    assert load(str(full / "latch.json"), {"stop": True})[0] == [Latch("behaviour 1 (line 3)", ("stop",))]
