"""A fast reader of indexed ROS 1 bag v2.0 files for replay, in the order rosbag's read_messages gives.

It reads the file header, the connection and chunk-info records at the end (never the per-message
index), then walks the chunks by start time, parsing each message record with one struct call and
deserialising only the topics asked for. Order: by time, then by the connection's place in the
index (as rosbag's heapq.merge breaks ties), then by place in the file. rosbag gives the same order
whenever each connection's messages were written in time order (always so for `rosbag record`).
Bags this reader does not handle (format 1.2, encryption, an unknown compression) raise
Unsupported, so that the caller can use rosbag instead.
"""
from __future__ import annotations

import os
import struct
import sys
from typing import Any, Dict, Iterable, Iterator, List, Optional, Set, Tuple

from .bagrecords import (FIELD_CONN, FIELD_OP, FIELD_TIME, MSG_FIELDS, MSG_HEADER_LEN, MSG_PREFIX, NS, OP_CHUNK,
                         OP_CHUNK_INFO, OP_CONNECTION, OP_FILE_HEADER, OP_MSG_DATA, U32, VERSION_LINE,
                         BagFormatError, Chunk, Connection, NoMessageSupport, Unindexed, Unsupported, decompressor,
                         fields_of,
                         int_field, message_class, message_layout, op_of, record_at, seconds, str_field, time_field)

__all__ = ["BagFile", "BagFormatError", "Chunk", "Connection", "NoMessageSupport", "Unindexed", "Unsupported",
           "message_class"]


class BagFile:
    """An indexed bag v2.0 open for reading; BagFormatError, Unindexed or Unsupported if it cannot be."""

    def __init__(self, path: str) -> None:
        self.filename = path
        self._file = open(path, "rb")
        try:
            self._open()
        except BaseException:
            self._file.close()
            raise

    # -- opening -------------------------------------------------------------------------
    def _open(self) -> None:
        f = self._file
        size = os.fstat(f.fileno()).st_size
        line = f.read(len(VERSION_LINE))
        if line != VERSION_LINE:
            if line.startswith(b"#ROSBAG V"):
                raise Unsupported(f"bag format {line[9:].strip().decode('latin-1')}")
            raise BagFormatError("no ROS bag version line at its start")
        head = f.read(8192)
        fields, _, _ = record_at(head, 0)
        if op_of(fields) != OP_FILE_HEADER:
            raise BagFormatError("no file header record after the version line")
        if "encryptor" in fields and fields["encryptor"]:
            raise Unsupported("an encrypted bag")
        index_pos = int_field(fields, "index_pos", "Q")
        conn_count = int_field(fields, "conn_count", "I")
        chunk_count = int_field(fields, "chunk_count", "I")
        if index_pos == 0:
            raise Unindexed("the bag is not indexed")
        if index_pos > size:
            raise Unindexed(f"its index is at byte {index_pos}, past its end ({size} bytes): it is truncated")
        f.seek(index_pos)
        connections, chunks = self._index(f.read(), conn_count, chunk_count)
        for chunk in chunks:
            self._chunk_header(chunk, size)
        totals: Dict[int, int] = {}
        for chunk in chunks:
            for conn_id, n in chunk.counts.items():
                if conn_id not in connections:
                    raise BagFormatError(f"a chunk holds messages of connection {conn_id}, which has no record")
                totals[conn_id] = totals.get(conn_id, 0) + n
        # as rosbag: connections without messages are left out
        self._connections = {c: conn for c, conn in connections.items() if totals.get(c)}
        self.connections = self._connections
        self.chunks = chunks
        self._counts = totals

    @staticmethod
    def _index(buf: bytes, conn_count: int, chunk_count: int) -> Tuple[Dict[int, Connection], List[Chunk]]:
        """The connection and chunk-info records that end the file."""
        pos = 0
        connections: Dict[int, Connection] = {}
        for _ in range(conn_count):
            fields, start, end = record_at(buf, pos)
            if op_of(fields) != OP_CONNECTION:
                raise BagFormatError("a connection record is missing from the index")
            conn_id = int_field(fields, "conn", "I")
            info = fields_of(buf, start, end)
            connections[conn_id] = Connection(conn_id, str_field(fields, "topic"), str_field(info, "type"),
                                              str_field(info, "md5sum"), str_field(info, "message_definition"), info)
            pos = end
        chunks: List[Chunk] = []
        for i in range(chunk_count):
            fields, start, end = record_at(buf, pos)
            if op_of(fields) != OP_CHUNK_INFO or int_field(fields, "ver", "I") != 1:
                raise BagFormatError("a chunk info record is missing from the index")
            counts = {}
            for j in range(int_field(fields, "count", "I")):
                if start + 8 * j + 8 > end:
                    raise BagFormatError("a chunk info record is cut short")
                conn_id, n = struct.unpack_from("<II", buf, start + 8 * j)  # connection, messages
                counts[conn_id] = n
            chunks.append(Chunk(i, int_field(fields, "chunk_pos", "Q"), time_field(fields, "start_time"),
                                time_field(fields, "end_time"), counts))
            pos = end
        return connections, chunks

    def _chunk_header(self, chunk: Chunk, size: int) -> None:
        if chunk.pos >= size:
            raise BagFormatError(f"a chunk at byte {chunk.pos} lies past the end of the file")
        self._file.seek(chunk.pos)
        head = self._file.read(4)
        if len(head) < 4:
            raise BagFormatError(f"the chunk at byte {chunk.pos} is cut short")
        length = U32.unpack(head)[0]
        if chunk.pos + 4 + length + 4 > size:  # before reading: a corrupt length must not allocate gigabytes
            raise BagFormatError(f"the chunk at byte {chunk.pos} has a header longer than the file")
        head += self._file.read(length + 4)
        fields, data_pos = self._header_only(head, chunk)
        if op_of(fields) != OP_CHUNK:
            raise BagFormatError(f"no chunk at byte {chunk.pos}, where the index says one is")
        chunk.compression = fields.get("compression", b"none").decode("latin-1")
        chunk.data_pos = chunk.pos + data_pos
        chunk.data_len = U32.unpack_from(head, data_pos - 4)[0]
        if chunk.data_pos + chunk.data_len > size:
            raise BagFormatError(f"the chunk at byte {chunk.pos} runs past the end of the file (truncated?)")
        decompressor(chunk.compression)

    @staticmethod
    def _header_only(head: bytes, chunk: Chunk) -> Tuple[Dict[str, bytes], int]:
        """A chunk record's header fields and where its data starts (relative to the record)."""
        hend = 4 + U32.unpack_from(head, 0)[0]
        if hend + 4 > len(head):
            raise BagFormatError(f"the chunk at byte {chunk.pos} is cut short")
        return fields_of(head, 4, hend), hend + 4

    # -- what it holds -------------------------------------------------------------------
    @property
    def message_count(self) -> int:
        return sum(self._counts.values())

    @property
    def start_time(self) -> float:
        """As rosbag's get_start_time: the first chunk's start (0.0 for an empty bag)."""
        return seconds(self.chunks[0].start) if self.chunks and self._counts else 0.0

    @property
    def end_time(self) -> float:
        """As rosbag's get_end_time: the last chunk's end (0.0 for an empty bag)."""
        return seconds(self.chunks[-1].end) if self.chunks and self._counts else 0.0

    def topics(self) -> Dict[str, Tuple[str, int]]:
        """topic -> (type of its first connection, messages), as rosbag's get_type_and_topic_info."""
        out: Dict[str, Tuple[str, int]] = {}
        for conn in self._connections.values():
            datatype, n = out.get(conn.topic, (conn.datatype, 0))
            out[conn.topic] = (datatype, n + self._counts[conn.id])
        return out

    def topic_class(self, topic: str) -> Any:
        """The message class of a topic's first message (None if it has none)."""
        conns = [c for c in self._connections.values() if c.topic == topic]
        if len(conns) == 1:
            return self._class(conns[0])
        for _, _, msg in self.read([topic], {topic}):  # several connections: the first message's
            return type(msg)
        return None

    # -- reading -------------------------------------------------------------------------
    def read(self, topics: Iterable[str], decode: Set[str] = frozenset(),  # type: ignore[assignment]
             callers: Set[str] = frozenset()  # type: ignore[assignment]
             ) -> Iterator[Tuple[float, str, Optional[Any]]]:
        """(time in s, topic, message or None) in rosbag's order; only topics in decode are deserialised.
        Messages of topics in `callers` carry their publisher, as rospy's do: `_connection_header['callerid']`."""
        wanted = set(topics)
        ranks = {c: r for r, c in enumerate(self._connections)}
        nconn = max(len(ranks), 1)
        conns: Dict[int, Tuple[int, str, Any]] = {}
        for conn in self._connections.values():
            if conn.topic in wanted:
                cls = self._class(conn) if conn.topic in decode else None
                if cls is not None and conn.topic in callers:
                    cls = _with_caller(cls, conn)
                conns[conn.id] = (ranks[conn.id], conn.topic, cls)
        chunks = sorted((c for c in self.chunks if any(k in conns for k in c.counts)), key=lambda c: (c.start, c.index))
        held: List[Tuple[float, str, Any]] = []  # messages at or after the next chunk's start
        held_keys: List[int] = []
        for i, chunk in enumerate(chunks):
            buf, items, records, in_order = self._scan(chunk, conns)

            def key(j: int, buf: bytes = buf, records: List[int] = records) -> int:
                """The order key of the chunk's j-th message: (stamp in ns, connection's rank)."""
                fields, _, _ = record_at(buf, records[j])
                return time_field(fields, "time") * nconn + conns[int_field(fields, "conn", "I")][0]

            if not in_order or (held and items and held_keys[-1] > key(0)):
                # a stable sort keeps equal stamps of one connection in file order
                keys = held_keys + [key(j) for j in range(len(items))]
                items = held + items
                order = sorted(range(len(keys)), key=keys.__getitem__)
                items, keys = [items[j] for j in order], [keys[j] for j in order]
                key_of = keys.__getitem__
            elif held:
                items = held + items
                key_of = (lambda j, h=len(held), hk=held_keys, k=key: hk[j] if j < h else k(j - h))
            else:
                key_of = key
            cut, held_keys = len(items), []
            if i + 1 < len(chunks):  # hold back what the next chunk may have to come between
                limit = chunks[i + 1].start * nconn
                while cut:
                    k = key_of(cut - 1)
                    if k < limit:
                        break
                    cut -= 1
                    held_keys.append(k)
                held_keys.reverse()
            held = items[cut:]
            yield from (items if cut == len(items) else items[:cut])
        yield from held

    def _class(self, conn: Connection) -> Any:
        try:
            return message_class(conn)
        except ImportError as exc:  # the python3 first on PATH has no ROS (ros1-notes.md)
            raise NoMessageSupport(f"{conn.datatype} needs ROS 1's Python message support, which this "
                                   f"interpreter ({sys.executable}) cannot import ({exc}): run rubass with "
                                   f"/usr/bin/python3") from None
        except Exception as exc:  # genmsg errors on a broken recorded definition
            raise BagFormatError(f"topic {conn.topic}: no message class for {conn.datatype} "
                                 f"({exc.__class__.__name__}: {exc})") from None

    def _chunk_data(self, chunk: Chunk) -> bytes:
        self._file.seek(chunk.data_pos)
        data = self._file.read(chunk.data_len)
        if len(data) != chunk.data_len:
            raise BagFormatError(f"the chunk at byte {chunk.pos} is cut short")
        try:
            return decompressor(chunk.compression)(data)
        except (OSError, ValueError, EOFError, RuntimeError) as exc:  # bz2: OSError; roslz4: RuntimeError
            raise BagFormatError(f"the chunk at byte {chunk.pos} cannot be decompressed "
                                 f"({exc.__class__.__name__}: {exc})") from None

    def _scan(self, chunk: Chunk, conns: Dict[int, Tuple[int, str, Any]]
              ) -> Tuple[bytes, List[Tuple[float, str, Any]], List[int], bool]:
        """A chunk's data, its wanted messages in file order, where their records start, and whether
        they are in order (stamp, then connection's rank)."""
        buf = self._chunk_data(chunk)
        n = len(buf)
        items: List[Tuple[float, str, Any]] = []
        records: List[int] = []
        add, add_record = items.append, records.append
        layout, i_op, i_conn, i_time = message_layout(("op", "conn", "time"))
        unpack = layout.unpack_from
        in_order, last_secs, last_nsecs, last_rank, pos = True, -1, -1, -1, 0
        get = conns.get
        try:
            while pos < n:
                record = pos
                try:
                    r = unpack(buf, pos)
                except struct.error:
                    r = (0,)
                if (r[0] == MSG_HEADER_LEN and r[i_op] == FIELD_OP and r[i_conn] == FIELD_CONN
                        and r[i_time] == FIELD_TIME):
                    conn, secs, nsecs = r[i_conn + 1], r[i_time + 1], r[i_time + 2]
                    start = pos + MSG_PREFIX
                    pos = start + r[-1]
                else:  # a connection record, or a message laid out otherwise
                    fields, start, pos = record_at(buf, pos)
                    op = op_of(fields)
                    if op == OP_CONNECTION:
                        continue
                    if op != OP_MSG_DATA:
                        raise BagFormatError(f"a record with op {op} inside a chunk")
                    conn, stamp = int_field(fields, "conn", "I"), time_field(fields, "time")
                    secs, nsecs = divmod(stamp, NS)
                    if start - record == MSG_PREFIX and set(fields) == MSG_FIELDS:  # the next ones likely too
                        layout, i_op, i_conn, i_time = message_layout(tuple(fields))
                        unpack = layout.unpack_from
                if pos > n:
                    raise BagFormatError("a message runs past the end of its chunk")
                want = get(conn)
                if want is None:
                    continue
                rank, topic, cls = want
                if secs == last_secs:  # compared part by part: cheaper than one key in ns
                    if nsecs < last_nsecs or (nsecs == last_nsecs and rank < last_rank):
                        in_order = False
                elif secs < last_secs:
                    in_order = False
                last_secs, last_nsecs, last_rank = secs, nsecs, rank
                if cls is None:
                    add((secs + nsecs / 1e9, topic, None))
                else:
                    msg = cls()
                    msg.deserialize(buf[start:pos])
                    add((secs + nsecs / 1e9, topic, msg))
                add_record(record)
        except BagFormatError as exc:
            raise BagFormatError(f"the chunk at byte {chunk.pos}: {exc}") from None
        except Exception as exc:  # genpy.DeserializationError, struct.error from a damaged message
            raise BagFormatError(f"a message in the chunk at byte {chunk.pos} cannot be read "
                                 f"({exc.__class__.__name__}: {exc})") from None
        return buf, items, records, in_order

    # -- lifecycle -----------------------------------------------------------------------
    def close(self) -> None:
        self._file.close()

    def __enter__(self) -> "BagFile":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def _with_caller(cls: Any, conn: Connection) -> Any:
    """A class of `cls` whose messages say who published them (the connection's callerid), at no cost
    per message: the connection header is a class attribute of one subclass per connection."""
    caller = conn.header.get("callerid", b"").decode("utf-8", "replace")
    if not caller:  # written by a tool, not recorded from a publisher: who published is not known
        return cls
    sub = type(cls.__name__, (cls,), {"__slots__": (), "_connection_header": {"callerid": caller}})
    sub.__slots__ = cls.__slots__  # genpy walks __slots__ for its fields (==, str, copy): the class's own
    return sub
