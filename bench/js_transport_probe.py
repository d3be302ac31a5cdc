"""Sends JointState messages down the simulator node's own path, stamped with the wall clock.

Run by run_bench.py as a separate process: the benchmark subscribes and measures how long
a /atlas/joint_states message takes from the node's send to a subscriber callback in
another process. So that the figure is the transport the command latency includes, this
uses the node's path, not rospy's publish(): a publisher with queue_size=None (synchronous,
no writer thread), the message pre-serialized by msgs/wire.JointStateWire (the node's
layout, same names and size), and one WireBatch.add() + flush() per message, i.e. one
transport.ConnectionWriter send per step as the node does at real_time_factor 1.
The stamp is CLOCK_MONOTONIC (time.perf_counter_ns on Linux), which all processes share,
taken just before the message is batched and flushed.

usage: js_transport_probe.py TOPIC COUNT RATE_HZ
"""

from __future__ import annotations

import sys
import time
import warnings

import rospy
from sensor_msgs.msg import JointState

from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.msgs.wire import JointStateWire
from tutorial_atlas_control.node.transport import WireBatch

#: Longest wait for the benchmark's subscriber (s, wall).
SUBSCRIBER_TIMEOUT_S = 20.0


def main() -> int:
    topic, count, rate_hz = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
    rospy.init_node('tac_bench_js_probe', anonymous=True, disable_signals=True)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', SyntaxWarning)  # rospy: "explicit queue_size"
        pub = rospy.Publisher(topic, JointState, queue_size=None)  # as sim_node._advertise
    deadline = time.monotonic() + SUBSCRIBER_TIMEOUT_S
    while not WireBatch.wanted(pub):
        if time.monotonic() > deadline:
            print('js_transport_probe: no subscriber', file=sys.stderr)
            return 1
        time.sleep(0.05)
    time.sleep(0.5)
    wire = JointStateWire(JOINT_NAMES)
    wire.position[:] = wire.velocity[:] = wire.effort[:] = [0.1 * i
                                                             for i in range(len(JOINT_NAMES))]
    batch = WireBatch()
    period = 1.0 / rate_hz
    next_s = time.perf_counter()
    for _ in range(count):
        batch.add(pub, wire.stamped(time.perf_counter_ns()))
        batch.flush()
        next_s += period
        delay = next_s - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
    time.sleep(0.3)
    rospy.signal_shutdown('done')
    return 0


if __name__ == '__main__':
    sys.exit(main())
