"""Publishes JointState messages shaped like the simulator's, stamped with the wall clock.

Run by run_bench.py as a separate process: the benchmark subscribes and measures how long
a /atlas/joint_states-sized message takes from rospy's publish() in one process to a
subscriber callback in another (rospy's queued publisher, as the simulator node uses).
The stamp is CLOCK_MONOTONIC (time.perf_counter on Linux), which all processes share.

usage: js_transport_probe.py TOPIC COUNT RATE_HZ
"""

from __future__ import annotations

import sys
import time

import rospy
from sensor_msgs.msg import JointState

from tutorial_atlas_control.joints import JOINT_NAMES

#: Longest wait for the benchmark's subscriber (s, wall).
SUBSCRIBER_TIMEOUT_S = 20.0


def main() -> int:
    topic, count, rate_hz = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
    rospy.init_node('tac_bench_js_probe', anonymous=True, disable_signals=True)
    pub = rospy.Publisher(topic, JointState, queue_size=100)
    deadline = time.monotonic() + SUBSCRIBER_TIMEOUT_S
    while pub.get_num_connections() == 0:
        if time.monotonic() > deadline:
            print('js_transport_probe: no subscriber', file=sys.stderr)
            return 1
        time.sleep(0.05)
    time.sleep(0.5)
    msg = JointState(name=list(JOINT_NAMES))
    values = [0.1 * i for i in range(len(JOINT_NAMES))]
    period = 1.0 / rate_hz
    next_s = time.perf_counter()
    for _ in range(count):
        msg.position, msg.velocity, msg.effort = list(values), list(values), list(values)
        now_ns = time.perf_counter_ns()
        msg.header.stamp = rospy.Time(now_ns // 1_000_000_000, now_ns % 1_000_000_000)
        pub.publish(msg)
        next_s += period
        delay = next_s - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
    time.sleep(0.3)
    rospy.signal_shutdown('done')
    return 0


if __name__ == '__main__':
    sys.exit(main())
