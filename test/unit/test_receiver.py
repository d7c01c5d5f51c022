"""The receiver (rubass/ros/receiver.py): one thread reads every watched topic's connections.

rospy's own transport and subscriber objects over a socket pair (no master): the far end plays
the publisher after the handshake. What must hold: every message delivered whole and in order
whatever the stream's cuts, the bytes that came with the handshake first, a connection ended or
closed as rospy ends it, and any other callback on a topic (or a failing receiver) handing the
connection back to a rospy thread that reads on from the same byte."""
import socket
import struct
import threading
import time

import pytest
from hypothesis import given, settings, strategies as st

rospy = pytest.importorskip("rospy")

from rospy.impl.tcpros_base import TCPROSTransport  # noqa: E402
from rospy.impl.tcpros_pubsub import TCPROSSub  # noqa: E402
from rospy.topics import _SubscriberImpl  # noqa: E402

from rubass.ros import receiver as rx  # noqa: E402

pytestmark = pytest.mark.ros

HEADER = {"type": "std_msgs/String", "md5sum": "992ce8a1687cec8c8bd883ec73ca41d1", "callerid": "/pub"}


def frame(payload: bytes) -> bytes:
    return struct.pack("<I", len(payload)) + payload


class Topic:
    """A subscriber of one topic as the monitor makes it: rospy's impl with the monitor's callback."""

    def __init__(self, receiver, name="/t"):
        self.name, self.receiver = name, receiver
        self.impl = _SubscriberImpl(name, rospy.AnyMsg)
        self.state = object()
        self.got, self.via_rospy = [], []
        self.seen = threading.Condition()
        self.impl.add_callback(self.callback, self.state)
        receiver.route(name, self.callback, self.on_frame, self.state)

    def callback(self, raw, state):  # what rospy's own delivery calls (an AnyMsg)
        assert state is self.state
        self.via_rospy.append(raw._buff)
        self.on_frame(raw._buff, raw._connection_header, state)

    def on_frame(self, buff, header, state):
        assert state is self.state and header["callerid"] == "/pub"
        with self.seen:
            self.got.append(bytes(buff))
            self.seen.notify_all()

    def slowed(self, seconds):
        """Each message of this topic evaluated `seconds` long from now on (a slow evaluation)."""
        real = self.on_frame

        def slow(buff, header, state):
            time.sleep(seconds)
            real(buff, header, state)

        self.receiver.route(self.name, self.callback, slow, self.state)

    def wait(self, n, timeout=5.0):
        with self.seen:
            assert self.seen.wait_for(lambda: len(self.got) >= n, timeout), self.got
        return self.got

    def connect(self, rest=b"", latched=False):
        """A connection whose handshake is done, handed to the receiver; the publisher's end."""
        ours, theirs = socket.socketpair()
        conn = TCPROSTransport(TCPROSSub(self.name, rospy.AnyMsg), self.name)
        conn.set_socket(ours, "http://pub:1/")
        conn.header, conn.is_latched = dict(HEADER, latching="1" if latched else "0"), latched
        conn.read_buff.write(rest)
        self.impl.add_connection(conn)
        assert self.receiver.hand_over(conn, self.impl, self.name)
        return conn, theirs


@pytest.fixture
def receiver():
    logs = []
    r = rx.Receiver(lambda level, text: logs.append((level, text)))
    r.logs = logs
    yield r
    r.close()


def until(cond, timeout=3.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(0.01)
    return False


@settings(max_examples=60, deadline=None)
@given(st.lists(st.binary(max_size=300), min_size=1, max_size=12), st.lists(st.integers(1, 400), min_size=1))
def test_messages_come_whole_and_in_order_whatever_the_cuts_of_the_stream(payloads, cuts):
    r = rx.Receiver(lambda level, text: None)
    try:
        t = Topic(r)
        ours, theirs = socket.socketpair()
        conn = TCPROSTransport(TCPROSSub("/t", rospy.AnyMsg), "/t")
        conn.set_socket(ours, "http://pub:1/")
        conn.header, conn.is_latched = dict(HEADER), False
        link = rx._Link(conn, t.impl, "/t", b"")
        stream = b"".join(frame(p) for p in payloads)
        i = k = 0
        while i < len(stream):  # the cutting itself, chunk by chunk as recv could return them
            n = cuts[k % len(cuts)]
            r._cut(link, stream[i:i + n])
            i, k = i + n, k + 1
        assert t.got == payloads and not link.rest
        assert conn.stat_num_msg == len(payloads)
        ours.close()
        theirs.close()
    finally:
        r.close()


def test_the_bytes_that_came_with_the_handshake_are_delivered_first(receiver):
    """A latched message often arrives in the same read as the publisher's handshake header, and
    may be the only one for a long time: it is delivered without waiting for more."""
    t = Topic(receiver)
    _, pub = t.connect(rest=frame(b"latched"))
    assert t.wait(1) == [b"latched"]
    u = Topic(receiver, "/u")
    _, pub2 = u.connect(rest=frame(b"latched") + frame(b"second")[:5])
    pub2.sendall(frame(b"second")[5:] + frame(b"third"))
    assert u.wait(3) == [b"latched", b"second", b"third"]


def test_a_large_message_over_many_reads_and_many_connections_in_one_thread(receiver):
    t, u = Topic(receiver, "/big"), Topic(receiver, "/small")
    _, big = t.connect()
    _, small = u.connect()
    payload = bytes(range(256)) * (5 * 4096)  # 5 MiB: ~80 reads of 64 KiB
    sender = threading.Thread(target=big.sendall, args=(frame(payload) + frame(b"after"),))
    sender.start()
    for i in range(50):
        small.sendall(frame(b"s%d" % i))
    sender.join()
    assert t.wait(2, timeout=10) == [payload, b"after"]
    assert u.wait(50) == [b"s%d" % i for i in range(50)]
    assert receiver.describe() == "one thread, 2 connections"


def test_a_publisher_that_closes_its_end_ends_the_connection_as_rospy_does(receiver):
    t = Topic(receiver)
    conn, pub = t.connect()
    pub.sendall(frame(b"one"))
    t.wait(1)
    pub.close()
    assert until(lambda: conn.done), "rospy's connection was not closed"
    assert until(lambda: receiver.describe() == "one thread, 0 connections")


def test_a_connection_rospy_closes_is_dropped_and_its_fd_may_serve_the_next(receiver):
    t = Topic(receiver)
    conn, pub = t.connect()
    fd = conn.fileno()
    conn.close()  # an unsubscribe, or the master's publisherUpdate without this publisher
    # at once, before the sweep: the kernel gives the new socket the lowest free fd, the closed one's
    conn2, pub2 = t.connect()
    assert conn2.fileno() == fd  # the case this test is about
    pub.close()
    pub2.sendall(frame(b"fresh"))
    assert t.wait(1) == [b"fresh"]
    assert t.via_rospy == [] and receiver.given_back == 0  # read by the receiver, not handed back
    assert until(lambda: receiver.describe() == "one thread, 1 connection")
    conn2.close()
    assert until(lambda: receiver.describe() == "one thread, 0 connections")
    pub2.close()


def test_a_closed_connections_fd_reused_before_the_sweep_serves_the_new_connection():
    """Driven by hand (the thread stopped) to hold the race: rospy closed a connection, the
    kernel gave its fd to the next one, and the receiver had not yet seen the close."""
    r = rx.Receiver(lambda level, text: None)
    r.close()
    r._closed = False  # its thread has ended: this test plays it
    t = Topic(r)
    conn, pub = t.connect()
    r._add(r._new.pop())
    fd = conn.fileno()
    conn.close()
    conn2, pub2 = t.connect()
    assert conn2.fileno() == fd
    new = r._new.pop()
    r._add(new)
    assert r._links == {fd: new} and r._sel.get_key(fd).data is new
    pub2.sendall(frame(b"fresh"))
    r._read(new)
    assert t.got == [b"fresh"]
    for s in (pub, pub2):
        s.close()


def test_another_callback_on_the_topic_gives_the_connection_back_to_a_rospy_thread(receiver):
    """A `limit` action reading the same topic publishes from its callback: never on the receiver."""
    t = Topic(receiver)
    conn, pub = t.connect()
    pub.sendall(frame(b"one"))
    t.wait(1)
    other = []
    t.impl.add_callback(lambda raw: other.append((raw._buff, threading.current_thread().name)), None)
    pub.sendall(frame(b"two") + frame(b"thr")[:3])  # a message cut at the hand-back
    assert until(lambda: len(other) == 1)
    pub.sendall(frame(b"thr")[3:] + frame(b"four"))
    assert t.wait(4) == [b"one", b"two", b"thr", b"four"]
    assert until(lambda: len(other) == 3)
    assert [m for m, _ in other] == [b"two", b"thr", b"four"]
    assert {name for _, name in other} == {"/t"}  # rospy's delivery, on a thread of the topic's name
    assert t.via_rospy == [b"two", b"thr", b"four"]
    assert receiver.given_back == 1 and "1 given to rospy's threads" in receiver.describe()
    pub.close()
    assert until(lambda: conn.done)
    assert "given" not in receiver.describe()  # ended: no longer read by anyone


def test_a_latched_connection_keeps_its_latest_message_for_a_later_callback(receiver):
    t = Topic(receiver)
    conn, pub = t.connect(latched=True)
    pub.sendall(frame(b"a") + frame(b"b"))
    t.wait(2)
    assert until(lambda: conn.latch is not None and conn.latch._buff == b"b")


def test_a_callback_that_raises_is_logged_and_the_next_message_delivered(receiver):
    t = Topic(receiver)
    real = t.on_frame

    def flaky(buff, header, state):
        if buff == b"bad":
            raise ValueError("boom")
        real(buff, header, state)

    receiver.route("/t", t.callback, flaky, t.state)
    _, pub = t.connect()
    pub.sendall(frame(b"bad") + frame(b"good"))
    assert t.wait(1) == [b"good"]
    assert any("ValueError: boom" in text for _, text in receiver.logs)


def test_if_waiting_on_the_sockets_fails_every_connection_goes_back_to_rospy(receiver, monkeypatch):
    t = Topic(receiver)
    conn, pub = t.connect()
    pub.sendall(frame(b"before"))
    t.wait(1)

    def broken(timeout=None):
        raise OSError(9, "Bad file descriptor")

    monkeypatch.setattr(receiver._sel, "select", broken)
    receiver._wake()
    assert until(lambda: receiver.failed)
    pub.sendall(frame(b"after"))
    assert t.wait(2) == [b"before", b"after"]
    assert t.via_rospy == [b"after"]
    assert not receiver.takes("/t")
    assert receiver.describe().startswith("rospy's threads (the receiver failed: waiting on the sockets: OSError")
    assert any(level == "error" and "every watched topic is read by rospy's threads" in text
               for level, text in receiver.logs)
    pub.close()
    assert until(lambda: conn.done)


def test_install_leaves_rospys_threads_in_place_for_a_rospy_it_was_not_written_for(monkeypatch):
    import rospy.impl.tcpros_pubsub as pubsub

    logs = []
    monkeypatch.setattr(rx, "_RECEIVER", None)
    monkeypatch.setattr(rx, "_ROSPY_CONNECT", lambda conn, uri, cb: None)
    monkeypatch.setattr(pubsub, "robust_connect_subscriber", rx._ROSPY_CONNECT)
    assert rx.install(lambda level, text: logs.append((level, text))) is None
    assert pubsub.robust_connect_subscriber is rx._ROSPY_CONNECT
    assert logs and logs[0][0] == "warn" and "read by a rospy thread of its own" in logs[0][1]


def test_install_replaces_rospys_connecting_function_once(monkeypatch):
    import rospy.impl.tcpros_pubsub as pubsub

    monkeypatch.setattr(rx, "_RECEIVER", None)
    monkeypatch.setattr(pubsub, "robust_connect_subscriber", rx._ROSPY_CONNECT)
    first = rx.install(lambda level, text: None)
    try:
        assert first is not None and pubsub.robust_connect_subscriber is rx._connect
        assert rx.install(lambda level, text: None) is first
    finally:
        first.close()


def test_a_latched_message_that_comes_before_the_monitors_callback_reaches_it_through_the_latch(receiver):
    """rospy registers, connects, then adds the callback: a fast latched publisher can be first."""
    t = Topic.__new__(Topic)  # the subscriber without its callback yet
    t.name, t.receiver, t.state = "/t", receiver, object()
    t.impl = _SubscriberImpl("/t", rospy.AnyMsg)
    t.got, t.via_rospy, t.seen = [], [], threading.Condition()
    receiver.route("/t", t.callback, t.on_frame, t.state)
    conn, pub = t.connect(rest=frame(b"latched"), latched=True)
    assert until(lambda: conn.latch is not None and conn.latch._buff == b"latched")
    t.impl.add_callback(t.callback, t.state)  # rospy's add_callback replays the latch
    pub.sendall(frame(b"next"))
    assert t.wait(2) == [b"latched", b"next"]
    assert receiver.given_back == 0 and t.via_rospy == [b"latched"]  # the next one read by the receiver


def test_the_latch_is_set_before_the_callback_runs(receiver):
    """A callback added while the monitor evaluates a latched message must get it (rospy's order)."""
    t = Topic(receiver)
    seen_latch = []
    real = t.on_frame

    def on_frame(buff, header, state):
        seen_latch.append(conn.latch._buff if conn.latch is not None else None)
        real(buff, header, state)

    receiver.route("/t", t.callback, on_frame, t.state)
    conn, pub = t.connect(latched=True)
    pub.sendall(frame(b"a"))
    t.wait(1)
    pub.sendall(frame(b"b"))
    t.wait(2)
    assert seen_latch == [b"a", b"b"]


def test_a_closed_subscriber_is_no_error_and_no_hand_back(receiver):
    t = Topic(receiver)
    conn, pub = t.connect()
    t.impl.callbacks = None  # rospy's _SubscriberImpl.close()
    pub.sendall(frame(b"x"))
    time.sleep(0.3)
    assert t.got == [] and receiver.given_back == 0 and receiver.logs == []


def test_a_length_prefix_beyond_a_gibibyte_closes_that_connection_only(receiver):
    t, u = Topic(receiver), Topic(receiver, "/u")
    conn, pub = t.connect()
    _, other = u.connect()
    pub.sendall(struct.pack("<I", (1 << 30) + 1) + b"garbage")
    assert until(lambda: conn.done)
    assert any("a message of 1073741825 bytes announced by /pub (over 1024 MiB: a broken stream): its connection "
               "is closed" in text for _, text in receiver.logs), receiver.logs
    other.sendall(frame(b"fine"))
    assert u.wait(1) == [b"fine"]


def test_if_the_thread_dies_every_connection_goes_back_to_rospy_and_new_ones_are_rospys(receiver, monkeypatch):
    t = Topic(receiver)
    conn, pub = t.connect()
    pub.sendall(frame(b"before"))
    t.wait(1)

    def dies(link):
        raise SystemExit("a bug beyond Exception")

    monkeypatch.setattr(receiver, "_read", dies)
    pub.sendall(frame(b"after"))
    assert until(lambda: receiver.failed)
    assert t.wait(2) == [b"before", b"after"] and t.via_rospy == [b"after"]
    assert not receiver.takes("/t")
    assert receiver.describe() == "rospy's threads (the receiver failed: SystemExit: a bug beyond Exception)"


def tcp_pair():
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(1)
    client = socket.create_connection(srv.getsockname())
    server, _ = srv.accept()
    srv.close()
    return client, server


def tcp_link(receiver, t):
    """A TCP connection (the kernel stamps TCP packets, not a socket pair's) to topic `t`, not handed over yet."""
    ours, pub = tcp_pair()
    # stamped from the start: the kernel stamps a packet only while some socket asks for stamps, and
    # turns stamping on a moment after the first asks (deferred work), so a packet sent at once after
    # it may go unstamped (read as "now": a CI run met it)
    ours.setsockopt(socket.SOL_SOCKET, rx._SO_TIMESTAMPNS, 1)
    time.sleep(0.2)
    conn = TCPROSTransport(TCPROSSub(t.name, rospy.AnyMsg), t.name)
    conn.set_socket(ours, "http://pub:1/")
    conn.header, conn.is_latched = dict(HEADER), False
    t.impl.add_connection(conn)
    return conn, pub


def test_how_long_data_waited_in_the_socket_is_measured_from_the_kernels_stamp(receiver):
    """Data that waited 0.6 s before the receiver could read it (here: handed over late), evaluated
    at once: the kernel's arrival stamp of the oldest data says 0.6 s, the receiver's turn nothing."""
    t = Topic(receiver)
    conn, pub = tcp_link(receiver, t)
    for i in range(5):
        pub.sendall(frame(b"m%d" % i))
    time.sleep(0.6)
    assert receiver.take_behind() < 0.05
    assert receiver.hand_over(conn, t.impl, "/t")
    t.wait(5)
    behind = receiver.take_behind()
    assert 0.55 < behind < 1.0, behind
    assert receiver.take_behind() < 0.05  # taken
    assert 0.55 < receiver.take_behind(1) < 1.0  # the status asks on its own
    pub.close()


def test_a_step_of_the_wall_clock_is_not_lateness(receiver, monkeypatch):
    """NTP steps the clock 5 s forward while data waits (the receiver busy 0.3 s with another topic):
    its kernel stamp is 5 s old on the new clock; what is lateness is the 0.3 s turn."""
    u = Topic(receiver, "/u")
    u.slowed(0.3)
    _, upub = u.connect()
    t = Topic(receiver)
    conn, pub = tcp_link(receiver, t)
    assert receiver.hand_over(conn, t.impl, "/t")
    assert until(lambda: receiver.describe() == "one thread, 2 connections")
    upub.sendall(frame(b"slow"))
    time.sleep(0.05)  # the receiver is in /u's evaluation
    pub.sendall(frame(b"m"))
    real = time.time
    monkeypatch.setattr(rx.time, "time", lambda: real() + 5.0)
    t.wait(1)
    assert 0.2 < receiver.take_behind() < 1.0
    pub.close()
    upub.close()


def test_a_long_turn_of_the_thread_is_lateness_while_it_lasts(receiver):
    """A turn of 1.2 s (evaluation that slow, a starved CPU): the tick asking meanwhile sees it grow."""
    t = Topic(receiver)
    t.slowed(0.4)
    _, pub = t.connect()
    pub.sendall(frame(b"a") + frame(b"b") + frame(b"c"))
    time.sleep(0.9)
    during = receiver.take_behind()
    t.wait(3)
    assert 0.7 < during < 1.2, during
    assert receiver.take_behind() >= 1.1  # the whole turn, once it ended
    pub.close()


def test_closing_the_receiver_gives_its_connections_back_to_rospy():
    r = rx.Receiver(lambda level, text: None)
    t = Topic(r)
    conn, pub = t.connect()
    pub.sendall(frame(b"before"))
    t.wait(1)
    r.close()
    pub.sendall(frame(b"after"))
    assert t.wait(2) == [b"before", b"after"] and t.via_rospy == [b"after"]
    assert r.failed == "" and not r.takes("/t")
    pub.close()
    assert until(lambda: conn.done)
