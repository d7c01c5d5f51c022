"""The kept-alive XML-RPC caller used for polled calls (node liveness, the master watch), against
the standard library's servers (HTTP/1.0, and HTTP/1.1 as rospy's) and broken ones."""
import socket
import threading
import time
import xmlrpc.client
from xmlrpc.server import SimpleXMLRPCRequestHandler, SimpleXMLRPCServer

import pytest

from rubass.ros.rpc import Caller


class _Http11(SimpleXMLRPCRequestHandler):
    protocol_version = "HTTP/1.1"  # as rosgraph's handler: connections are kept


class _Counting(SimpleXMLRPCServer):
    def __init__(self, handler):
        super().__init__(("127.0.0.1", 0), handler, logRequests=False)
        self.connections = 0

    def process_request(self, request, client_address):
        self.connections += 1
        threading.Thread(target=self._serve_one, args=(request, client_address), daemon=True).start()

    def _serve_one(self, request, client_address):
        try:
            self.finish_request(request, client_address)
        except OSError:
            pass
        finally:
            self.shutdown_request(request)


@pytest.fixture(params=[_Http11, SimpleXMLRPCRequestHandler], ids=["http1.1", "http1.0"])
def server(request):
    srv = _Counting(request.param)
    srv.register_function(lambda caller: [1, "", 4242], "getPid")
    srv.register_function(lambda caller, name: [1, "", f"http://h:1/{name}"], "lookupNode")

    def fault():
        raise ValueError("boom")

    srv.register_function(fault, "fault")
    srv.register_function(lambda: "x" * 200_000, "big")
    thread = threading.Thread(target=srv.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True)
    thread.start()
    yield srv, request.param is _Http11
    srv.shutdown()
    srv.server_close()


def test_calls_answer_as_the_standard_client_does(server):
    srv, _ = server
    uri = f"http://127.0.0.1:{srv.server_address[1]}/"
    caller = Caller(uri, 1.0)
    try:
        for _ in range(3):
            assert caller.call("getPid", "/me") == [1, "", 4242]
            assert caller.call("lookupNode", "/me", "/n") == xmlrpc.client.ServerProxy(uri).lookupNode("/me", "/n")
        assert caller.call("big") == "x" * 200_000
    finally:
        caller.close()


def test_an_http11_server_keeps_one_connection_for_every_call(server):
    srv, kept = server
    caller = Caller(f"http://127.0.0.1:{srv.server_address[1]}/", 1.0)
    try:
        for _ in range(20):
            caller.call("getPid", "/me")
    finally:
        caller.close()
    assert srv.connections == (1 if kept else 20)


def test_a_fault_is_raised_and_the_connection_still_serves(server):
    srv, _ = server
    caller = Caller(f"http://127.0.0.1:{srv.server_address[1]}/", 1.0)
    try:
        with pytest.raises(xmlrpc.client.Fault):
            caller.call("fault")
        assert caller.call("getPid", "/me") == [1, "", 4242]
    finally:
        caller.close()


def _listener():
    sock = socket.socket()
    sock.bind(("127.0.0.1", 0))
    sock.listen(8)
    return sock


def test_a_server_that_accepts_but_never_answers_times_out_in_the_time_given():
    sock = _listener()  # a hung node: its kernel accepts, nobody reads
    try:
        caller = Caller(f"http://127.0.0.1:{sock.getsockname()[1]}/", 0.2)
        t0 = time.monotonic()
        with pytest.raises(socket.timeout):
            caller.call("getPid", "/me")
        assert 0.15 < time.monotonic() - t0 < 2.0
    finally:
        sock.close()


def _one_answer(sock, answer):
    conn, _ = sock.accept()
    conn.recv(65536)
    conn.sendall(answer)
    conn.close()


@pytest.mark.parametrize("answer, error", [
    (b"garbage\r\n\r\n", xmlrpc.client.ProtocolError),
    (b"HTTP/1.1 500 Internal\r\nContent-Length: 0\r\n\r\n", xmlrpc.client.ProtocolError),
    (b"HTTP/1.1 200 OK\r\nContent-Length: 100\r\n\r\n<short", xmlrpc.client.ProtocolError),
    (b"HTTP/1.1 200 OK\r\nContent-Length: 5\r\n\r\nnoxml", xmlrpc.client.ResponseError),
    (b"HTTP/1.1 200 OK\r\nContent-Length: x\r\n\r\n", xmlrpc.client.ProtocolError),
    (b"", xmlrpc.client.ProtocolError),  # closed without a word
])
def test_a_broken_answer_is_an_xmlrpc_error_not_a_crash(answer, error):
    sock = _listener()
    try:
        threading.Thread(target=_one_answer, args=(sock, answer), daemon=True).start()
        caller = Caller(f"http://127.0.0.1:{sock.getsockname()[1]}/", 1.0)
        with pytest.raises(error):
            caller.call("getPid", "/me")
        assert caller._sock is None  # never reused after a broken answer
    finally:
        sock.close()


@pytest.mark.parametrize("reset", [False, True], ids=["closed", "reset"])
def test_a_kept_connection_the_server_dropped_while_idle_is_reopened_once(reset):
    import struct

    sock = _listener()
    body = xmlrpc.client.dumps(([1, "", 7],), methodresponse=True).encode()
    answer = b"HTTP/1.1 200 OK\r\nContent-Length: %d\r\n\r\n" % len(body) + body

    def serve():
        first, _ = sock.accept()  # answers once, then drops the connection while idle
        first.recv(65536)
        first.sendall(answer)
        time.sleep(0.1)
        if reset:  # an RST, as from a host that lost the connection; else a clean close (a restart)
            first.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        first.close()
        second, _ = sock.accept()
        second.recv(65536)
        second.sendall(answer)
        second.close()

    threading.Thread(target=serve, daemon=True).start()
    try:
        caller = Caller(f"http://127.0.0.1:{sock.getsockname()[1]}/", 1.0)
        assert caller.call("getPid", "/me") == [1, "", 7]
        time.sleep(0.3)
        assert caller.call("getPid", "/me") == [1, "", 7]
    finally:
        sock.close()


def test_a_refused_connection_is_an_oserror():
    sock = _listener()
    port = sock.getsockname()[1]
    sock.close()
    with pytest.raises(OSError):
        Caller(f"http://127.0.0.1:{port}/", 0.5).call("getPid", "/me")


def test_a_uri_that_is_not_http_is_refused_at_once():
    with pytest.raises(ValueError):
        Caller("rosrpc://host:1", 0.5)


def test_without_keep_alive_every_call_has_a_connection_of_its_own(server):
    srv, _ = server
    caller = Caller(f"http://127.0.0.1:{srv.server_address[1]}/", 1.0, keep_alive=False)
    for _ in range(5):
        assert caller.call("getPid", "/me") == [1, "", 4242]
        assert caller._sock is None
    assert srv.connections == 5

