#!/usr/bin/python3
"""Small robot nodes for the multi-host tests.

    multihost_node.py talk TOPIC HZ          publish std_msgs/Header on TOPIC at HZ
    multihost_node.py hog                    keep one core busy (a runaway node)
    multihost_node.py listen OUT TOPIC:TYPE...  append each message as a JSON line to OUT

The node name comes from __name:=NAME.
"""
import json
import sys
import threading
import time

import genpy
import roslib.message
import rospy
from std_msgs.msg import Header


def to_dict(msg):
    if hasattr(msg, "__slots__"):
        return {k: to_dict(getattr(msg, k)) for k in msg.__slots__}
    if isinstance(msg, (list, tuple)):
        return [to_dict(v) for v in msg]
    if isinstance(msg, genpy.TVal):
        return msg.to_sec()
    return msg


def main():
    rospy.init_node("multihost_" + sys.argv[1])
    argv = rospy.myargv(sys.argv)  # without __name:= and other remappings
    mode = argv[1]
    if mode == "talk":
        pub = rospy.Publisher(argv[2], Header, queue_size=10, tcp_nodelay=True)
        rate = rospy.Rate(float(argv[3]))
        while not rospy.is_shutdown():
            pub.publish(Header(stamp=rospy.Time.now()))
            try:
                rate.sleep()
            except rospy.ROSInterruptException:
                break
    elif mode == "hog":
        def burn():
            x = 0
            while not rospy.is_shutdown():
                x += 1

        threading.Thread(target=burn, daemon=True).start()
        rospy.spin()
    elif mode == "listen":
        out = open(argv[2], "a")
        lock = threading.Lock()

        def callback(msg, topic):
            with lock:
                out.write(json.dumps({"topic": topic, "wall": time.time(), "msg": to_dict(msg)}) + "\n")
                out.flush()

        for item in argv[3:]:
            topic, type_ = item.split(":")
            rospy.Subscriber(topic, roslib.message.get_message_class(type_), callback, callback_args=topic)
        rospy.spin()


if __name__ == "__main__":
    main()
