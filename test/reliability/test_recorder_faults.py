"""The recorder's faults in a running atlas.launch: killed, disk full, bag_dir.

Each injects the fault from outside, then checks what the user sees (the simulator's and
the recorder's one line, analyze_bag.py's one line and exit status) and what is recovered
after `rosbag reindex`: every step recorded, up to the last chunk written.
"""

from __future__ import annotations

import os
import re
import signal
import struct
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from support.bag_checks import missing_steps
from support.launch import STARTUP_TIMEOUT_S, TestLaunch
from tutorial_atlas_control.bags.reader import read_bag

REPO = Path(__file__).resolve().parents[2]
ANALYZE = REPO / 'scripts' / 'analyze_bag.py'
#: rosbag's default chunk threshold (bytes of messages per chunk, before compression).
CHUNK_BYTES = 768 * 1024
SIM_STOPPED = 'the recorder (/recorder) stopped at sim time '
#: Wall-clock guard (s) for a line to appear: far beyond GRACE_S on a loaded machine.
LINE_TIMEOUT_S = 60.0


def index_pos(bag: Path) -> int:
    """The bag header's index_pos: where the messages end and the index begins."""
    with bag.open('rb') as stream:
        assert stream.read(13) == b'#ROSBAG V2.0\n'
        (header_len,) = struct.unpack('<I', stream.read(4))
        header = stream.read(header_len)
    fields, offset = {}, 0
    while offset < header_len:
        (field_len,) = struct.unpack_from('<I', header, offset)
        name, _, value = header[offset + 4:offset + 4 + field_len].partition(b'=')
        fields[name] = value
        offset += 4 + field_len
    return struct.unpack('<Q', fields[b'index_pos'])[0]


def analyze(bag: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(ANALYZE), str(bag)], capture_output=True,
                          text=True, timeout=600, check=False)


def the_active_bag(launch: TestLaunch) -> Path:
    active = sorted(launch.bag_dir.glob('atlas_*.bag.active'))
    assert len(active) == 1 and not list(launch.bag_dir.glob('atlas_*.bag')), \
        f'expected one .bag.active and no .bag: {sorted(launch.bag_dir.iterdir())}'
    return active[0]


def chunk_span_s(bag: Path) -> float:
    """The median sim time one chunk of `bag` covers (s)."""
    from rosbags.rosbag1 import Reader

    with Reader(bag) as reader:
        spans = sorted(info.end_time - info.start_time for info in reader.chunk_infos)
    return spans[len(spans) // 2] * 1e-9


def recover(active: Path, hit_s: tuple[float, float], fault: str) -> float:
    """analyze_bag.py's one line on `active`, `rosbag reindex`, and what it gives back: the
    seconds of the run readable (printed beside `hit_s`: the sim times just before the fault
    and when the simulator noticed it)."""
    result = analyze(active)
    assert result.returncode == 1, result
    assert result.stderr == (
        f'analyze_bag.py: error: {active} is not indexed (an interrupted `rosbag record` leaves '
        f'an unindexed .bag.active file); run `rosbag reindex {active}` and analyze it '
        'again.\n'), result.stderr
    size = active.stat().st_size
    reindex = subprocess.run(['rosbag', 'reindex', str(active)], capture_output=True,
                             text=True, timeout=600, check=False)
    assert reindex.returncode == 0, reindex.stderr
    lost_bytes = size - index_pos(active)
    assert 0 <= lost_bytes <= CHUNK_BYTES, 'all but the last chunk, at most, is read back'
    states = read_bag(active).joint_states
    assert states is not None, 'joint states are read back'
    assert missing_steps(states) == 0, 'every step from the first recorded to the last'
    readable_s = float(states.t_s[-1])
    assert readable_s > 1.0
    assert analyze(active).returncode == 0, 'analyze_bag.py reads the reindexed bag'
    print(f'figures: {fault}: hit between sim time {hit_s[0]:.2f} and {hit_s[1]:.2f} s; '
          f'{states.t_s[0]:.3f} to {readable_s:.2f} s readable after `rosbag reindex` '
          f'(a chunk spans {chunk_span_s(active):.2f} s; {lost_bytes} bytes of the file '
          'past the last whole chunk)')
    (active.parent / (active.name.removesuffix('.active') + '.orig.active')).unlink(
        missing_ok=True)
    return readable_s


def wait_line(launch: TestLaunch, text: str) -> str:
    """Until the launch's output has a line containing `text`; that line."""
    launch.wait(lambda: text in launch.output(), LINE_TIMEOUT_S, f'no line with {text!r}')
    lines = [line for line in launch.output().splitlines() if text in line]
    assert len(lines) == 1, lines
    return lines[0]


def test_recorder_killed_with_sigkill(atlas_launch: TestLaunch) -> None:
    atlas_launch.wait_ready()
    atlas_launch.wait_sim_s(3.0)
    run_s = atlas_launch.sim_time_s()
    os.kill(atlas_launch.pid_of('atlas_recorder'), signal.SIGKILL)
    line = wait_line(atlas_launch, SIM_STOPPED)
    assert 'this run is no longer recorded (the simulation goes on)' in line
    assert '`rosbag reindex` it to read it' in line
    stopped_s = float(line.split(SIM_STOPPED)[1].split(' s:')[0])
    assert stopped_s >= run_s
    atlas_launch.wait_sim_until(stopped_s + 2.0)  # the simulator goes on, unrecorded
    atlas_launch.interrupt()
    recover(the_active_bag(atlas_launch), (run_s, stopped_s), 'recorder SIGKILL')


def test_disk_full_stops_the_recorder_with_one_line(atlas_launch: TestLaunch) -> None:
    """A file-size limit on the recorder (EFBIG, as ENOSPC: a write fails) stands for a full
    disk: no tmpfs mount is needed."""
    atlas_launch.wait_ready()
    atlas_launch.wait_sim_s(2.0)
    pid = atlas_launch.pid_of('atlas_recorder')
    active = the_active_bag(atlas_launch)
    limit = active.stat().st_size + 4 * CHUNK_BYTES
    result = subprocess.run(['prlimit', f'--pid={pid}', f'--fsize={limit}'],
                            capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    line = wait_line(atlas_launch, 'atlas_recorder: recording stopped: cannot write ')
    assert (f' to {active} (File too large); the bag holds the run up to here: '
                         f'`rosbag reindex {active}` to read it') in line, line
    assert 'terminate called' not in atlas_launch.output()
    failed_s = float(re.search(r'\[\d+\.\d+, (\d+\.\d+)\]', line).group(1))  # its sim time
    sim_line = wait_line(atlas_launch, SIM_STOPPED)
    stopped_s = float(sim_line.split(SIM_STOPPED)[1].split(' s:')[0])
    atlas_launch.wait_sim_until(stopped_s + 2.0)  # the simulator goes on, unrecorded
    atlas_launch.interrupt()
    assert active.stat().st_size <= limit
    recover(the_active_bag(atlas_launch), (failed_s, stopped_s), 'disk full (file-size limit)')


def test_bag_dir_that_cannot_be_written_is_refused_before_the_simulator_starts(
        tmp_path: Path) -> None:
    blocker = tmp_path / 'not_a_directory'
    blocker.write_text('')
    bag_dir = blocker / 'bags'
    with TestLaunch(tmp_path, f'bag_dir:={bag_dir}') as launch:
        launch.wait_exit(STARTUP_TIMEOUT_S)
        output = launch.output()
    assert (f'atlas_sim: bag_dir {bag_dir} cannot be written (Not a directory): the run would '
            'not be recorded; give a writable bag_dir:=, or record:=false') in output, output
    assert 'Atlas v1 simulator ready' not in output
    assert 'REQUIRED process [atlas_sim' in output


def test_a_launch_refused_before_the_simulator_is_ready_leaves_no_bag(tmp_path: Path) -> None:
    """The recorder started beside a simulator that refused its set-up: no empty bag left
    to become the bag tools' "newest bag", and one line saying so."""
    with TestLaunch(tmp_path, 'real_time_factor:=fast') as launch:
        launch.wait_exit(STARTUP_TIMEOUT_S)
        output = launch.output()
    assert "parameter /atlas_sim/real_time_factor must be a number >= 0.0, got 'fast'" in output
    assert (f'atlas_recorder: no message to write (the simulator never published a sim time); '
            f'no bag left in {launch.bag_dir}') in output, output
    assert list(launch.bag_dir.iterdir()) == []


@pytest.mark.optional('needs root and a tmpfs mount (a container may forbid it)')
def test_a_full_tmpfs_bag_dir_stops_the_recorder(tmp_path: Path) -> None:
    """A real full disk: a 4 MiB tmpfs as bag_dir (~3 s of a run). `rosbag reindex` cannot
    work in place there (its backup copy fails), so the line says --output-dir."""
    disk = tmp_path / 'small_disk'
    disk.mkdir()
    mounted = subprocess.run(['mount', '-t', 'tmpfs', '-o', 'size=4m', 'tmpfs', str(disk)],
                             capture_output=True, text=True, check=False)
    if mounted.returncode != 0:
        pytest.skip(f'cannot mount a tmpfs: {mounted.stderr.strip()}')
    try:
        with TestLaunch(tmp_path, f'bag_dir:={disk}') as launch:
            launch.wait_ready()
            line = wait_line(launch, 'atlas_recorder: recording stopped: cannot write ')
            active = sorted(disk.glob('atlas_*.bag.active'))[0]
            assert (f' to {active} (No space left on device); the bag holds the run up to '
                    f'here: `rosbag reindex --output-dir DIR_WITH_ROOM {active}` to read it'
                    ) in line, line
            failed_s = float(re.search(r'\[\d+\.\d+, (\d+\.\d+)\]', line).group(1))
            sim_line = wait_line(launch, SIM_STOPPED)
            stopped_s = float(sim_line.split(SIM_STOPPED)[1].split(' s:')[0])
            launch.wait_sim_until(stopped_s + 2.0)
            launch.interrupt()
        room = tmp_path / 'room'
        room.mkdir()
        reindex = subprocess.run(['rosbag', 'reindex', '--output-dir', str(room), str(active)],
                                 capture_output=True, text=True, timeout=600, check=False)
        assert reindex.returncode == 0, reindex.stderr
        states = read_bag(room / active.name).joint_states
        assert states is not None and missing_steps(states) == 0
        print(f'figures: full 4 MiB tmpfs: write failed at sim {failed_s:.2f} s; '
              f'{states.t_s[0]:.3f} to {states.t_s[-1]:.2f} s readable after '
              '`rosbag reindex --output-dir`')
    finally:
        subprocess.run(['umount', '-l', str(disk)], check=False)
