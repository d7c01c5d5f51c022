"""One thread receives the messages of every topic the monitor watches (issue 17).

rospy gives each connection of a subscriber a thread of its own that blocks on its socket,
wraps each message in an object and calls the subscriber's callbacks under its bookkeeping.
The receiver keeps rospy for everything else (registration with the master, `publisherUpdate`,
the connection's handshake on rospy's short-lived connecting thread, its statistics for
`rosnode info`) and takes over each connection of a watched topic once its handshake is done:
one thread waits on all their sockets (epoll), cuts each stream into messages and hands each
message's bytes to the topic's callback. A connection ends as rospy ends it (the publisher
closed it or the socket failed: closed, and a publisher's new connection comes from the
master's `publisherUpdate`); one rospy closes (an unsubscribe, a publisher gone, shutdown) is
dropped within `WAIT`.

Isolation is kept: the receiver only ever runs the monitor's own callback. A connection whose
topic gets another subscriber in the process (a `limit` action's input, which publishes from
its callback), or rospy's statistics, or that meets an error the receiver did not expect, is
given back to a rospy thread of its own, which reads it from where the receiver stopped; if
waiting on the sockets itself fails, every connection is given back and rospy's threads read
them from then on. Nothing is dropped on the way. `install` checks that rospy's connecting
function is the one this was written against, and leaves rospy's threads in place if not."""
from __future__ import annotations

import inspect
import selectors
import socket
import struct
import threading
import time
from typing import Any, Callable, Dict, List, Optional, Tuple

import rospy
import rospy.impl.tcpros_pubsub as _pubsub

Log = Callable[[str, str], None]
OnFrame = Callable[[bytes, Dict[str, str], Any], None]  # (serialised message, connection header, state)

_SIZE = struct.Struct("<I")
_RECV = 1 << 16  # bytes per read (rospy's buff_size): a larger message is gathered over several reads
MAX_MESSAGE = 1 << 30  # bytes: a length prefix beyond it is a broken stream (TCPROS allows 4 GiB), not a message
# the kernel stamps each packet as it arrives, and a read gets the stamp of the last packet it took: a
# read of one byte, the stamp of the oldest data waiting. From it to the end of the evaluation of what
# was read is how late the monitor sees the robot (Linux's value on x86 and ARM; Python's socket
# module does not name it). Each connection is stamped that way every PROBE seconds (one more read)
_SO_TIMESTAMPNS = getattr(socket, "SO_TIMESTAMPNS", 35)
PROBE = 0.1  # s
_STEP = 0.01  # s: the wall clock moved this much against the monotonic one: stepped (NTP), its stamps not used
_STAMP = struct.Struct("qq")
_ANC = socket.CMSG_SPACE(_STAMP.size)
_ROSPY_CONNECT = _pubsub.robust_connect_subscriber
_EXPECTED = ["conn", "dest_addr", "dest_port", "pub_uri", "receive_cb", "resolved_topic_name"]


class _Failed(Exception):
    """The receiver cannot go on (its text says why): every connection goes back to rospy's threads."""


class _Link:
    """One publisher's connection to a watched topic, as the receiver reads it."""

    __slots__ = ("conn", "sock", "fd", "impl", "topic", "header", "latched", "rest", "need", "stamped", "stamp",
                 "probe_at", "offset")

    def __init__(self, conn: Any, impl: Any, topic: str, rest: bytes) -> None:
        self.conn, self.sock, self.impl, self.topic = conn, conn.socket, impl, topic
        self.fd: int = self.sock.fileno()
        self.header: Dict[str, str] = conn.header or {}
        self.latched = bool(conn.is_latched)
        self.rest = bytearray(rest)  # bytes of a message not complete yet
        self.need = 4  # how many bytes `rest` must hold before it is worth cutting again
        self.stamped = False  # the kernel stamps its packets (how long they waited is known)
        self.stamp = 0.0  # the arrival of the oldest data of this read (monotonic clock), 0 if not stamped
        self.probe_at = 0.0  # when to stamp a read again (monotonic clock)
        self.offset = time.time() - time.monotonic()  # the wall clock's, at the latest stamped read


class Receiver:
    """The receiving thread and the topics it serves: `route` a topic before subscribing to it."""

    WAIT = 0.25  # s: the longest a connection rospy closed stays registered
    FAILURES = 3  # waits on the sockets failing in a row: every connection goes back to rospy's threads

    def __init__(self, log: Log) -> None:
        self.log = log
        self._sel = selectors.DefaultSelector()
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self._sel.register(self._wake_r.fileno(), selectors.EVENT_READ, None)
        self._routes: Dict[str, Tuple[Callable[..., Any], OnFrame, Any]] = {}  # topic -> (rospy cb, on_frame, state)
        self._new: List[_Link] = []
        self._links: Dict[int, _Link] = {}  # by socket fd
        self._lock = threading.Lock()  # _routes and _new, for moments
        self._closed = False
        self.given_back = 0  # connections handed to rospy's threads, since start
        self._given: List[Any] = []  # those connections, while rospy's threads read them
        self.failed = ""  # why the receiver gave every connection back, if it did
        self._behind = [0.0, 0.0]  # the latest evaluation after its data arrived, since `take_behind(0)`, `(1)`
        self._busy_since = 0.0  # when the wait on the sockets last returned, while what it returned is handled
        self._thread = threading.Thread(target=self._run, name="rubass-receive", daemon=True)
        self._thread.start()

    # -- topics (the monitor's registrar thread) -----------------------------------------------
    def route(self, topic: str, callback: Callable[..., Any], on_frame: OnFrame, state: Any) -> None:
        """Messages of `topic` (resolved) go to on_frame(bytes, header, state) while `callback`
        with `state` (what the topic's rospy.Subscriber was given) is its only callback."""
        with self._lock:
            self._routes[topic] = (callback, on_frame, state)

    def unroute(self, topic: str, state: Any) -> None:
        """Stop routing `topic`, if it is still routed for `state` (not for a later subscription)."""
        with self._lock:
            if topic in self._routes and self._routes[topic][2] is state:
                del self._routes[topic]

    def takes(self, topic: str) -> bool:
        """Whether a new connection of `topic` is the receiver's to read (each batch of its messages
        is checked again: another callback on the topic gives the connection back to rospy)."""
        return not self._closed and topic in self._routes and self._thread.is_alive()

    def take_behind(self, who: int = 0) -> float:
        """How late the monitor saw its messages (s: from their bytes' arrival in the kernel to the end
        of their evaluation), the most since this was last asked by `who` (0: the engine's tick, for
        the overload fail-safe; 1: the status)."""
        behind, self._behind[who] = self._behind[who], 0.0
        busy = self._busy_since
        # still busy with what one wait returned: whatever came meanwhile waits at least that long
        return max(behind, time.monotonic() - busy) if busy else behind

    def _sole(self, topic: str, impl: Any) -> Optional[Tuple[OnFrame, Any]]:
        """(on_frame, state) when the monitor's callback is the only one `impl` runs, else None."""
        route = self._routes.get(topic)
        callbacks = impl.callbacks or ()
        if (route is None or len(callbacks) != 1 or callbacks[0][0] != route[0] or callbacks[0][1] is not route[2]
                or getattr(impl, "statistics_logger", None) is not None):
            return None
        return route[1], route[2]

    def describe(self) -> str:
        """For /diagnostics: who reads the watched topics' connections."""
        if self.failed:
            return f"rospy's threads (the receiver failed: {self.failed})"
        with self._lock:
            self._given = [c for c in self._given if not c.done]
            n = len(self._given)
        given = f", {n} given to rospy's threads" if n else ""
        return f"one thread, {len(self._links)} connection{'s' if len(self._links) != 1 else ''}{given}"

    def close(self) -> None:
        """Stop the thread; the connections it read go back to rospy's threads."""
        with self._lock:
            self._closed = True
        self._wake()
        self._thread.join(2.0)

    # -- connections (rospy's connecting thread) -----------------------------------------------
    def hand_over(self, conn: Any, impl: Any, topic: str) -> bool:
        """Take a connection whose handshake is done; False if it cannot be (rospy's thread reads it)."""
        sock, buff = conn.socket, conn.read_buff
        if sock is None or buff is None:
            return False
        with self._lock:  # not between `_fail`'s closing and its giving back: no connection left unread
            if self._closed:
                return False
            rest = buff.getvalue()[:buff.tell()]  # what came after the handshake header (a latched message)
            sock.setblocking(False)
            self._new.append(_Link(conn, impl, topic, rest))
        self._wake()
        return True

    def _wake(self) -> None:
        try:
            self._wake_w.send(b"x")
        except OSError:
            pass  # a wake-up is already pending (or the receiver is closed)

    # -- the thread ------------------------------------------------------------------------------
    def _run(self) -> None:
        try:
            self._serve()
        except _Failed as exc:
            self._fail(str(exc))
            return
        except BaseException as exc:  # noqa: BLE001 - a bug, out of threads, out of memory: never a topic left unread
            self._fail(f"{exc.__class__.__name__}: {exc}")
            return
        self._fail("")  # closed: what it read goes back to rospy's threads

    def _serve(self) -> None:
        swept, failures = time.monotonic(), 0
        while not self._closed:
            try:
                events = self._sel.select(self.WAIT)
            except Exception as exc:  # noqa: BLE001 - epoll itself: retried, then rospy's threads take over
                failures += 1
                if failures >= self.FAILURES:
                    raise _Failed(f"waiting on the sockets: {exc.__class__.__name__}: {exc}") from None
                time.sleep(0.01)
                continue
            failures = 0
            self._busy_since = time.monotonic() if events else 0.0
            for key, _ in events:
                link = key.data
                try:
                    if link is None:
                        self._take_new()
                    elif self._links.get(link.fd) is link:
                        self._read(link)
                except Exception as exc:  # noqa: BLE001 - that connection goes back to rospy, the rest read on
                    if link is not None:
                        self._trouble(link, f"{exc.__class__.__name__}: {exc}")
                    else:
                        self.log("error", f"receiver: taking new connections: {exc.__class__.__name__}: {exc}")
            now = time.monotonic()
            if self._busy_since:
                self._late(now - self._busy_since)  # a long turn: what came during it waited that long
                self._busy_since = 0.0
            if now - swept >= self.WAIT:
                swept = now
                self._sweep()

    def _trouble(self, link: _Link, why: str) -> None:
        """Something unexpected on one connection: logged, and a rospy thread reads it from now on."""
        self.log("error", f"receiver: topic {link.topic}: {why}; its connection is read by a rospy thread from now on")
        self._give_back(link, [])

    def _fail(self, why: str) -> None:
        """Every connection back to rospy's threads, for good (`why`: logged; empty when closed)."""
        with self._lock:
            self._closed = True  # `takes` says no: new connections are rospy's
            new, self._new = self._new, []
        if why:
            self.failed = why
            self.log("error", f"receiver: {why}: every watched topic is read by rospy's threads from now on")
        for link in list(self._links.values()) + new:
            try:
                self._give_back(link, [])
            except Exception as exc:  # noqa: BLE001 - the others are still given back
                self.log("error", f"receiver: topic {link.topic}: cannot give its connection back: {exc}")

    def _take_new(self) -> None:
        try:
            while self._wake_r.recv(4096):
                pass
        except OSError:
            pass  # drained
        with self._lock:
            new, self._new = self._new, []
        for i, link in enumerate(new):
            try:
                self._add(link)
            except Exception as exc:  # noqa: BLE001 - never a connection left unread: rospy reads it
                try:
                    self._trouble(link, f"{exc.__class__.__name__}: {exc}")
                except BaseException:
                    with self._lock:  # the ones after it are still taken (by `_fail` if this thread ends)
                        self._new[:0] = new[i + 1:]
                    self._wake()
                    raise

    def _add(self, link: _Link) -> None:
        old = self._links.get(link.fd)
        if old is not None:  # rospy closed that one and the fd now serves this connection
            self._forget(old)
        if link.conn.done:
            return
        try:
            link.sock.setsockopt(socket.SOL_SOCKET, _SO_TIMESTAMPNS, 1)
            link.stamped = link.sock.family in (socket.AF_INET, socket.AF_INET6)
        except OSError:
            link.stamped = False  # how long its data waited is not known: no lateness measured on it
        self._sel.register(link.fd, selectors.EVENT_READ, link)
        self._links[link.fd] = link
        if len(link.rest) >= 4:  # a message came with the handshake: no read may follow soon
            self._cut(link, b"")

    def _sweep(self) -> None:
        for link in [x for x in self._links.values() if x.conn.done or x.conn.socket is not x.sock]:
            self._forget(link)

    def _forget(self, link: _Link) -> None:
        if self._links.get(link.fd) is link:
            del self._links[link.fd]
        key = self._sel.get_map().get(link.fd)
        if key is not None and key.data is link:
            try:
                self._sel.unregister(link.fd)
            except (KeyError, ValueError, OSError):
                pass  # closed by rospy: epoll dropped it already

    def _read(self, link: _Link) -> None:
        link.stamp = 0.0
        try:
            if link.stamped and time.monotonic() >= link.probe_at:
                data = self._stamped_read(link)
            else:
                data = link.sock.recv(_RECV)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            data = b""
        if not data:  # the publisher closed it, or the socket failed: ended as rospy ends it
            self._forget(link)
            if not link.conn.done:
                link.conn.close()
            return
        link.conn.stat_bytes += len(data)
        self._cut(link, data)

    @staticmethod
    def _stamped_read(link: _Link) -> bytes:
        """One byte with the stamp of the oldest data waiting (`link.stamp`), then the rest."""
        head, stamps, _, _ = link.sock.recvmsg(1, _ANC)
        now, wall = time.monotonic(), time.time()
        link.probe_at = now + PROBE
        offset, link.offset = link.offset, wall - now
        for _, kind, raw in stamps:
            if kind == _SO_TIMESTAMPNS and len(raw) >= _STAMP.size and abs(wall - now - offset) < _STEP:
                sec, nsec = _STAMP.unpack_from(raw)
                # how long it waited, on the kernel's wall clock (not across a step of it: the
                # wall clock kept its pace against the monotonic one since the last stamped read),
                # then counted on the monotonic one
                link.stamp = now - max(0.0, wall - sec - nsec * 1e-9)
        if not head:
            return head  # the publisher closed it
        try:
            return head + link.sock.recv(_RECV)
        except OSError:
            return head  # that byte was all there was (an error comes back at the next read)

    def _cut(self, link: _Link, data: bytes) -> None:
        """Cut the stream into messages and deliver them."""
        rest = link.rest
        if rest:
            rest += data
            if len(rest) < link.need:
                return  # a large message still arriving
            data = bytes(rest)
            rest.clear()
        frames: List[bytes] = []
        off, n = 0, len(data)
        while n - off >= 4:
            end = off + 4 + _SIZE.unpack_from(data, off)[0]
            if end > n:
                break
            frames.append(data[off + 4:end])
            off = end
        if off < n:
            link.need = 4 + _SIZE.unpack_from(data, off)[0] if n - off >= 4 else 4
            if link.need > MAX_MESSAGE:  # garbage, not a message: gathering it would exhaust the memory
                self.log("error", f"receiver: topic {link.topic}: a message of {link.need - 4} bytes announced by "
                                  f"{link.header.get('callerid', '?')} (over {MAX_MESSAGE >> 20} MiB: a broken stream): "
                                  f"its connection is closed")
                self._forget(link)
                link.conn.close()
                return
            rest += data[off:]
        if frames:
            link.conn.stat_num_msg += len(frames)
            self._deliver(link, frames)

    def _deliver(self, link: _Link, frames: List[bytes]) -> None:
        if link.latched:  # rospy's #1852, before any callback runs: a callback added later gets it
            link.conn.latch = _message(link, frames[-1])
        if not link.impl.callbacks:  # none yet (the subscriber is being made) or none any more: as rospy,
            return  # delivered to nobody (a latched message reaches a later callback through the latch)
        sole = self._sole(link.topic, link.impl)
        if sole is None:  # another callback on the topic now (or a reload dropped it): rospy's delivery
            self._give_back(link, frames)
            return
        on_frame, state = sole
        header = link.header
        for frame in frames:
            try:
                on_frame(frame, header, state)
            except Exception as exc:  # noqa: BLE001 - as rospy's `bad callback`: the next message is delivered
                self.log("error", f"topic {link.topic}: {exc.__class__.__name__}: {exc}")
            if link.stamp:  # the oldest data of a stamped read, evaluated this long after it arrived
                self._late(time.monotonic() - link.stamp)
                link.stamp = 0.0

    def _late(self, behind: float) -> None:
        if behind > self._behind[0]:
            self._behind[0] = behind
        if behind > self._behind[1]:
            self._behind[1] = behind

    def _give_back(self, link: _Link, frames: List[bytes]) -> None:
        """A rospy thread reads this connection from now on, these messages first."""
        self._forget(link)
        conn = link.conn
        buff = conn.read_buff
        if conn.done or buff is None or conn.socket is None:
            return
        msgs = [m for m in (_message(link, f) for f in frames) if m is not None]
        buff.seek(0)
        buff.truncate()
        buff.write(bytes(link.rest))  # rospy's receive_once reads what it holds first
        link.rest.clear()
        self.given_back += 1
        with self._lock:
            self._given.append(conn)
        threading.Thread(target=_rospy_reads, args=(conn, link.impl, msgs), name=link.topic, daemon=True).start()


def _message(link: _Link, frame: bytes) -> Any:
    """A frame as rospy delivers it: the subscriber's class, with its connection header (None if it cannot)."""
    msg = link.impl.data_class()
    try:
        msg.deserialize(frame)
    except Exception:  # noqa: BLE001 - rospy logs such a message and reads on
        return None
    msg._connection_header = link.header
    return msg


def _rospy_reads(conn: Any, impl: Any, msgs: List[Any]) -> None:
    if msgs:
        impl.receive_callback(msgs, conn)
    conn.receive_loop(impl.receive_callback)


_RECEIVER: Optional[Receiver] = None


def _connect(conn: Any, dest_addr: str, dest_port: int, pub_uri: str, receive_cb: Any, resolved_topic_name: str) -> None:
    """rospy's `robust_connect_subscriber`, handing a watched topic's connection to the receiver."""
    receiver = _RECEIVER
    impl = getattr(receive_cb, "__self__", None)
    if receiver is None or impl is None or not receiver.takes(resolved_topic_name):
        return _ROSPY_CONNECT(conn, dest_addr, dest_port, pub_uri, receive_cb, resolved_topic_name)
    interval = 0.5  # rospy's connecting loop, as it is
    while conn.socket is None and not conn.done and not rospy.is_shutdown():
        try:
            conn.connect(dest_addr, dest_port, pub_uri, timeout=60.)
        except rospy.exceptions.TransportInitError as e:
            if conn.protocol is None:
                conn.done = True
                break
            receiver.log("debug", f"topic {resolved_topic_name}: cannot connect to {pub_uri}: {e}; again in {interval} s")
            if interval < 30.0:
                interval = interval * 2
            time.sleep(interval)
            conn.done = not _pubsub.check_if_still_publisher(resolved_topic_name, pub_uri)
    if conn.done or rospy.is_shutdown():
        return None
    if not receiver.takes(resolved_topic_name) or not receiver.hand_over(conn, impl, resolved_topic_name):
        conn.receive_loop(receive_cb)  # rospy's own reading, on this thread
    return None


def install(log: Log) -> Optional[Receiver]:
    """Start the receiver and have rospy hand it the watched topics' connections; None (rospy's
    threads read them, as before) where rospy's connecting function is not the expected one."""
    global _RECEIVER
    if _RECEIVER is not None:
        return _RECEIVER
    try:
        params = list(inspect.signature(_ROSPY_CONNECT).parameters)
    except (TypeError, ValueError):
        params = []
    if params != _EXPECTED or not hasattr(_pubsub, "check_if_still_publisher"):
        log("warn", "receiver: this rospy connects subscribers differently from the one rubass was written for: "
                    "each connection is read by a rospy thread of its own (more CPU per message, nothing lost)")
        return None
    _RECEIVER = Receiver(log)
    _pubsub.robust_connect_subscriber = _connect
    return _RECEIVER
