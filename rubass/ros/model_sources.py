"""System models gathered from ROS: a recording's connections, the live graph (types from the
master, definitions of types not installed from the publishers' TCPROS handshake, joint kinds
from /robot_description), and installed message and service definitions."""
from __future__ import annotations

import dataclasses
import io
import os
import socket
from typing import Dict, List, Optional, Sequence

from ..lang import SpecError, load_spec
from ..lang.errors import Diagnostic, RubassError
from ..lang.model import CheckedSpec
from ..lang.msgdef import DefinitionError, Registry
from ..lang.std_units import joint_state_units, urdf_joint_kinds
from ..lang.sysmodel import SystemModel, norm_topic
from ..lang.topicnames import spellings
from .bag import BagError, open_bag
from .libtypes import add_installed
from .rpc import proxy as rpc_proxy

CALLER = "/rubass_check"


class LiveError(RubassError):
    """The live graph cannot be read (no master, …); the message says why, in one line."""


def bag_model(path: str, strict: bool = True) -> SystemModel:
    """Topics, types, definitions and (when recorded) publishing nodes of a recording. A recorded
    definition that cannot be read is a BagError; not `strict`, it is kept in the model's `broken`
    (load_spec_against refuses it only for a spec that reads that topic's fields)."""
    bag, info = open_bag(path)
    broken: Dict[str, str] = {}
    try:
        registry = Registry()
        for conn in bag._connections.values():  # rosbag keeps each connection's header here
            try:
                registry.add_full(conn.datatype, conn.msg_def)
            except DefinitionError as exc:
                if strict:
                    raise BagError(f"{path}: topic {conn.topic}: {exc}") from None
                broken.setdefault(norm_topic(conn.topic), f"{path}: topic {conn.topic}: {exc}")
    finally:
        bag.close()
    # No node list: a bag names only publishers, and often as the recorder or player
    # ('/play_1633455785917753240') rather than the node that ran on the robot.
    return SystemModel(dict(info.types), None, registry, source=f"the recording {os.path.basename(path)}",
                       broken=broken)


def recorded_types(path: str) -> Dict[str, List[str]]:
    """Topic -> every type recorded on it, the one bag_model gives it first (a topic may have connections
    of several types); BagError if the recording cannot be read."""
    bag, info = open_bag(path)
    try:
        out = {t: [ty] for t, ty in info.types.items()}
        for conn in bag._connections.values():  # both readers keep the connections here
            kinds = out.setdefault(conn.topic, [conn.datatype])
            if conn.datatype not in kinds:
                kinds.append(conn.datatype)
    finally:
        bag.close()
    return out


def load_spec_against(path: str, actions: Sequence[str], model: Optional[SystemModel],
                      bag: Optional[str] = None) -> CheckedSpec:
    """load_spec(path, actions, model=model); with `bag`, the recording `model` is of, the spec is read
    against every other type recorded on one of its topics as well (as `rubass replay` reads it, and
    refuses it if it cannot): each error of that reading at its place, naming the type. SpecError with
    every error, the spec's against the topics' first types and these. BagError when the spec reads the
    fields of a topic whose recorded definition cannot be read (the model's `broken`)."""
    if model is not None and model.broken:  # a definition the recording holds unreadable: only the spec
        plain = load_spec(path, list(actions))  # that reads that topic's fields is refused (BagError)
        read = {norm_topic(t) for t in plain.field_readers(implicit=False)}
        unreadable = [why for topic, why in sorted(model.broken.items()) if topic in read]
        if unreadable:
            raise BagError("; ".join(unreadable))
    checked: Optional[CheckedSpec] = None
    failed: Optional[SpecError] = None
    try:
        checked = load_spec(path, list(actions), model=model)
    except SpecError as exc:
        if bag is None or model is None:
            raise
        failed = exc
    if bag is None or model is None:
        assert checked is not None
        return checked
    try:
        kinds_of = recorded_types(bag)
    except BagError:  # read for the model a moment ago: nothing more to say than bag_model said
        kinds_of = {}
    wanted = None if checked is None else {norm_topic(t) for t in spellings(checked.topics)}
    errors = list(failed.diagnostics) if failed is not None else []
    new: List[Diagnostic] = []
    warned = list(checked.warnings) if checked is not None else []
    for topic, kinds in sorted(kinds_of.items()):
        if wanted is not None and norm_topic(topic) not in wanted:
            continue  # a topic the spec does not read
        for type_name in kinds[1:]:
            variant = dataclasses.replace(model, topics={**model.topics, norm_topic(topic): type_name})
            note = (f"{topic} is recorded as {type_name} too in {os.path.basename(bag)} (first as {kinds[0]}): "
                    f"this is the spec read against {type_name}")
            try:
                other = load_spec(path, list(actions), model=variant)
            except SpecError as exc:
                new += [dataclasses.replace(d, message=f"{d.message}; {note}") for d in exc.diagnostics
                        if d not in errors]
                continue
            if checked is not None:  # a warning of one type only (stamp_age() of a type without a header) says so
                warned = [w if w in other.warnings or w not in checked.warnings else dataclasses.replace(
                    w, message=f"{w.message}; this holds for its {kinds[0]} messages only ({topic} is recorded as "
                               f"{type_name} too in {os.path.basename(bag)})") for w in warned]
                warned += [dataclasses.replace(w, message=f"{w.message}; {note}") for w in other.warnings
                           if w not in checked.warnings]
    if failed is not None:
        raise SpecError(errors + new, failed.sources, failed.warnings) if new else failed
    assert checked is not None
    checked.warnings[:] = warned
    if new:
        raise SpecError(new, checked.sources, checked.warnings)
    return checked


def _master(uri: Optional[str], timeout: float):  # type: ignore[no-untyped-def]
    """A master handle whose every call gives up after `timeout` (a hung master must not hang us)."""
    import rosgraph

    try:
        master = rosgraph.Master(CALLER, master_uri=uri)
    except ValueError as exc:  # ROS_MASTER_URI unset or malformed
        raise LiveError(f"{exc} (set ROS_MASTER_URI or pass --master http://HOST:11311)") from None
    master.handle = rpc_proxy(master.master_uri, timeout)
    if not master.is_online():
        raise LiveError(f"no ROS master at {master.master_uri} (is roscore running? is ROS_MASTER_URI right?)")
    return master


def live_model(uri: Optional[str] = None, timeout: float = 2.0) -> SystemModel:
    """Topics and types, nodes and definitions of the running graph."""
    import rosgraph.masterapi

    master = _master(uri, timeout)
    try:
        types = dict(master.getTopicTypes())
        pubs, subs, srvs = master.getSystemState()
    except (rosgraph.masterapi.Error, OSError) as exc:  # socket.timeout is an OSError
        raise LiveError(f"the master at {master.master_uri} does not answer: {exc}") from None
    nodes = sorted({n for _, ns in list(pubs) + list(subs) + list(srvs) for n in ns})
    registry = Registry()
    add_installed(registry, set(types.values()))
    for topic, publishers in pubs:
        ty = types.get(topic)
        if ty is None or ty == "*" or registry.get(ty) is not None:
            continue
        for node in publishers:
            text = _definition_from_publisher(master, topic, node, timeout)
            if text is not None:
                try:
                    registry.add_full(ty, text)
                    break
                except DefinitionError:
                    continue
    published = {t for t, ns in pubs if ns}
    model = SystemModel({t: ty for t, ty in types.items() if ty != "*"}, nodes, registry,
                        source=f"the live graph at {master.master_uri}",
                        unpublished={t for t in types if t not in published})
    apply_joint_kinds(model, _joint_kinds(master))
    return model


def _definition_from_publisher(master, topic: str, node: str, timeout: float) -> Optional[str]:  # type: ignore
    """The message definition a publisher sends in its TCPROS handshake (no message is read)."""
    from rosgraph.network import read_ros_handshake_header, write_ros_handshake_header

    try:
        api = master.lookupNode(node)
        code, _, proto = rpc_proxy(api, timeout).requestTopic(CALLER, topic, [["TCPROS"]])
        if code != 1 or not proto or proto[0] != "TCPROS":
            return None
        with socket.create_connection((proto[1], int(proto[2])), timeout=timeout) as sock:
            write_ros_handshake_header(sock, {"topic": topic, "md5sum": "*", "type": "*", "callerid": CALLER})
            header = read_ros_handshake_header(sock, io.BytesIO(), 65536)
    except Exception:  # a dead, hung or odd publisher: its type's fields stay unknown
        return None
    return header.get("message_definition") or None


def _joint_kinds(master) -> Dict[str, str]:  # type: ignore[no-untyped-def]
    """URDF joint name -> type from /robot_description; {} when absent or unreadable."""
    try:
        return urdf_joint_kinds(master.getParam("/robot_description"))
    except Exception:  # no such parameter, not a URDF, a master gone: units stay unknown
        return {}


def apply_joint_kinds(model: SystemModel, kinds: Dict[str, str]) -> None:
    """Units of every sensor_msgs/JointState topic of the model, when the joints' kinds say them."""
    units = joint_state_units(kinds) if kinds else {}
    for topic, ty in model.topics.items():
        if ty == "sensor_msgs/JointState" and units:
            model.topic_units[topic] = dict(units)
