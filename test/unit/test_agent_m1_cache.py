"""The agent's node cache (rubass/ros/agent_cache.py): where it lives, reading a bad file, writing
it atomically, and which entries a node's own answer keeps. Pure: a local XML-RPC server plays
the node."""
import json
import os
import socket
import threading
import time
from xmlrpc.server import SimpleXMLRPCServer

import pytest

from rubass.ros import agent_cache


def test_the_cache_lives_under_ros_home_per_host(tmp_path, monkeypatch):
    assert agent_cache.cache_path(str(tmp_path), "10_0_0_2") == str(tmp_path / "rubass" / "agent_10_0_0_2.json")
    monkeypatch.setenv("HOME", str(tmp_path))
    assert agent_cache.cache_path(None, "gpu/board") == str(tmp_path / ".ros" / "rubass" / "agent_gpu_board.json")


def test_save_then_load_round_trips_and_a_missing_file_is_empty(tmp_path):
    path = str(tmp_path / "rubass" / "agent_h.json")
    assert agent_cache.load(path) == {}
    agent_cache.save(path, {"/b": "http://10.0.0.2:2/", "/a": "http://10.0.0.2:1/"})
    assert agent_cache.load(path) == {"/a": "http://10.0.0.2:1/", "/b": "http://10.0.0.2:2/"}
    assert [f for f in os.listdir(tmp_path / "rubass")] == ["agent_h.json"]  # no temporary file left


@pytest.mark.parametrize("text, why", [("{not json", "cannot read"), ("[1, 2]", "not an agent's node cache"),
                                       ('{"nodes": 3}', "not an agent's node cache")])
def test_a_bad_file_says_why(tmp_path, text, why):
    path = tmp_path / "agent_h.json"
    path.write_text(text)
    with pytest.raises(ValueError, match=why):
        agent_cache.load(str(path))


def test_entries_that_are_not_uris_are_left_out(tmp_path):
    path = tmp_path / "agent_h.json"
    path.write_text(json.dumps({"nodes": {"/a": "http://h:1/", "/b": 5, "/c": "ftp://x"}}))
    assert agent_cache.load(str(path)) == {"/a": "http://h:1/"}


@pytest.fixture
def fake_node():
    """A node named /kept answering getName; `hang` makes it answer after 1 s."""
    server = SimpleXMLRPCServer(("127.0.0.1", 0), logRequests=False)
    state = {"hang": False}

    def get_name(caller):
        if state["hang"]:
            time.sleep(1.0)
        return 1, "", "/kept"

    server.register_function(get_name, "getName")
    threading.Thread(target=server.serve_forever, daemon=True).start()
    state["uri"] = f"http://127.0.0.1:{server.server_address[1]}/"
    yield state
    server.shutdown()
    server.server_close()


def test_a_node_is_kept_only_while_it_answers_with_its_name(fake_node):
    uri = fake_node["uri"]
    assert agent_cache.check("/kept", uri, "/agent", 0.5) is True
    assert agent_cache.check("/other", uri, "/agent", 0.5) is False  # another node took the port
    with socket.socket() as s:  # a port nobody listens on: the node is gone
        s.bind(("127.0.0.1", 0))
        dead = f"http://127.0.0.1:{s.getsockname()[1]}/"
    assert agent_cache.check("/kept", dead, "/agent", 0.5) is False


def test_a_hung_node_is_neither_kept_as_known_nor_forgotten(fake_node):
    fake_node["hang"] = True
    assert agent_cache.check("/kept", fake_node["uri"], "/agent", 0.1) is None


def test_a_cpp_node_without_get_name_is_kept_while_it_answers_get_pid():
    """roscpp's slave API has getPid but no getName (a Fault): every C++ node was dropped from the cache."""
    server = SimpleXMLRPCServer(("127.0.0.1", 0), logRequests=False)
    server.register_function(lambda caller: (1, "", 4242), "getPid")
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        uri = f"http://127.0.0.1:{server.server_address[1]}/"
        assert agent_cache.check("/cpp_node", uri, "/agent", 0.5) is True
    finally:
        server.shutdown()
        server.server_close()
