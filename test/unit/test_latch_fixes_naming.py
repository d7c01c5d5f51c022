"""The latch state file is keyed by master as well as node name (two robots simulated on one machine,
each with its own master, share no file), and a latch on an action the spec no longer declares is
kept in it until ~reset (docs/failure-modes.md, latch state file)."""
import json
import os
import socket

from rubass.actions.latches import Latch, LatchFile, default_path, load, master_key, undeclared
from rubass.ros.latch_master import is_local

LOCAL = {"localhost", "127.0.0.1", "myhost"}
local = LOCAL.__contains__


def test_a_master_on_this_machine_at_the_default_port_keeps_the_version_2_name(tmp_path):
    for uri in ("http://localhost:11311", "http://127.0.0.1:11311/", "http://myhost:11311", "http://MyHost.:11311",
                "http://localhost"):
        assert master_key(uri, local) == "", uri
    assert default_path(str(tmp_path), "/rubass", "") == str(tmp_path / "rubass" / "rubass.latches.json")


def test_every_spelling_of_this_machine_at_another_port_is_one_file_and_another_port_another():
    keys = {master_key(f"http://{h}:12194", local) for h in ("localhost", "127.0.0.1", "myhost", "LOCALHOST")}
    assert keys == {"12194"}
    assert master_key("http://localhost:12195", local) == "12195"
    a, b = (default_path("/h", "/rubass", master_key(f"http://localhost:{p}", local)) for p in (12194, 12195))
    assert a != b and a == "/h/rubass/rubass.12194.latches.json"
    assert default_path("/h", "/rubass", "") not in (a, b)


def test_another_machines_master_is_named_by_host_and_port():
    assert master_key("http://Robot1:11311", local) == "robot1.11311"
    assert master_key("http://robot2:11311", local) != master_key("http://robot1:11311", local)
    assert master_key("http://[fe80::1]:11311", local) == "fe80__1.11311"
    assert master_key("http://robot1:notaport", local) == "http___robot1_notaport"


def test_is_local_knows_loopback_this_machines_name_and_not_another_address():
    assert is_local("localhost") and is_local("127.0.0.1") and is_local("127.0.1.1")
    assert is_local(socket.gethostname())
    assert not is_local("192.0.2.1")  # TEST-NET-1: no interface of this machine holds it


def _write(path, latched):
    path.write_text(json.dumps({"format": "rubass-latches", "version": 1, "spec": "/old.rbs", "latched": latched}))


def test_undeclared_lists_only_the_actions_the_spec_no_longer_declares(tmp_path):
    path = tmp_path / "s.json"
    assert undeclared(str(path), {"halt": True}) == []  # no file
    _write(path, [{"holder": "behaviour 1 (line 4)", "actions": ["stop", "brake"]}, {"holder": "b2", "actions": ["halt"]}])
    assert undeclared(str(path), {"halt": True, "brake": False}) == [Latch("behaviour 1 (line 4)", ("stop",))]
    assert undeclared(str(path), {"halt": True, "brake": False, "stop": True}) == []
    path.write_bytes(b"\x00garbage stop")
    assert undeclared(str(path), {"halt": True}) == []  # a damaged file is load's (latched for what it names)


def test_a_kept_latch_stays_in_the_file_with_every_state_until_cleared(tmp_path):
    path = str(tmp_path / "s.json")
    f = LatchFile(path, "/new.rbs")
    f.kept = [Latch("behaviour 1 (line 4)", ("stop",))]
    assert f.save([])
    assert undeclared(path, {"halt": True}) == f.kept, "another restart still knows of it"
    assert f.save([Latch("behaviour 2 (line 5)", ("halt",))])
    assert load(path, {"halt": True, "stop": True})[0] == [Latch("behaviour 1 (line 4)", ("stop",)),
                                                         Latch("behaviour 2 (line 5)", ("halt",))]
    f.kept = []
    assert f.save([]) and load(path, {"stop": True}) == ([], [])


def test_a_latch_written_for_another_spec_is_restored_all_the_same(tmp_path):
    """The conservative choice: a stop survives the spec's being renamed or moved."""
    path = tmp_path / "s.json"
    _write(path, [{"holder": "behaviour 1 (line 4)", "actions": ["stop"]}])
    assert load(str(path), {"stop": True}) == ([Latch("behaviour 1 (line 4)", ("stop",))], [])
    assert os.path.isfile(path)
