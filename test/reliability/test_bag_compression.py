"""atlas.launch's `compression` argument: each recorder writes the chunks it names, and every
reader of the project's bags (`rosbag info`, `rosbag play`, the analysis) still reads them.
`recorder:=rosbag` end to end: its bag, closed by the launch's SIGINT, goes through the
user's tools, `analyze_bag.py` and `replay_bag.py`, as one `atlas_recorder` wrote.

A short standing run per setting: 3 s of sim time after the launch is ready.
"""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from support.bag_checks import all_finite, missing_steps
from support.launch import TestLaunch
from support.scripts import run_script
from tutorial_atlas_control import processes, topics
from tutorial_atlas_control.bags.analysis import analyze_bag
from tutorial_atlas_control.bags.reader import BagData, read_bag
from tutorial_atlas_control.bags.records import IndexedBag, PublicBag

#: Serial: `rosbag record` drops joint states when it is starved (seen beside a busy core:
#: 56 of 4803 dropped, the replay compared the 953 steps before the first); the check
#: follows the bag it got, but a standing run of 3 s must come out whole when not starved.
pytestmark = pytest.mark.serial

#: Sim time (s) recorded after the launch is ready.
RUN_S = 3.0
#: Wall-clock guard (s) for `rosbag play` of a few seconds of bag at 20 x (and its master).
PLAY_TIMEOUT_S = 60.0
#: Wall-clock guard (s) for analyze_bag.py and replay_bag.py on a few seconds of bag.
TOOL_TIMEOUT_S = 120.0


def rosbag_info(bag: Path, key: str) -> str:
    result = subprocess.run(['rosbag', 'info', '--yaml', f'--key={key}', str(bag)],
                            capture_output=True, text=True, timeout=60, check=False)
    assert result.returncode == 0, result.stderr
    return result.stdout.strip()


def record(tmp_path: Path, recorder: str, compression: str) -> Path:
    """A standing run of RUN_S recorded by `recorder` with `compression`; its closed bag."""
    with TestLaunch(tmp_path, f'recorder:={recorder}', f'compression:={compression}') as launch:
        launch.wait_ready()
        launch.wait_sim_s(RUN_S)
        launch.interrupt()
        assert f'chunks compressed: {compression}' in launch.output()
        return launch.bag()


#: atlas_recorder with lz4, the launch's default, records every other live test's bag: read by
#: both readers (test_bag_reader.py compares them on lz4 chunks) and by `rosbag play`
#: (test_replay_live.py); here the settings no other test records with.
@pytest.mark.parametrize(('recorder', 'compression'), [
    ('atlas_recorder', 'none'), ('atlas_recorder', 'bz2'), ('rosbag', 'lz4'),
])
def test_bag_is_compressed_as_asked_and_reads_back(tmp_path: Path, recorder: str,
                                                   compression: str) -> None:
    bag = record(tmp_path, recorder, compression)

    assert rosbag_info(bag, 'compression') == compression
    assert rosbag_info(bag, 'indexed') == 'True'
    # The analysis: every 1 ms step's joint state, standing, no fall.
    data = read_bag(bag)
    assert len(data.joint_states.t_s) >= RUN_S * 1000
    assert all_finite(data.joint_states)
    if recorder == 'atlas_recorder':  # rosbag record may drop some (its 100-message queue)
        assert missing_steps(data.joint_states) == 0
    assert analyze_bag(bag).fell is False
    # The fast reader (decompressed chunks sliced by its numpy index) reads what rosbags'
    # public reader reads.
    fast, public = IndexedBag(bag), PublicBag(bag)
    fast.open()
    public.open()
    try:
        wanted = [c for c in fast.connections if c.topic == topics.JOINT_STATES]
        fast_ns, fast_raw = fast.raw_messages(wanted)
        public_ns, public_raw = public.raw_messages(
            [c for c in public.connections if c.topic == topics.JOINT_STATES])
        assert fast_ns.tolist() == public_ns.tolist()
        assert fast_raw == public_raw
    finally:
        fast.close()
        public.close()
    # rosbag play (C++ rosbag_storage) decompresses the chunks too.
    with processes.RosMaster(tmp_path / 'master.log') as master:
        master.wait_online()
        played = subprocess.run(['rosbag', 'play', '-q', '-r', '20', str(bag)], env=master.env,
                                capture_output=True, text=True, timeout=PLAY_TIMEOUT_S,
                                check=False)
    assert played.returncode == 0, played.stdout + played.stderr
    assert 'ERROR' not in played.stdout + played.stderr
    if recorder == 'rosbag':
        check_user_tools(bag, data)


def check_user_tools(bag: Path, data: BagData) -> None:
    """analyze_bag.py and replay_bag.py on the bag: exit 0, standing, replayed exactly."""
    analysed = run_script('analyze_bag.py', str(bag), '--json', timeout_s=TOOL_TIMEOUT_S)
    assert analysed.returncode == 0, analysed.stderr
    report = json.loads(analysed.stdout)
    assert report['fell'] is False
    assert report['topics'][topics.JOINT_STATES]['count'] == len(data.joint_states.t_s)
    # The pelvis at standing height (about 0.93 m pinned and after; a fall is below 0.5 m).
    assert report['min_pelvis_height'] > 0.8
    replayed = run_script('replay_bag.py', str(bag), timeout_s=TOOL_TIMEOUT_S)
    assert replayed.returncode == 0, replayed.stdout + replayed.stderr
    assert replayed.stdout.splitlines()[-1].startswith('REPRODUCED (tolerance '), replayed.stdout
    # The steps up to the bag's start (rosbag stamps a message when it hears it) are re-created
    # in Stand mode; every joint state after them is replayed from its torque and compared.
    steps = re.search(r'replayed (\d+) steps to [\d.]+ s: (\d+) before the recording re-created '
                      r'in Stand mode, (\d+) with the recorded torques', replayed.stdout)
    assert steps, replayed.stdout
    total, before, compared = (int(n) for n in steps.groups())
    assert total == before + compared
    # rosbag record drops messages when it is starved (its subscription's queue of 100):
    # the replay then stops at the first missing joint state and says so.
    stamps_ms = np.rint((data.joint_states.t_s + data.start_time_s) * 1000).astype(int)
    after = stamps_ms[stamps_ms > before]
    gaps = np.flatnonzero(np.diff(after) != 1)
    assert compared == (int(gaps[0]) + 1 if len(gaps) else len(after)) > 0
    assert ('joint state(s) missing after' in replayed.stdout) is bool(len(gaps)), replayed.stdout
    if not len(gaps):
        assert compared > (RUN_S - 0.5) * 1000
    # Same model, same MuJoCo: the replay is exact (replay_bag.py --help).
    for label, unit in (('joint positions', 'rad'), ('joint velocities', 'rad/s')):
        assert re.search(rf'^  {label} +max \|diff\| 0 {unit}, {compared} samples$',
                         replayed.stdout, re.MULTILINE), replayed.stdout
