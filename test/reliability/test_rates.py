"""The simulator's publication rates and real_time_factor, judged from the recorded bag.

Two launches with rates that are not the defaults: unpaced (`real_time_factor:=0`, the loop
flat out, sending every FLUSH_PERIOD_S of wall time) and paced at a factor no machine
reaches (`real_time_factor:=1000`: always behind schedule, so every step takes pacing.py's
catch-up branch, a send at most every CATCH_UP_FLUSH_PERIOD_S; which branch ran leaves no
trace in a bag without wall time: what is asserted is that neither loses or misplaces a
message). `joint_states_rate` and `odom_rate` are atlas.launch arguments; the private
`~imu_rate`, `~contact_rate` and `~tf_rate` are set as /atlas_sim/... parameters by a
launch file that includes atlas.launch (as a user would set them).

What must hold whatever the machine's speed (none of it depends on wall time):
- each topic is sent every N steps, N = schedule.steps_between(rate): its stamps are N ms
  apart without exception (no step missing), on the step grid (joint states stamped at a
  step's end, the sensors and poses at its start: schedule.py);
- /clock is thinned to the latest time of each send (loop.py, `outbox.replace`): its values
  strictly increase and each is a step's end, so with joint states every step each /clock
  value from the first recorded joint state on is the stamp of one (transport.py sends a
  flush's /clock after its joint states).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

import rosbag

from support.launch import TestLaunch
from tutorial_atlas_control import topics
from tutorial_atlas_control.stepping.schedule import steps_between

#: Timing or memory claims: run alone, after make test's parallel part.
pytestmark = pytest.mark.serial

#: Sim time (s) recorded after the launch is ready.
RUN_S = 4.0
STEP_NS = 1_000_000
#: The simulator's own transform on /tf (the links' transforms go there too, at 50 Hz).
PELVIS_TF = ('world', 'pelvis')

WRAPPER = '''<launch>
  <!-- The simulator's private rates (sim_node.py), set before atlas.launch starts it. -->
  <param name="/atlas_sim/imu_rate" value="{imu}"/>
  <param name="/atlas_sim/contact_rate" value="{contact}"/>
  <param name="/atlas_sim/tf_rate" value="{tf}"/>
  <include file="$(find tutorial_atlas_control)/launch/atlas.launch">
    <arg name="real_time_factor" value="{rtf}"/>
    <arg name="joint_states_rate" value="{joint_states}"/>
    <arg name="odom_rate" value="{odom}"/>
    <arg name="gui" value="false"/>
    <arg name="bag_dir" value="{bag_dir}"/>
  </include>
</launch>
'''

#: (real_time_factor, rates in Hz): 0 and rates at or above the step rate mean every step;
#: 300 Hz rounds to every 3 steps (333 Hz), 333 Hz too.
CASES = {
    'unpaced': (0.0, {'joint_states': 0.0, 'odom': 50.0, 'imu': 250.0, 'contact': 300.0,
                      'tf': 40.0}),
    'catching_up': (1000.0, {'joint_states': 333.0, 'odom': 0.0, 'imu': 2000.0,
                             'contact': 100.0, 'tf': 1000.0}),
}
#: Topic -> (its rate's key, stamped at the step's end).
TOPIC_RATES = {
    topics.JOINT_STATES: ('joint_states', True),
    topics.GROUND_TRUTH_ODOM: ('odom', False),
    topics.IMU: ('imu', False),
    topics.L_FOOT_CONTACT: ('contact', False),
    topics.R_FOOT_CONTACT: ('contact', False),
    topics.TF: ('tf', False),
}


def recorded_stamps(bag_path: Path) -> dict[str, np.ndarray]:
    """Each topic's stamps (ns of sim time) in the order recorded; /clock's values."""
    stamps: dict[str, list[int]] = {topic: [] for topic in [*TOPIC_RATES, topics.CLOCK]}
    with rosbag.Bag(str(bag_path)) as bag:
        for topic, msg, _ in bag.read_messages(topics=list(stamps)):
            if topic == topics.CLOCK:
                stamps[topic].append(msg.clock.to_nsec())
            elif topic == topics.TF:
                stamps[topic].extend(
                    t.header.stamp.to_nsec() for t in msg.transforms
                    if (t.header.frame_id, t.child_frame_id) == PELVIS_TF)
            else:
                stamps[topic].append(msg.header.stamp.to_nsec())
    return {topic: np.asarray(values, dtype=np.int64) for topic, values in stamps.items()}


@pytest.mark.parametrize('case', list(CASES))
def test_rates_and_real_time_factor(tmp_path: Path, case: str) -> None:
    rtf, rates = CASES[case]
    bag_dir = tmp_path / 'bags'
    wrapper = tmp_path / 'rates.launch'
    wrapper.write_text(WRAPPER.format(rtf=rtf, bag_dir=bag_dir, **rates))
    with TestLaunch(tmp_path, launch_file=str(wrapper)) as launch:
        launch.wait_ready()
        launch.wait_sim_s(RUN_S)
        launch.interrupt()
        assert launch.process.returncode == 0, launch.output()
        bag = launch.bag()
    stamps = recorded_stamps(bag)

    for topic, (key, at_end) in TOPIC_RATES.items():
        every = steps_between(rates[key], STEP_NS / 1e9)
        # The message sent before the first step (sim time 0) is off the schedule.
        got = stamps[topic][stamps[topic] > 0]
        assert len(got) * every >= (RUN_S - 0.5) * 1000, f'{topic}: only {len(got)} messages'
        gaps = np.diff(got)
        assert np.all(gaps == every * STEP_NS), (
            f'{topic} every {every} steps: stamps {every} ms apart expected, found gaps of '
            f'{sorted({int(g) for g in gaps})} ns')
        # Sent after steps number every, 2 every, ...: a step's end, or its start for sensors.
        step_ends = got if at_end else got + STEP_NS
        assert np.all(step_ends % (every * STEP_NS) == 0), f'{topic}: off the step grid'

    clock = stamps[topics.CLOCK]
    assert len(clock) > 0
    assert np.all(np.diff(clock) > 0), '/clock went backwards or repeated a value'
    assert np.all(clock % STEP_NS == 0), '/clock carries a time that is no step end'
    joint_states = stamps[topics.JOINT_STATES]
    if steps_between(rates['joint_states'], STEP_NS / 1e9) == 1:
        # The recorder subscribes to each topic in turn: /clock may be heard first, while
        # the joint states of those times went to no one yet.
        recorded = set(joint_states.tolist())
        unstamped = [int(c) for c in clock
                     if joint_states[0] <= c <= joint_states[-1] and int(c) not in recorded]
        assert not unstamped, f'/clock values stamping no joint state: {unstamped[:5]}'
    print(f'{case}: {len(clock)} /clock values for {len(joint_states)} joint states')
