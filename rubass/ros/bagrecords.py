"""The records of ROS 1 bag v2.0 files: constants, header parsing, errors, connections and chunks.

Used by bagfile.py; pure Python and struct (message classes come from rosbag's cache or genpy).
"""
from __future__ import annotations

import bz2
import struct
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, Tuple

VERSION_LINE = b"#ROSBAG V2.0\n"
OP_MSG_DATA, OP_FILE_HEADER, OP_INDEX_DATA, OP_CHUNK, OP_CHUNK_INFO, OP_CONNECTION = 2, 3, 4, 5, 6, 7
NS = 1000000000

U32 = struct.Struct("<I")
TIME = struct.Struct("<II")
# A message data record whose header holds exactly the fields op, conn and time is parsed with one
# struct call; writers order the fields differently (rosbag's Python writer: op, conn, time), so a
# layout is made for each order met: (struct, index of the op field, of conn's name, of time's name).
FIELD_OP = b"\x04\x00\x00\x00op=\x02"
FIELD_CONN = b"\x09\x00\x00\x00conn="
FIELD_TIME = b"\x0d\x00\x00\x00time="
_PIECES = {"op": ("8s", 1), "conn": ("9sI", 2), "time": ("9sII", 3)}
Layout = Tuple[struct.Struct, int, int, int]
_layouts: Dict[Tuple[str, ...], Layout] = {}


def message_layout(order: Tuple[str, ...]) -> Layout:
    """The layout of message records whose header fields come in this order."""
    if order not in _layouts:
        fmt, at, index = "<I", {}, 1
        for name in order:
            fmt += _PIECES[name][0]
            at[name] = index
            index += _PIECES[name][1]
        _layouts[order] = (struct.Struct(fmt + "I"), at["op"], at["conn"], at["time"])
    return _layouts[order]


MSG_HEADER_LEN = 38
MSG_PREFIX = 46  # header length, header, data length
MSG_FIELDS = {"op", "conn", "time"}


class BagFormatError(Exception):
    """The file is not a readable bag: the message says what is wrong, in a few words."""


class Unindexed(BagFormatError):
    """The bag has no index (recording interrupted, or the file truncated)."""


class Unsupported(Exception):
    """A bag this reader does not handle (another format version, encryption, a compression)."""


class NoMessageSupport(Exception):
    """ROS 1's Python message support (genpy) cannot be imported: the bag is fine, the interpreter is not."""


@dataclass(frozen=True)
class Connection:
    """A connection record: the attributes rosbag's _ConnectionInfo has."""
    id: int
    topic: str
    datatype: str
    md5sum: str
    msg_def: str
    header: Dict[str, bytes] = field(repr=False, compare=False)


@dataclass
class Chunk:
    """A chunk-info record and its chunk's header: times in nanoseconds."""
    index: int  # place in the file
    pos: int
    start: int
    end: int
    counts: Dict[int, int]  # connection id -> messages
    compression: str = "none"
    data_pos: int = 0
    data_len: int = 0


def fields_of(buf: bytes, pos: int, end: int) -> Dict[str, bytes]:
    """A record header's name=value fields."""
    out: Dict[str, bytes] = {}
    while pos < end:
        if pos + 4 > end:
            raise BagFormatError("a record header is cut short")
        (size,) = U32.unpack_from(buf, pos)
        pos += 4
        if pos + size > end:
            raise BagFormatError("a record header field runs past its header")
        name, sep, value = buf[pos:pos + size].partition(b"=")
        if not sep:
            raise BagFormatError("a record header field has no '='")
        out[name.decode("latin-1")] = value
        pos += size
    return out


def record_at(buf: bytes, pos: int) -> Tuple[Dict[str, bytes], int, int]:
    """(header fields, data start, data end) of the record at pos in buf."""
    if pos + 4 > len(buf):
        raise BagFormatError("a record is cut short")
    (hlen,) = U32.unpack_from(buf, pos)
    hend = pos + 4 + hlen
    if hend + 4 > len(buf):
        raise BagFormatError("a record header runs past the end of the data")
    fields = fields_of(buf, pos + 4, hend)
    (dlen,) = U32.unpack_from(buf, hend)
    if hend + 4 + dlen > len(buf):
        raise BagFormatError("a record runs past the end of the data")
    return fields, hend + 4, hend + 4 + dlen


def int_field(fields: Dict[str, bytes], name: str, fmt: str) -> int:
    try:
        return struct.unpack("<" + fmt, fields[name])[0]
    except KeyError:
        raise BagFormatError(f"a record has no field '{name}'") from None
    except struct.error:
        raise BagFormatError(f"a record's field '{name}' has the wrong size") from None


def op_of(fields: Dict[str, bytes]) -> int:
    return int_field(fields, "op", "B")


def time_field(fields: Dict[str, bytes], name: str) -> int:
    try:
        secs, nsecs = TIME.unpack(fields[name])
    except KeyError:
        raise BagFormatError(f"a record has no field '{name}'") from None
    except struct.error:
        raise BagFormatError(f"a record's field '{name}' has the wrong size") from None
    return secs * NS + nsecs


def str_field(fields: Dict[str, bytes], name: str) -> str:
    try:
        return fields[name].decode("utf-8")
    except KeyError:
        raise BagFormatError(f"a connection has no field '{name}'") from None
    except UnicodeDecodeError:
        raise BagFormatError(f"a connection's field '{name}' is not text") from None


def seconds(ns: int) -> float:
    """Nanoseconds as seconds, rounded as genpy's Time.to_sec rounds them."""
    secs, nsecs = divmod(ns, NS)
    return secs + nsecs / 1e9


def decompressor(name: str) -> Callable[[bytes], bytes]:
    if name == "none":
        return lambda data: data
    if name == "bz2":
        return bz2.decompress
    if name == "lz4":
        try:
            import roslz4  # what rosbag itself uses (Debian python3-roslz4, a dependency of python3-rosbag)
        except ImportError:
            raise Unsupported("lz4 chunks need the roslz4 module") from None
        return roslz4.decompress  # type: ignore[no-any-return]
    raise Unsupported(f"chunks compressed with '{name}'")


def message_class(conn: Connection) -> Any:
    """The message class of a connection, as rosbag makes it (from the recorded definition)."""
    try:
        from rosbag.bag import _get_message_type  # rosbag's cache: the very classes rosbag yields
    except ImportError:  # pragma: no cover - rosbag is installed with this reader's users
        import genpy.dynamic

        return genpy.dynamic.generate_dynamic(conn.datatype, conn.msg_def)[conn.datatype]
    return _get_message_type(conn)
