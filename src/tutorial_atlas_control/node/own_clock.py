"""The simulator is /clock's source: its rospy time follows what it sends, unsubscribed.

With /use_sim_time set (atlas.launch sets it), rospy.init_node subscribes every node to
/clock, the simulator too. It would then receive its own time at every step it sends one
(every step at real time): one more TCP send per step, and a rospy receive thread that
wakes, takes the GIL from the stepping loop, deserializes a Clock and notifies rospy's time
condition. Measured on the node at real_time_factor 1 without a client, that thread alone
was about a fifth of its CPU. Here the subscription is dropped and rospy's time is set
from each /clock the node has just sent instead: the same values at the same moments, so
log stamps and rospy's throttled logs keep running on sim time.
"""

from __future__ import annotations

import struct

import rospy
from rospy.impl import simtime

from tutorial_atlas_control.node.transport import WireBatch

__all__ = ['follow_own_clock', 'set_rostime_from_clock']

#: rosgraph_msgs/Clock with its TCPROS length prefix (msgs/wire.clock_bytes).
_FRAMED_CLOCK = struct.Struct('<III')


def set_rostime_from_clock(data: bytes | bytearray) -> None:
    """rospy's time := the last Clock in `data` (TCPROS-framed Clock messages)."""
    _, secs, nsecs = _FRAMED_CLOCK.unpack_from(data, len(data) - _FRAMED_CLOCK.size)
    rospy.rostime._set_rostime(rospy.Time(secs, nsecs))  # what rospy's /clock callback calls


def follow_own_clock(outbox: WireBatch, clock_pub: rospy.Publisher) -> bool:
    """Drop rospy's /clock subscription of this node, and set rospy's time from each
    /clock `outbox` sends through `clock_pub` instead. False (nothing changed) when rospy
    did not subscribe (no /use_sim_time)."""
    subscription = getattr(simtime, '_clock_sub', None)
    if subscription is None:
        return False
    subscription.unregister()
    simtime._clock_sub = None
    outbox.watch(clock_pub, set_rostime_from_clock)
    return True
