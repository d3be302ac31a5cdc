"""Floods of bad commands and a heavy load of good ones against a real-time simulator.

What must hold at any speed of the machine is asserted here; how fast the simulator stays
under the load (its real-time factor) is `make bench`'s `load` section.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from support.bag_checks import (
    ERROR,
    WARN,
    all_finite,
    count,
    log_lines,
    missing_steps,
)
from support.launch import TestLaunch, flood_figures
from tutorial_atlas_control.bags.reader import read_bag
from tutorial_atlas_control.bags.typestore import load_typestore
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.node.transport import MAX_BACKLOG_BYTES
from tutorial_atlas_control.processes import rss_kib

#: Timing or memory claims: run alone, after make test's parallel part.
pytestmark = pytest.mark.serial

#: The issue's figures.
FLOOD_S = 10.0
LOAD_PUBLISHERS = 3
LOAD_RATE_HZ = 2000.0
LOAD_S = 30.0
#: The valid command's left elbow target (rad): the robot must hold it.
VALID_ELBOW_RAD = 1.2
#: How far the held elbow may be from its target (rad): P-gain slack plus the standing
#: robot's slow sway (1.17 typical; 1.14 in the last second of a long run), as in the
#: sim_interface rostest. A refused command would send it to 0.
ELBOW_TOLERANCE_RAD = 0.1
#: Resident memory the simulator may gain over the load (KiB), once what the transport held
#: for a starved subscriber is sent: Python's allocator settling, far below what a queue of
#: 30 s x 6 kHz commands (~100 MB) would take, and below a leak of 100 bytes per command.
RSS_GROWTH_BOUND_KIB = 4096
#: The simulator's malloc: every block of 128 KiB or more in its own mapping, returned to
#: the system when freed (a fixed threshold: glibc does not raise it after a free). A starved
#: subscriber's backlog (up to MAX_BACKLOG_BYTES, node/transport.py) is such a block: once it
#: is sent, its memory leaves the resident set instead of staying in the heap, so that the
#: bound after the load needs no allowance for it (which would let a 12 MB leak pass).
SIM_MALLOC_ENV = {'MALLOC_MMAP_THRESHOLD_': str(128 * 1024)}
#: Wall-clock guard (s) for the backlogs to drain after the load (the recorder catching up).
DRAIN_TIMEOUT_S = 60.0
#: The load's distinct commands: publisher k's neck_ay target in its flood, then in its last
#: command (rad, well inside the joint's -0.61..1.13 rad); its flood lasts k x LAST_STAGGER_S
#: longer (wall s: the publishers' ends far apart on a loaded machine).
NECK_STEP_RAD = 0.1
LAST_STAGGER_S = 0.5
NECK = JOINT_NAMES.index('neck_ay')
#: Sim time (s) after the floods before stopping: the neck reaching its last target.
SETTLE_S = 1.0
#: How far the neck may end from its last target (rad): P-gain slack holding the head up
#: (0.038 measured at 0.5 rad); besides, it must be nearer that target than any other sent.
NECK_TOLERANCE_RAD = NECK_STEP_RAD


def last_command_position(bag: Path) -> np.ndarray:
    """Positions of the last /atlas/joint_commands in the bag (receipt order)."""
    from rosbags.rosbag1 import Reader

    with Reader(bag) as reader:
        connections = [c for c in reader.connections if c.topic == '/atlas/joint_commands']
        assert connections, 'no command recorded'  # none: Reader.messages reads every topic
        last = None
        for connection, _t, raw in reader.messages(connections=connections):
            last = connection, raw
        assert last is not None, 'no command recorded'
        message = load_typestore(reader.connections).deserialize_ros1(last[1], last[0].msgtype)
    return np.asarray(message.position)


def flood_neck_rad(k: int) -> float:
    return round(k * NECK_STEP_RAD, 6)


def last_neck_rad(k: int) -> float:
    return round((LOAD_PUBLISHERS + k) * NECK_STEP_RAD, 6)


#: Sim time (s) the floods start at: after the torso is released (time_to_unpin 1 s).
START_SIM_S = 2.0
#: Sim time (s) of the first memory reading: a third into the floods, when the allocator has
#: settled at the load's working set (on a machine busy with other work, later: the command
#: queue between two steps is longer). A leak of only 100 bytes per command would still add
#: 12 MB over the remaining 20 s.
RSS_START_SIM_S = START_SIM_S + 10.0


@pytest.fixture()
def atlas_launch(tmp_path: Path) -> Iterator[TestLaunch]:
    """atlas.launch whose simulator hands large freed blocks back (SIM_MALLOC_ENV)."""
    with TestLaunch(tmp_path, base_env={**os.environ, **SIM_MALLOC_ENV}) as launch:
        yield launch


def test_flood_of_bad_commands_and_modes_is_refused(atlas_launch: TestLaunch) -> None:
    atlas_launch.wait_ready()
    atlas_launch.set_mode('User')
    flood = atlas_launch.start_flood('--kind', 'bad', '--rate', '1000', '--elbow',
                                     str(VALID_ELBOW_RAD), '--duration', str(FLOOD_S),
                                     '--start-sim', str(START_SIM_S))
    figures = flood_figures(flood, timeout_s=FLOOD_S + 90.0)
    time.sleep(1.0)
    atlas_launch.interrupt()
    bag = atlas_launch.bag()
    data = read_bag(bag)
    states, pelvis = data.joint_states, data.pelvis

    assert all_finite(states), 'NaN/Inf in /atlas/joint_states'
    assert missing_steps(states) == 0
    assert data.modes[-1][1] != 'User' and 'User' in [mode for _, mode in data.modes], \
        'the bad modes were published (and recorded) after User'
    errors = log_lines(bag, min_level=ERROR)
    assert not errors, f'errors (divergence?) during the flood: {errors}'
    assert 'unstable' not in atlas_launch.output()
    warnings = log_lines(bag, min_level=WARN)
    assert any('refused /atlas/joint_commands' in line for line in warnings)
    assert any('refused /atlas/control_mode' in line for line in warnings)
    # Every message reached the recording: the valid one, the flood, and the `User` mode.
    recorded = count(bag, '/atlas/joint_commands')
    assert recorded == figures['sent'] + 1, (recorded, figures)
    # Still in User mode under the one valid command: elbow bent, standing.
    flood_start_s = figures['sim_start_s'] - data.start_time_s
    after = states.t_s >= flood_start_s
    elbow = states.position[after, states.names.index('l_arm_elx')]
    last = elbow[-1000:]
    assert np.all(np.abs(last - VALID_ELBOW_RAD) < ELBOW_TOLERANCE_RAD), last.min()
    assert float(pelvis.position_m[pelvis.t_s >= flood_start_s, 2].min()) > 0.8
    print(f'figures: bad-command flood: {figures["sent"]} messages ({figures["rate_hz"]:.0f}/s, '
          f'{figures["bad_modes"]} bad modes) in {figures["wall_s"]:.1f} s; all refused; '
          f'{recorded} commands recorded, 0 lost; elbow held at {elbow[-1]:.3f} rad')


def test_three_publishers_at_2_khz_lose_nothing_and_keep_memory_flat(
        atlas_launch: TestLaunch) -> None:
    atlas_launch.wait_ready()
    atlas_launch.set_mode('User')
    sim_pid = atlas_launch.pid_of('atlas_sim_node.py')
    # Distinct commands: each publisher its own neck target, then a last command with another,
    # the publishers ending LAST_STAGGER_S apart: the last sent of all is the last publisher's.
    floods = [atlas_launch.start_flood('--kind', 'valid', '--rate', str(LOAD_RATE_HZ),
                                       '--elbow', str(VALID_ELBOW_RAD),
                                       '--neck', str(flood_neck_rad(k)),
                                       '--last-neck', str(last_neck_rad(k)),
                                       '--duration', str(LOAD_S + k * LAST_STAGGER_S),
                                       '--start-sim', str(START_SIM_S))
              for k in range(LOAD_PUBLISHERS)]
    atlas_launch.wait_sim_until(RSS_START_SIM_S)
    rss_start_kib = rss_kib(sim_pid)
    rss_kib_samples = []
    while any(flood.poll() is None for flood in floods):
        rss_kib_samples.append(rss_kib(sim_pid))
        time.sleep(1.0)
    figures = [flood_figures(flood, timeout_s=30.0) for flood in floods]
    atlas_launch.wait_sim_s(SETTLE_S)
    # The backlogs sent (the recorder caught up), the growth falls within the bound; a leak's
    # never does.
    deadline = time.monotonic() + DRAIN_TIMEOUT_S
    rss_end_kib = rss_kib(sim_pid)
    while rss_end_kib - rss_start_kib > RSS_GROWTH_BOUND_KIB and time.monotonic() < deadline:
        time.sleep(0.5)
        rss_end_kib = rss_kib(sim_pid)
    atlas_launch.interrupt()
    bag = atlas_launch.bag()
    data = read_bag(bag)

    sent = sum(f['sent'] for f in figures)
    recorded = count(bag, '/atlas/joint_commands')
    missing = missing_steps(data.joint_states)
    print(f'figures: load: {LOAD_PUBLISHERS} publishers at '
          f'{[round(f["rate_hz"]) for f in figures]} msg/s for {LOAD_S:.0f} s ({sent} commands); '
          f'real-time factor {[round(f["real_time_factor"], 4) for f in figures]}; '
          f'simulator RSS {rss_start_kib / 1024:.1f} -> {rss_end_kib / 1024:.1f} MiB '
          f'(max {max(rss_kib_samples) / 1024:.1f}); the recorder kept {recorded} of {sent} '
          f'commands; {missing} joint states missing')
    assert all(f['sent'] > 0 for f in figures), f'a publisher sent nothing: {figures}'
    # While it runs, a recorder starved of CPU (other work on the machine) may make the
    # simulator hold a backlog of its messages (transport.py), bounded: seen +11.7 MiB with
    # two CPU hogs beside the test (rtf 0.63), +0.1 without. After it, sent: no allowance.
    assert rss_end_kib - rss_start_kib <= RSS_GROWTH_BOUND_KIB, (
        f'the simulator kept {(rss_end_kib - rss_start_kib) / 1024:.1f} MiB after the load, '
        f'{DRAIN_TIMEOUT_S:g} s after it: a leak?')
    assert max(rss_kib_samples) - rss_start_kib <= RSS_GROWTH_BOUND_KIB + MAX_BACKLOG_BYTES // 1024
    assert all_finite(data.joint_states)
    elbow = data.joint_states.position[-1, data.joint_states.names.index('l_arm_elx')]
    assert abs(elbow - VALID_ELBOW_RAD) < ELBOW_TOLERANCE_RAD, 'the commands were applied'
    # The last command sent is the one applied: recorded last, and the neck ends nearest its
    # target of all those sent. (The merge order within one 1 ms step is test_stepping.py's:
    # with the loop merging oldest first, this test passed, the last command alone in its step.)
    expected_neck = last_neck_rad(LOAD_PUBLISHERS - 1)
    last_recorded = last_command_position(bag)
    neck = data.joint_states.position[-1, data.joint_states.names.index('neck_ay')]
    print(f'figures: load: last recorded neck_ay target {last_recorded[NECK]:.3f} rad, '
          f'neck_ay at the end {neck:.3f} rad (last sent {expected_neck:.3f})')
    assert last_recorded[NECK] == expected_neck
    targets = [f(k) for f in (flood_neck_rad, last_neck_rad) for k in range(LOAD_PUBLISHERS)]
    assert min(targets, key=lambda target: abs(neck - target)) == expected_neck, (
        f'neck_ay ends at {neck:.3f} rad, nearer another command than the last sent')
    assert abs(neck - expected_neck) < NECK_TOLERANCE_RAD, 'the last command sent was applied'
    # Nothing lost: atlas_recorder queues what it has not written yet (`rosbag record`, with
    # its 100-message queue, dropped 6-25 % of these commands; recorder:=rosbag).
    assert recorded == sent, f'the recorder lost {sent - recorded} of {sent} commands'
    assert missing == 0, f'{missing} joint states missing from the bag'
