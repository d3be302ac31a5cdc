#!/usr/bin/env python3
"""ROS side of test_viewer_gestures.py, in its own process (rospy allows one node per process).

    viewer_probe.py reset GESTURE_JSON   ragdoll the robot until it lies down, run the
                                         gesture (a command line, JSON list), report what
                                         the reset did
    viewer_probe.py pause GESTURE_JSON   run the gesture twice: /clock must stop, then go on

Prints one JSON object on stdout; the test judges it. ROS_MASTER_URI and DISPLAY come from
the environment.
"""

from __future__ import annotations

import json
import subprocess
import sys
import threading
import time

import rospy
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String

#: Sim time (s) after start by which the torso (pinned 1 s) is surely free.
START_S = 1.5
COLLAPSED_BELOW_M = 0.5
#: Sim time (s) after the reset over which the pelvis height is watched (< time_to_unpin).
PINNED_WATCH_S = 0.8
#: The first samples after the reset are skipped (s): the reset lands between two odom stamps.
SETTLE_S = 0.02
#: Wall time (s) without a /clock change that counts as paused (it ticks every 1 ms of sim time).
STILL_S = 0.5
#: Wall time (s) the clock is then watched while paused.
PAUSED_WATCH_S = 1.5
#: Wall-clock bounds (s).
TIMEOUT_S = 60.0


class Probe:
    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.clock_s: float | None = None
        self.clock_count = 0
        self.clock_backwards = 0
        self.odom: list[tuple[float, float]] = []
        self.last_reset_s: float | None = None
        rospy.Subscriber('/clock', Clock, self._on_clock, queue_size=100)
        rospy.Subscriber('/ground_truth_odom', Odometry, self._on_odom, queue_size=100)
        rospy.Subscriber('/atlas/sim_config', String, self._on_config, queue_size=10)
        self.mode = rospy.Publisher('/atlas/control_mode', String, queue_size=1, latch=True)

    def _on_clock(self, msg: Clock) -> None:
        now_s = msg.clock.to_sec()
        with self.lock:
            if self.clock_s is not None and now_s < self.clock_s:
                self.clock_backwards += 1
            self.clock_s = now_s
            self.clock_count += 1

    def _on_odom(self, msg: Odometry) -> None:
        with self.lock:
            self.odom.append((msg.header.stamp.to_sec(), msg.pose.pose.position.z))

    def _on_config(self, msg: String) -> None:
        with self.lock:
            self.last_reset_s = float(json.loads(msg.data)['last_reset_time'])

    def wait(self, condition, what: str, timeout_s: float = TIMEOUT_S) -> None:
        deadline = time.monotonic() + timeout_s
        while True:
            with self.lock:
                if condition():
                    return
            if time.monotonic() > deadline or rospy.is_shutdown():
                raise TimeoutError(f'{what}: not within {timeout_s:.0f} s')
            time.sleep(0.01)

    def latest_z(self) -> float | None:
        return self.odom[-1][1] if self.odom else None


def reset_scenario(probe: Probe, gesture: list[str]) -> dict[str, object]:
    probe.wait(lambda: probe.clock_s is not None and probe.clock_s >= START_S
               and probe.last_reset_s is not None, 'simulator start')
    probe.mode.publish(String(data='ragdoll'))
    probe.wait(lambda: (probe.latest_z() or 1.0) < COLLAPSED_BELOW_M, 'collapse in ragdoll')
    with probe.lock:
        before_s, collapsed_z, gesture_clock_s = probe.last_reset_s, probe.latest_z(), probe.clock_s
    subprocess.run(gesture, timeout=TIMEOUT_S, check=True)
    probe.wait(lambda: probe.last_reset_s > before_s, '/atlas/sim_config with a new reset time',
               timeout_s=20.0)
    with probe.lock:
        reset_s = probe.last_reset_s
    probe.wait(lambda: probe.clock_s >= reset_s + PINNED_WATCH_S, 'sim time after the reset')
    with probe.lock:
        heights = [z for stamp, z in probe.odom
                   if reset_s + SETTLE_S <= stamp <= reset_s + PINNED_WATCH_S]
        return {'collapsed_z_m': collapsed_z, 'reset_before_s': before_s, 'reset_after_s': reset_s,
                'gesture_clock_s': gesture_clock_s, 'pinned_heights_m': heights,
                'clock_backwards': probe.clock_backwards, 'clock_count': probe.clock_count}


def pause_scenario(probe: Probe, gesture: list[str]) -> dict[str, object]:
    probe.wait(lambda: probe.clock_s is not None and probe.clock_s >= START_S, 'simulator start')
    subprocess.run(gesture, timeout=TIMEOUT_S, check=True)
    # The key is handled when the window's thread next polls events, the request at the
    # node's next viewer refresh: a loaded machine can take a while. Paused = /clock still.
    deadline = time.monotonic() + 20.0
    while True:
        with probe.lock:
            before_s = probe.clock_s
        time.sleep(STILL_S)
        with probe.lock:
            paused_at_s = probe.clock_s
        if paused_at_s == before_s:
            break
        if time.monotonic() > deadline:
            raise TimeoutError('/clock did not stop after the pause gesture')
    time.sleep(PAUSED_WATCH_S)
    with probe.lock:
        paused_until_s = probe.clock_s
    subprocess.run(gesture, timeout=TIMEOUT_S, check=True)
    probe.wait(lambda: probe.clock_s > paused_until_s + 0.2, '/clock running again', 20.0)
    return {'paused_at_s': paused_at_s, 'paused_until_s': paused_until_s,
            'clock_backwards': probe.clock_backwards}


def main() -> int:
    scenario, gesture = sys.argv[1], json.loads(sys.argv[2])
    rospy.init_node('viewer_probe', anonymous=True, disable_signals=True)
    probe = Probe()
    try:
        result = (reset_scenario if scenario == 'reset' else pause_scenario)(probe, gesture)
    except (TimeoutError, subprocess.CalledProcessError) as err:
        result = {'error': str(err)}
    print(json.dumps(result))
    rospy.signal_shutdown('probe done')
    return 0


if __name__ == '__main__':
    sys.exit(main())
