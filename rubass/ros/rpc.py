"""XML-RPC with a timeout: a hung master or node must not stall the thread asking it.

`proxy` is the standard library's client (a new connection per call), for calls made now and
then. `Caller` is for calls polled several times a second (node liveness, the master watch):
one kept-alive HTTP/1.1 connection and a minimal HTTP exchange, since the standard client's
connect, header parsing (the `email` package) and the thread the server starts per connection
cost about a millisecond of CPU a call on both sides.
"""
from __future__ import annotations

import socket
import threading
import time
import xmlrpc.client
from typing import Any, Optional, Tuple
from urllib.parse import urlparse

_MAX_RESPONSE = 16 << 20  # bytes: far above any getPid, lookupNode or getSystemState answer


class _TimeoutTransport(xmlrpc.client.Transport):
    def __init__(self, timeout: float) -> None:
        super().__init__()
        self.timeout = timeout

    def make_connection(self, host: Any) -> Any:
        conn = super().make_connection(host)
        conn.timeout = self.timeout
        return conn


def proxy(uri: str, timeout: float) -> xmlrpc.client.ServerProxy:
    """A proxy whose every call gives up (socket.timeout) after `timeout` seconds."""
    return xmlrpc.client.ServerProxy(uri, transport=_TimeoutTransport(timeout))


class Caller:
    """XML-RPC calls to one URI; each call gives up after `timeout` seconds in all, counted from
    when the call gets the connection (socket.timeout). Errors are those of `proxy`: OSError for
    the connection, xmlrpc.client.Error (ProtocolError, ResponseError, Fault) for a bad answer.
    Thread-safe (one call at a time).

    keep_alive: one connection for every call (the master). Without it each call connects anew
    and asks the server to close (a node's liveness: a node that shut down closes its listening
    socket, but a connection it had accepted may still be served by its threads)."""

    def __init__(self, uri: str, timeout: float, keep_alive: bool = True) -> None:
        parsed = urlparse(uri)
        if parsed.scheme != "http" or not parsed.hostname:
            raise ValueError(f"not an http XML-RPC URI: {uri!r}")
        self.uri, self.timeout, self.keep_alive = uri, timeout, keep_alive
        self._addr = (parsed.hostname, parsed.port or 80)
        self._head = (f"POST {parsed.path or '/'} HTTP/1.1\r\nHost: {parsed.hostname}:{self._addr[1]}\r\n"
                      + ("" if keep_alive else "Connection: close\r\n")
                      + "Content-Type: text/xml\r\nContent-Length: ")
        self._sock: Optional[socket.socket] = None
        self._lock = threading.Lock()

    def call(self, method: str, *params: Any) -> Any:
        body = xmlrpc.client.dumps(params, method).encode()
        request = f"{self._head}{len(body)}\r\n\r\n".encode() + body
        with self._lock:
            deadline = time.monotonic() + self.timeout
            try:
                try:
                    kept = self._sock is not None
                    data = self._exchange(request, deadline)
                except _Stale:
                    if not kept:
                        raise
                    data = self._exchange(request, deadline)  # the server closed an idle connection: anew
            except _Stale:
                raise xmlrpc.client.ProtocolError(self.uri, 0, "closed the connection without answering",
                                                  {}) from None
            except BaseException:
                self.close()  # a half-read answer must not be read as the next one
                raise
            try:
                return xmlrpc.client.loads(data, use_builtin_types=True)[0][0]
            except xmlrpc.client.Fault:
                raise
            except Exception as exc:  # expat's error, an empty answer: a server not to trust further
                self.close()
                raise xmlrpc.client.ResponseError(f"{self.uri}: unreadable answer to {method}: {exc}") from None

    def close(self) -> None:
        sock, self._sock = self._sock, None
        if sock is not None:
            sock.close()

    def _exchange(self, request: bytes, deadline: float) -> bytes:
        if self._sock is None:
            self._sock = socket.create_connection(self._addr, timeout=_left(deadline))
            self._sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        sock = self._sock
        try:
            sock.settimeout(_left(deadline))
            try:
                sock.sendall(request)
            except (ConnectionResetError, BrokenPipeError, ConnectionAbortedError):
                raise _Stale() from None  # a kept connection the server had dropped
            status, close, length, buf = self._head_of_answer(sock, deadline)
            if length is None:  # no length: the body runs to the end of the connection
                close = True
                while True:
                    chunk = self._recv(sock, deadline)
                    if not chunk:
                        break
                    buf += chunk
            else:
                while len(buf) < length:
                    chunk = self._recv(sock, deadline)
                    if not chunk:
                        raise xmlrpc.client.ProtocolError(self.uri, 0, "the answer was cut short", {})
                    buf += chunk
                buf = buf[:length]
        except _Stale:
            self.close()
            raise
        if close or not self.keep_alive:
            self.close()
        if status != 200:
            raise xmlrpc.client.ProtocolError(self.uri, status, f"HTTP status {status}", {})
        return buf

    def _head_of_answer(self, sock: socket.socket, deadline: float) -> Tuple[int, bool, Optional[int], bytes]:
        """(status, whether the server closes, Content-Length or None, the body bytes read so far)."""
        buf = b""
        while b"\r\n\r\n" not in buf:
            try:
                chunk = self._recv(sock, deadline)
            except (ConnectionResetError, ConnectionAbortedError):
                if buf:
                    raise
                raise _Stale() from None  # reset before a word of answer: dropped while idle
            if not chunk:
                if not buf:
                    raise _Stale()
                raise xmlrpc.client.ProtocolError(self.uri, 0, "the answer was cut short", {})
            buf += chunk
            if len(buf) > 65536:
                raise xmlrpc.client.ProtocolError(self.uri, 0, "the answer's header is too long", {})
        head, _, rest = buf.partition(b"\r\n\r\n")
        lines = head.decode("latin-1").split("\r\n")
        parts = lines[0].split(None, 2)
        if len(parts) < 2 or not parts[0].startswith("HTTP/") or not parts[1].isdigit():
            raise xmlrpc.client.ProtocolError(self.uri, 0, f"not an HTTP answer: {lines[0][:60]!r}", {})
        close = parts[0] == "HTTP/1.0"
        length: Optional[int] = None
        for line in lines[1:]:
            name, _, value = line.partition(":")
            name = name.strip().lower()
            if name == "content-length":
                try:
                    length = int(value.strip())
                except ValueError:
                    raise xmlrpc.client.ProtocolError(self.uri, 0, f"bad Content-Length {value.strip()!r}",
                                                      {}) from None
                if not 0 <= length <= _MAX_RESPONSE:
                    raise xmlrpc.client.ProtocolError(self.uri, 0, f"Content-Length {length} out of range", {})
            elif name == "connection":
                close = value.strip().lower() == "close"
            elif name == "transfer-encoding" and value.strip().lower() != "identity":
                raise xmlrpc.client.ProtocolError(self.uri, 0, f"unsupported Transfer-Encoding {value.strip()}", {})
        return int(parts[1]), close, length, rest

    def _recv(self, sock: socket.socket, deadline: float) -> bytes:
        sock.settimeout(_left(deadline))
        return sock.recv(65536)


class _Stale(Exception):
    """A kept connection the server had closed before it answered."""


def _left(deadline: float) -> float:
    left = deadline - time.monotonic()
    if left <= 0:
        raise socket.timeout("timed out")
    return left
