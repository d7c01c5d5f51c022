"""Our bag reader (rubass/ros/bagfile.py) yields what rosbag's read_messages yields, in the same order,
on bags rosbag writes, on bags laid out as other writers lay them out, and on the real recordings;
damaged files give BagError naming the file."""
import os
import struct

import pytest

rosbag = pytest.importorskip("rosbag")
import rospy  # noqa: E402
from std_msgs.msg import Float64, String  # noqa: E402

from conftest import shared_path  # noqa: E402
from rubass.ros.bag import BagError, message_classes, open_bag, read  # noqa: E402
from rubass.ros.bagfile import BagFile  # noqa: E402

pytestmark = pytest.mark.ros
T0 = 1700000000


def write_bag(path, items, compression="none", chunk_threshold=768 * 1024):
    """items: (secs, nsecs, topic, message) in writing order."""
    with rosbag.Bag(path, "w", compression=compression, chunk_threshold=chunk_threshold) as bag:
        for secs, nsecs, topic, msg in items:
            bag.write(topic, msg, rospy.Time(secs, nsecs))
    return path


def rosbag_read(path, topics):
    with rosbag.Bag(path) as bag:
        return [(stamp.to_sec(), topic, msg) for topic, msg, stamp in bag.read_messages(topics=topics)]


def assert_reads_as_rosbag(path, per_topic=True):
    """Info and every message (time, topic, deserialised message) as rosbag gives them, in its order."""
    bag, info = open_bag(path)
    assert isinstance(bag, BagFile)
    with rosbag.Bag(path) as rb:
        topics = rb.get_type_and_topic_info().topics
        assert info.types == {t: v.msg_type for t, v in topics.items()}
        assert info.messages == sum(v.message_count for v in topics.values())
        if info.messages:
            assert (info.start, info.end) == (rb.get_start_time(), rb.get_end_time())
    with bag:
        names = sorted(info.types)
        mine = list(read(bag, names, set(names)))
        assert mine == rosbag_read(path, names)
        # undecoded topics: the same times and topics, no message
        assert [(t, topic, None) for t, topic, _ in mine] == list(read(bag, names, set()))
        for topic in names if per_topic else ():  # one topic alone
            assert list(read(bag, [topic], {topic})) == rosbag_read(path, [topic])
    return mine


def float_items(n, topics=("/a", "/b", "/c"), per_stamp=None, step_ns=1000000):
    """n messages, per_stamp of them sharing each stamp, cycling over topics."""
    per_stamp = per_stamp or len(topics)
    return [(T0 + (i // per_stamp) * step_ns // 10 ** 9, (i // per_stamp) * step_ns % 10 ** 9,
             topics[i % len(topics)], Float64(i * 0.5)) for i in range(n)]


@pytest.mark.parametrize("compression", ["none", "bz2", "lz4"])
def test_compressions_and_many_chunks(tmp_path, compression):
    path = write_bag(str(tmp_path / "c.bag"), float_items(3000), compression, chunk_threshold=2000)
    with BagFile(path) as b:
        assert len(b.chunks) > 20 and {c.compression for c in b.chunks} == {compression}
    mine = assert_reads_as_rosbag(path)
    assert len(mine) == 3000 and mine[0][2].data == 0.0


def test_equal_stamps_follow_the_connections_order_not_the_writing_order(tmp_path):
    # the connections come as /a, /c, /b; at every stamp /c, /b, /a are written in that order,
    # and chunk boundaries fall between messages of one stamp
    items = [(T0, 0, "/a", Float64(-1.0))]
    for i in range(1, 400):
        for topic in ("/c", "/b", "/a"):
            items.append((T0 + i // 100, (i % 100) * 10 ** 7, topic, Float64(i)))
    path = write_bag(str(tmp_path / "e.bag"), items, chunk_threshold=500)
    mine = assert_reads_as_rosbag(path)
    assert [topic for _, topic, _ in mine[1:4]] == ["/a", "/c", "/b"]


def test_messages_written_out_of_time_order_within_a_chunk(tmp_path):
    items = [(T0, 9 * 10 ** 8 - i * 10 ** 7, "/a" if i % 2 else "/b", Float64(i)) for i in range(60)]
    mine = assert_reads_as_rosbag(write_bag(str(tmp_path / "o.bag"), items))
    assert [t for t, _, _ in mine] == sorted(t for t, _, _ in mine)


def test_strings_and_other_types_on_several_topics(tmp_path):
    items = []
    for i in range(500):
        items.append((T0 + i, 0, "/name", String("ü" * (i % 7))))
        items.append((T0 + i, 5, "/x", Float64(i)))
    assert_reads_as_rosbag(write_bag(str(tmp_path / "s.bag"), items, "bz2", chunk_threshold=3000))


def test_empty_bag(tmp_path):
    path = str(tmp_path / "empty.bag")
    rosbag.Bag(path, "w").close()
    bag, info = open_bag(path)
    with bag:
        assert (info.messages, info.types, info.start, info.end) == (0, {}, 0.0, 0.0)
        assert list(read(bag, ["/a"], {"/a"})) == []


# -- bags laid out as other writers lay them out --------------------------------------------------
def _record(fields, data=b""):
    header = b"".join(struct.pack("<I", len(name) + 1 + len(value)) + name.encode() + b"=" + value
                      for name, value in fields)
    return struct.pack("<I", len(header)) + header + struct.pack("<I", len(data)) + data


def craft_bag(path, conns, chunks, order=("conn", "op", "time")):
    """A bag written record by record. conns: (id, topic, class, callerid); chunks: lists of
    (conn id, secs, nsecs, message) in file order; order: the fields of message record headers."""
    def conn_record(cid, topic, cls, caller):
        info = [("topic", topic.encode()), ("type", cls._type.encode()), ("md5sum", cls._md5sum.encode()),
                ("message_definition", cls._full_text.encode()), ("callerid", caller.encode())]
        return _record([("op", b"\x07"), ("topic", topic.encode()), ("conn", struct.pack("<I", cid))],
                       _record(info)[4:-4])

    by_id = {c[0]: c for c in conns}
    body, infos, pos = b"", [], 4096 + 13
    for messages in chunks:
        data, index, seen = b"", {}, set()
        for cid, secs, nsecs, msg in messages:
            if cid not in seen:
                seen.add(cid)
                data += conn_record(*by_id[cid])
            index.setdefault(cid, []).append((secs, nsecs, len(data)))
            values = {"op": b"\x02", "conn": struct.pack("<I", cid), "time": struct.pack("<II", secs, nsecs)}
            buf = __import__("io").BytesIO()
            msg.serialize(buf)
            data += _record([(name, values[name]) for name in order], buf.getvalue())
        chunk = _record([("op", b"\x05"), ("compression", b"none"), ("size", struct.pack("<I", len(data)))], data)
        for cid, entries in index.items():  # as rosbag's C++ writer: sorted by time, stable
            entries.sort(key=lambda e: (e[0], e[1]))
            chunk += _record([("op", b"\x04"), ("ver", struct.pack("<I", 1)), ("conn", struct.pack("<I", cid)),
                              ("count", struct.pack("<I", len(entries)))],
                             b"".join(struct.pack("<III", *e) for e in entries))
        stamps = [(s, n) for _, s, n, _ in messages]
        infos.append((pos, min(stamps), max(stamps), {c: len(e) for c, e in index.items()}))
        body, pos = body + chunk, pos + len(chunk)
    tail = b"".join(conn_record(*c) for c in conns)
    for chunk_pos, start, end, counts in infos:
        tail += _record([("op", b"\x06"), ("ver", struct.pack("<I", 1)), ("chunk_pos", struct.pack("<Q", chunk_pos)),
                         ("start_time", struct.pack("<II", *start)), ("end_time", struct.pack("<II", *end)),
                         ("count", struct.pack("<I", len(counts)))],
                        b"".join(struct.pack("<II", c, n) for c, n in counts.items()))
    header = _record([("op", b"\x03"), ("index_pos", struct.pack("<Q", pos)),
                      ("conn_count", struct.pack("<I", len(conns))), ("chunk_count", struct.pack("<I", len(infos)))])
    header = header[:-4] + struct.pack("<I", 4096 - len(header)) + b" " * (4096 - len(header))
    with open(path, "wb") as fh:
        fh.write(b"#ROSBAG V2.0\n" + header + body + tail)
    return path


@pytest.mark.parametrize("order", [("conn", "op", "time"), ("time", "conn", "op"), ("op", "conn", "time")])
def test_other_header_layouts_and_several_connections_on_one_topic(tmp_path, order):
    conns = [(0, "/x", Float64, "/left"), (1, "/name", String, "/talker"), (2, "/x", Float64, "/right")]
    chunks = []
    for k in range(4):  # chunk boundaries inside a stamp; connection 2 writes before 0 at equal stamps
        chunk = []
        for i in range(50):
            stamp = (T0 + k, i * 10 ** 7) if i < 49 else (T0 + k + 1, 0)
            chunk += [(2, *stamp, Float64(-i)), (0, *stamp, Float64(i)), (1, *stamp, String(f"{k}.{i}"))]
        chunks.append(chunk)
    path = craft_bag(str(tmp_path / "l.bag"), conns, chunks, order)
    mine = assert_reads_as_rosbag(path)
    assert len(mine) == 600 and {topic for _, topic, _ in mine} == {"/x", "/name"}
    with BagFile(path) as b:
        first = {topic: type(msg) for _, topic, msg in reversed(mine)}
        assert message_classes(b, ["/x", "/name"]) == first


@pytest.mark.parametrize("chunks", [
    # a stamp split over two chunks, the second in order by itself but starting below the first's tail
    [[(0, T0, 1, 1.0), (1, T0, 2, 2.0)], [(0, T0, 2, 3.0), (1, T0, 3, 4.0)]],
    # a stamp split over two chunks, already in order across the boundary
    [[(0, T0, 1, 1.0), (0, T0, 2, 2.0)], [(1, T0, 2, 3.0), (0, T0, 3, 4.0)]],
    # overlapping chunks, one connection each, and a third after both
    [[(0, T0, t, t) for t in range(0, 80, 2)], [(1, T0, t, -t) for t in range(1, 80, 2)], [(0, T0 + 1, 0, 9.0)]],
    # a chunk written before an earlier one, not overlapping it
    [[(0, T0 + 5, t, t) for t in range(5)], [(1, T0, t, t) for t in range(5)]],
])
def test_chunk_boundaries_and_overlapping_chunks(tmp_path, chunks):
    conns = [(0, "/p", Float64, "/a"), (1, "/q", Float64, "/b")]
    chunks = [[(c, s, n, Float64(v)) for c, s, n, v in chunk] for chunk in chunks]
    mine = assert_reads_as_rosbag(craft_bag(str(tmp_path / "k.bag"), conns, chunks))
    assert len(mine) == sum(len(c) for c in chunks)


# -- the real recordings ------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["husky_outdoor_2015.bag", "turtlebot3_sim.bag"])
def test_real_recordings(name):
    mine = assert_reads_as_rosbag(shared_path("data", name), per_topic=False)
    assert len(mine) > 10000


# -- damaged files --------------------------------------------------------------------------------
def _fails(path):
    """The BagError that opening or reading the whole file gives (None if it reads)."""
    try:
        bag, info = open_bag(path)
        with bag:
            names = sorted(info.types)
            list(read(bag, names, set(names)))
    except BagError as exc:
        return str(exc)
    return None


def test_truncated_bags_give_bag_errors_naming_the_file(tmp_path):
    data = open(write_bag(str(tmp_path / "b.bag"), float_items(2000), "bz2", chunk_threshold=4000), "rb").read()
    for cut in (5, 13, 100, 4200, len(data) // 3, len(data) // 2, len(data) - 30, len(data) - 1):
        path = str(tmp_path / f"cut{cut}.bag")
        with open(path, "wb") as fh:
            fh.write(data[:cut])
        error = _fails(path)
        assert error is not None and error.startswith(path + ": ") and "\n" not in error, cut


def test_corrupt_chunks_give_bag_errors(tmp_path):
    for compression in ("none", "bz2"):
        path = write_bag(str(tmp_path / f"{compression}.bag"), float_items(600), compression, chunk_threshold=4000)
        with BagFile(path) as b:
            chunk = b.chunks[1]
        data = bytearray(open(path, "rb").read())
        data[chunk.data_pos + 100:chunk.data_pos + 140] = b"\xff" * 40  # record lengths / compressed stream
        with open(path, "wb") as fh:
            fh.write(data)
        error = _fails(path)
        assert error is not None and error.startswith(path + ": the bag is corrupt"), error


def test_a_chunk_header_length_beyond_the_file_is_refused_before_it_is_read(tmp_path):
    import struct

    path = write_bag(str(tmp_path / "h.bag"), float_items(50))
    with BagFile(path) as b:
        chunk = b.chunks[0]
    data = bytearray(open(path, "rb").read())
    data[chunk.pos:chunk.pos + 4] = struct.pack("<I", 0xFFFFFFF0)  # a header of almost 4 GB
    with open(path, "wb") as fh:
        fh.write(data)
    with pytest.raises(BagError, match="not a readable ROS 1 bag.*header longer than the file"):
        open_bag(path)


def test_unindexed_bag_says_reindex(tmp_path):
    path = write_bag(str(tmp_path / "u.bag"), float_items(10))
    data = bytearray(open(path, "rb").read())
    at = data.index(b"index_pos=") + len(b"index_pos=")
    data[at:at + 8] = bytes(8)
    with open(path, "wb") as fh:
        fh.write(data)
    with pytest.raises(BagError, match="not indexed.*rosbag reindex"):
        open_bag(path)


def test_not_a_bag(tmp_path):
    path = str(tmp_path / "x.bag")
    with open(path, "wb") as fh:
        fh.write(b"not a bag at all\n" * 10)
    with pytest.raises(BagError, match="not a readable ROS 1 bag"):
        open_bag(path)


def test_unknown_compression_falls_back_to_rosbag(tmp_path):
    path = write_bag(str(tmp_path / "z.bag"), float_items(30), "bz2")
    data = open(path, "rb").read().replace(b"compression=bz2", b"compression=zzz")
    with open(path, "wb") as fh:
        fh.write(data)
    bag, info = open_bag(path)
    with bag:
        assert not isinstance(bag, BagFile) and info.messages == 30
        with pytest.raises(BagError, match="compression"):
            list(read(bag, ["/a"], {"/a"}))
    assert os.path.exists(path)


def test_a_replay_is_the_same_with_either_reader():
    from conftest import ROOT
    from rubass.lang import load_spec
    from rubass.replay.run import replay
    from rubass.ros.bag import _read_rosbag

    spec = load_spec(os.path.join(ROOT, "test", "data", "turtlebot_gap.rbs"))
    path = shared_path("data", "turtlebot3_sim.bag")
    bag, info = open_bag(path)
    topics = [t for t in spec.topics if t in info.types]
    decode = {t for t in topics if spec.topics[t].needs_data}
    with bag, rosbag.Bag(path) as rb:
        ours = replay(spec, read(bag, topics, decode), info.start, info.end)[1]
        theirs = replay(spec, _read_rosbag(rb, topics, decode), info.start, info.end)[1]
    assert [(e.time, e.kind, e.behaviour, e.rule, e.value) for e in ours] == \
        [(e.time, e.kind, e.behaviour, e.rule, e.value) for e in theirs]
    assert sum(e.kind == "start" for e in ours) >= 2


@pytest.mark.parametrize("compression", ["none", "bz2"])
def test_random_damage_gives_a_bag_error_or_messages_never_another_exception(tmp_path, compression):
    import random

    items = [(T0 + i // 10, (i % 10) * 10 ** 8, "/name" if i % 3 else "/x", String(f"m{i}") if i % 3 else Float64(i))
             for i in range(300)]
    data = open(write_bag(str(tmp_path / "f.bag"), items, compression, chunk_threshold=1500), "rb").read()
    rnd = random.Random(4)
    path = str(tmp_path / "damaged.bag")
    outcomes = set()
    for _ in range(150):
        damaged = bytearray(data)
        for _ in range(rnd.choice([1, 3, 20])):
            at = rnd.randrange(len(damaged))
            damaged[at] = rnd.choice([0, 0xFF, rnd.randrange(256)])
        with open(path, "wb") as fh:
            fh.write(damaged)
        error = _fails(path)  # any exception but BagError fails the test
        assert error is None or (error.startswith(path + ": ") and "\n" not in error)
        outcomes.add(error is None)
    assert outcomes == {True, False}


def test_replay_of_a_bag_neither_reader_can_read_is_a_one_line_error(tmp_path, write):
    import subprocess
    import sys

    from conftest import ROOT

    path = write_bag(str(tmp_path / "z.bag"), float_items(30), "bz2")
    data = open(path, "rb").read().replace(b"compression=bz2", b"compression=zzz")
    with open(path, "wb") as fh:
        fh.write(data)
    lib = os.path.join(ROOT, "docs", "examples", "actions.yaml")
    spec = write("s.rbs", f'import "{lib}";\naction primitive stop;\n'
                          "entity e { rules: high: topic /a.data > 1; }\nif (e.high) then { stop; }\n")
    proc = subprocess.run([sys.executable, "-m", "rubass", "replay", spec, path], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    assert proc.stderr.startswith(f"rubass replay: error: {path}: ") and "compression" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_messages_of_a_callers_topic_say_who_published_them_and_stay_whole_messages(tmp_path):
    path = str(tmp_path / "c.bag")
    with rosbag.Bag(path, "w") as b:
        header = {"topic": "/rubass/agent_samples", "type": String._type, "md5sum": String._md5sum,
                  "message_definition": String._full_text, "callerid": "/rubass_agent_a"}
        for i in range(3):
            b.write("/rubass/agent_samples", String(data=f"r{i}"), rospy.Time(1, i), connection_header=header)
    with BagFile(path) as bag:
        got = [m for _, _, m in bag.read(["/rubass/agent_samples"], {"/rubass/agent_samples"},
                                        {"/rubass/agent_samples"})]
        plain = [m for _, _, m in bag.read(["/rubass/agent_samples"], {"/rubass/agent_samples"})]
    assert [m._connection_header["callerid"] for m in got] == ["/rubass_agent_a"] * 3
    import copy

    assert copy.deepcopy(got[0]).data == "r0" and got[0] != got[1]  # genpy walks __slots__ for its fields
    assert str(got[1]) == str(String(data="r1")) and type(got[0])(data="r0") == got[0]
    assert not hasattr(plain[0], "_connection_header") and plain[0].data == "r0"  # only where asked
