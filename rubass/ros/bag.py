"""Reading ROS 1 recordings for replay: messages in time order, deserialised only where needed.

Indexed bags of format 2.0 are read by our own reader (bagfile.py, about three times as fast as
rosbag's, and it opens a bag without reading its per-message index); other bags (format 1.2,
encrypted, an unknown compression) by rosbag.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Dict, Iterator, List, Optional, Set, Tuple, Union

from ..lang.errors import RubassError
from .bagfile import BagFile, BagFormatError, NoMessageSupport, Unindexed, Unsupported


class BagError(RubassError):
    """A recording that cannot be read; the message says why, in one line."""


@dataclass
class BagInfo:
    path: str
    start: float
    end: float
    messages: int
    types: Dict[str, str]  # topic -> message type


Bag = Union[BagFile, Any]  # our reader, or a rosbag.Bag where ours does not apply


def _unindexed(path: str) -> BagError:
    return BagError(f"{path}: the bag is not indexed (was recording interrupted?): run 'rosbag reindex {path}'")


def open_bag(path: str) -> Tuple[Bag, BagInfo]:
    """Open a bag for reading; BagError for a missing, unreadable, unindexed or corrupt file."""
    if not os.path.exists(path):
        raise BagError(f"{path}: no such file")
    if os.path.isdir(path):
        raise BagError(f"{path}: is a directory, not a bag")
    try:
        bag = BagFile(path)
    except Unsupported:
        return _open_rosbag(path)
    except Unindexed:
        raise _unindexed(path) from None
    except BagFormatError as exc:
        raise BagError(f"{path}: not a readable ROS 1 bag ({exc})") from None
    except OSError as exc:
        raise BagError(f"{path}: not a readable ROS 1 bag ({exc.__class__.__name__}: {exc})") from None
    except MemoryError:
        raise BagError(f"{path}: not a readable ROS 1 bag (a record claims more memory than there is: "
                       f"corrupt?)") from None
    topics = bag.topics()
    return bag, BagInfo(path, bag.start_time, bag.end_time, bag.message_count, {t: v[0] for t, v in topics.items()})


def _open_rosbag(path: str) -> Tuple[Any, BagInfo]:
    import rosbag

    try:
        bag = rosbag.Bag(path, "r")
        info = bag.get_type_and_topic_info()
        types = {t: v.msg_type for t, v in info.topics.items()}
        count = sum(v.message_count for v in info.topics.values())
        start = bag.get_start_time() if count else 0.0
        end = bag.get_end_time() if count else 0.0
    except rosbag.ROSBagUnindexedException:
        raise _unindexed(path) from None
    except (rosbag.ROSBagException, OSError, ValueError, KeyError, EOFError) as exc:
        raise BagError(f"{path}: not a readable ROS 1 bag ({exc.__class__.__name__}: {exc})") from None
    return bag, BagInfo(path, start, end, count, types)


def message_classes(bag: Bag, topics: List[str]) -> Dict[str, Any]:
    """The message class of each topic (that of its first message, so unknown types work too);
    BagError if the bag cannot be read."""
    out: Dict[str, Any] = {}
    for topic in topics:
        if isinstance(bag, BagFile):
            try:
                cls = bag.topic_class(topic)
            except BagFormatError as exc:
                raise BagError(f"{bag.filename}: the bag is corrupt: {exc}") from None
            except NoMessageSupport as exc:
                raise BagError(f"{bag.filename}: topic {topic}: {exc}") from None
            if cls is not None:
                out[topic] = cls
            continue
        for _, _, msg in _read_rosbag(bag, [topic], {topic}):
            out[topic] = type(msg)
            break
    return out


def read(bag: Bag, topics: List[str], decode: Set[str], callers: Set[str] = frozenset()  # type: ignore[assignment]
         ) -> Iterator[Tuple[float, str, Optional[Any]]]:
    """(time, topic, message or None) in recorded order; only topics in `decode` are deserialised; those in
    `callers` say who published them (`_connection_header['callerid']`, with our reader only)."""
    if not topics:
        return  # rosbag reads every topic when given none
    if isinstance(bag, BagFile):
        try:
            yield from bag.read(topics, decode, callers)
        except BagFormatError as exc:
            raise BagError(f"{bag.filename}: the bag is corrupt: {exc}") from None
        except NoMessageSupport as exc:
            raise BagError(f"{bag.filename}: {exc}") from None
        except OSError as exc:
            raise BagError(f"{bag.filename}: the bag cannot be read ({exc.__class__.__name__}: {exc})") from None
        except MemoryError:
            raise BagError(f"{bag.filename}: the bag is corrupt: a chunk claims more memory than there is") from None
        return
    yield from _read_rosbag(bag, topics, decode)


def _read_rosbag(bag: Any, topics: List[str], decode: Set[str]) -> Iterator[Tuple[float, str, Optional[Any]]]:
    import rosbag

    try:
        for topic, raw, stamp in bag.read_messages(topics=topics, raw=True):
            msg = None
            if topic in decode:
                msg = raw[-1]()
                msg.deserialize(raw[1])
            yield stamp.to_sec(), topic, msg
    except (rosbag.ROSBagException, OSError, ValueError, KeyError, EOFError) as exc:
        raise BagError(f"{bag.filename}: the bag is corrupt ({exc.__class__.__name__}: {exc})") from None
    except Exception as exc:  # genpy.DeserializationError and struct.error from a damaged chunk
        raise BagError(f"{bag.filename}: a message cannot be read ({exc.__class__.__name__}: {exc})") from None
