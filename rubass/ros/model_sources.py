"""System models gathered from ROS: a recording's connections, the live graph (types from the
master, definitions of types not installed from the publishers' TCPROS handshake, joint kinds
from /robot_description), and installed message and service definitions."""
from __future__ import annotations

import io
import os
import socket
from typing import Dict, Optional

from ..lang.errors import RubassError
from ..lang.msgdef import DefinitionError, Registry
from ..lang.std_units import joint_state_units, urdf_joint_kinds
from ..lang.sysmodel import SystemModel
from .bag import BagError, open_bag
from .libtypes import add_installed
from .rpc import proxy as rpc_proxy

CALLER = "/rubass_check"


class LiveError(RubassError):
    """The live graph cannot be read (no master, …); the message says why, in one line."""


def bag_model(path: str) -> SystemModel:
    """Topics, types, definitions and (when recorded) publishing nodes of a recording."""
    bag, info = open_bag(path)
    try:
        registry = Registry()
        for conn in bag._connections.values():  # rosbag keeps each connection's header here
            try:
                registry.add_full(conn.datatype, conn.msg_def)
            except DefinitionError as exc:
                raise BagError(f"{path}: topic {conn.topic}: {exc}") from None
    finally:
        bag.close()
    # No node list: a bag names only publishers, and often as the recorder or player
    # ('/play_1633455785917753240') rather than the node that ran on the robot.
    return SystemModel(dict(info.types), None, registry, source=f"the recording {os.path.basename(path)}")


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
