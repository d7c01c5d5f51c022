#!/usr/bin/python3
"""A scripted ROS node for integration tests: publishes and records, prints JSON lines.

    probe.py '{"listen": [{"topic": "/stop", "type": "geometry_msgs/Twist"}],
               "advertise": [{"topic": "/cmd_vel", "type": "geometry_msgs/Twist"}],
               "steps": [{"wait_subscribers": "/cmd_vel"},
                         {"publish": "/cmd_vel", "msg": {"linear": {"x": 2.0}}},
                         {"sleep": 0.5},
                         {"wait": "/stop", "timeout": 5}],
               "linger": 0.5}'

Each line out: {"kind": "sent"|"recv"|"timeout", "topic": …, "wall": time.time(), "msg": {…}}.
"""
import json
import sys
import threading
import time

import genpy
import roslib.message
import rospy


def to_dict(msg):
    if hasattr(msg, "__slots__"):
        return {k: to_dict(getattr(msg, k)) for k in msg.__slots__}
    if isinstance(msg, (list, tuple)):
        return [to_dict(v) for v in msg]
    if isinstance(msg, genpy.TVal):
        return msg.to_sec()
    if isinstance(msg, bytes):
        return list(msg)
    return msg


def main():
    plan = json.loads(sys.argv[1])
    rospy.init_node(plan.get("node", "probe"), anonymous=plan.get("anonymous", True), disable_signals=True)
    out_lock = threading.Lock()
    seen = {}

    def emit(record):
        with out_lock:
            sys.stdout.write(json.dumps(record) + "\n")
            sys.stdout.flush()

    def callback(msg, topic):
        wall = time.time()
        seen.setdefault(topic, threading.Event()).set()
        emit({"kind": "recv", "topic": topic, "wall": wall, "msg": to_dict(msg)})

    for item in plan.get("listen", []):
        cls = roslib.message.get_message_class(item["type"])
        seen.setdefault(item["topic"], threading.Event())
        rospy.Subscriber(item["topic"], cls, callback, callback_args=item["topic"], tcp_nodelay=True)
    for item in plan.get("serve", []):
        srv = roslib.message.get_service_class(item["type"])

        def handler(req, item=item, srv=srv):
            emit({"kind": "call", "topic": item["service"], "wall": time.time()})
            time.sleep(item.get("delay", 0.0))
            return srv._response_class(success=True, message="ok")

        rospy.Service(item["service"], srv, handler)
    pubs = {}
    for item in plan.get("advertise", []):
        cls = roslib.message.get_message_class(item["type"])
        pubs[item["topic"]] = (rospy.Publisher(item["topic"], cls, queue_size=100, tcp_nodelay=True), cls)
    for step in plan.get("steps", []):
        if "sleep" in step:
            time.sleep(step["sleep"])
        elif "wait_subscribers" in step:
            pub = pubs[step["wait_subscribers"]][0]
            end = time.time() + step.get("timeout", 10)
            while pub.get_num_connections() < step.get("count", 1) and time.time() < end:
                time.sleep(0.01)
        elif "wait_publishers" in step:
            end = time.time() + step.get("timeout", 10)
            while time.time() < end:
                topics = dict(rospy.get_published_topics())
                if step["wait_publishers"] in topics:
                    break
                time.sleep(0.05)
        elif "publish" in step:
            pub, cls = pubs[step["publish"]]
            for _ in range(step.get("repeat", 1)):
                msg = cls()
                if step.get("msg"):
                    genpy.message.fill_message_args(msg, [step["msg"]])
                wall = time.time()
                pub.publish(msg)
                emit({"kind": "sent", "topic": step["publish"], "wall": wall, "msg": step.get("msg")})
                if step.get("period"):
                    time.sleep(step["period"])
        elif "wait" in step:
            ev = seen.setdefault(step["wait"], threading.Event())
            if step.get("fresh"):
                ev.clear()
            if not ev.wait(step.get("timeout", 5)):
                emit({"kind": "timeout", "topic": step["wait"], "wall": time.time()})
        elif "mark" in step:
            emit({"kind": "mark", "name": step["mark"], "wall": time.time()})
    time.sleep(plan.get("linger", 0.0))
    rospy.signal_shutdown("done")


if __name__ == "__main__":
    main()
