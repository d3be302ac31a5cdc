"""`run_offline.py --asi-from IN.bag`: a recorded AtlasSimInterface session played again
offline. The session here is an offline one (DRCSim 2.7's start, a one-shot WALK of four
steps of 0.2 m at 3 s, written with its commands by write_asi_bag); played again, every
joint state must be, bit for bit, that of the simulator and the interface stepped directly
with the WALK applied before the step that starts at 3 s (a command applied a step early or
late, or another than the newest of a step's, breaks it). The command line
prints the walk's figures; a bag without AtlasSimInterface commands, or a trajectory given
too, is one line and exit 1 or 2, nothing written."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.asi import AtlasSimInterface, Behavior
from tutorial_atlas_control.bags import capture_trace, read_bag
from tutorial_atlas_control.msgs.atlas_sim_interface import (
    AsiCommand,
    ManipulateParams,
    StepData,
    decode_asi_command,
    encode_asi_command,
)
from tutorial_atlas_control.offline.asi_playback import AsiStream, write_asi_bag
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    AtlasSimulator,
    VrcMode,
    load_gains_yaml,
    load_model,
)
from tutorial_atlas_control.units import NS_PER_S
from tutorial_atlas_control.walking import straight_steps

pytestmark = pytest.mark.offline

SCRIPT = Path(__file__).resolve().parents[2] / 'scripts' / 'run_offline.py'
#: When the session's WALK is sent (s of sim time): Stand balances from 2 s.
WALK_AT_S = 3.0
#: The session lasts this long (s of sim time): the walk and its return to Stand.
SESSION_S = 7.0
#: Standing, the capture point is at least this far inside the feet (m).
STANDING_MARGIN_M = 0.03


def _walk_bytes(stamp_ns: int, behavior: int = Behavior.WALK) -> bytes:
    steps = straight_steps(4, 0.2, width_m=0.24)
    queue = tuple(StepData(s.step_index, s.foot_index, s.duration_s, (s.x_m, s.y_m, 0.0),
                           (0.0, 0.0, 0.0, 1.0), 0.0) for s in steps)
    return encode_asi_command(AsiCommand(stamp_ns, behavior, queue, False, StepData(), False,
                                         ManipulateParams(), None, 0))


@pytest.fixture(scope='module')
def session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An offline session's bag: the WALK at WALK_AT_S, sent three times in one step (the
    newest applies) and streamed again 10 ms later (a re-request changes nothing)."""
    bag = tmp_path_factory.mktemp('asi') / 'session.bag'
    at_ns = int(WALK_AT_S * NS_PER_S)
    commands = [(at_ns, _walk_bytes(at_ns, Behavior.STAND)), (at_ns, _walk_bytes(at_ns)),
                (at_ns, _walk_bytes(at_ns)), (at_ns + 10_000_000, _walk_bytes(at_ns))]
    stream = AsiStream(Path('recorded.bag'), VrcMode.BDI_STAND, commands,
                       int(SESSION_S * NS_PER_S))
    run = write_asi_bag(stream, bag, settle_s=0.0)
    assert run.commands == 2  # the newest of the first step's three, then the stream's
    return bag


def _direct_run(states: int) -> np.ndarray:
    """The session without the player: the simulator and the interface stepped here, the
    newest WALK applied before the first step that starts at WALK_AT_S, the streamed
    re-request 10 ms later; the joint positions before the first step and after each."""
    sim = AtlasSimulator(load_model(), load_gains_yaml(DEFAULT_GAINS_FILE),
                         startup_mode=VrcMode.BDI_STAND)
    interface = AtlasSimInterface(sim)
    at_ns = int(WALK_AT_S * NS_PER_S)
    due = {at_ns: _walk_bytes(at_ns), at_ns + 10_000_000: _walk_bytes(at_ns)}
    positions = [sim.joint_positions().copy()]
    while len(positions) < states:
        if sim.sim_time_ns in due:
            interface.apply(decode_asi_command(due[sim.sim_time_ns]))
        sim.step()
        interface.end_step()
        positions.append(sim.joint_positions().copy())
    return np.array(positions)


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True,
                          text=True, timeout=300, check=False)


def test_a_session_played_again_is_the_same_run(session: Path, tmp_path: Path) -> None:
    again = tmp_path / 'again.bag'
    result = _run('--asi-from', str(session), '--bag', str(again), '--settle', '0')
    assert result.returncode == 0, result.stdout + result.stderr
    lines = result.stdout.splitlines()
    taken = next(line for line in lines if line.startswith('walk: 4 of 4 steps taken; '))
    walked = float(taken.split('walked ')[1].split()[0])
    ended = float(taken.split('ended ')[1].split()[0])
    assert 0.55 < walked < 0.7 and 0.55 < ended < 0.7, taken  # four steps of 0.2 m
    assert any(line.startswith('walk: no fall (lowest pelvis 0.8') for line in lines), lines
    assert not any('did not fall' in line for line in lines), lines  # one no-fall line
    placed = next(line for line in lines if line.startswith('walk: landings '))
    worst = float(placed.split('worst placement ')[1].split()[0])
    assert worst < 5.0  # cm, the goal; measured 2.6 cm
    played = read_bag(again).joint_states
    assert played is not None
    np.testing.assert_array_equal(played.position, _direct_run(len(played.t_s)))


def test_a_bag_without_the_interface_s_commands_is_refused(tmp_path: Path) -> None:
    trajectory_run = tmp_path / 'trajectory.bag'
    made = _run('Traj_data2.yaml', 'step_and_fall', '--bag', str(trajectory_run),
                '--settle', '0')
    assert made.returncode == 0, made.stderr
    out = tmp_path / 'out.bag'
    result = _run('--asi-from', str(trajectory_run), '--bag', str(out))
    assert result.returncode == 1
    assert result.stderr.strip() == (
        f'run_offline.py: error: {trajectory_run}: holds no '
        '/atlas/atlas_sim_interface_command message to play')
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ['trajectory.bag']
    both = _run('Traj_data2.yaml', 'step_and_fall', '--asi-from', str(trajectory_run))
    assert both.returncode == 2
    assert both.stderr.splitlines()[-1] == ('run_offline.py: error: --asi-from plays a '
                                            'recorded session: give no YAML_FILE and NAME')


def test_a_behaviour_of_ones_own_that_does_not_load_is_one_line(session: Path,
                                                                 tmp_path: Path) -> None:
    out = tmp_path / 'out.bag'
    missing = tmp_path / 'mine.py'
    result = _run('--asi-from', str(session), '--bag', str(out), '--behaviour',
                  f'{missing}:Mine')
    assert result.returncode == 1
    assert result.stderr.strip() == (f"run_offline.py: error: behaviour '{missing}:Mine': "
                                     f'no file {missing}')
    assert not out.exists()
    alone = _run('Traj_data2.yaml', 'step_and_fall', '--behaviour', f'{missing}:Mine')
    assert alone.returncode == 2
    assert alone.stderr.splitlines()[-1] == ('run_offline.py: error: --behaviour serves the '
                                             'AtlasSimInterface: it needs --asi-from')


ANALYZE = Path(__file__).resolve().parents[2] / 'scripts' / 'analyze_bag.py'


def test_analyze_bag_reads_a_walk_as_a_walk(session: Path, tmp_path: Path) -> None:
    plot = tmp_path / 'walk.png'
    result = subprocess.run([sys.executable, str(ANALYZE), str(session), '--plot', str(plot)],
                            capture_output=True, text=True, timeout=300, check=False)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert 'Tracking: no joint command to track (what moved the joints was a behaviour or a ' \
           'cheat)' in lines
    assert not any('never commanded' in line for line in lines), lines
    assert any(line.startswith('walk: 4 of 4 steps taken; walked ') for line in lines), lines
    assert any(line.startswith('walk: landings ') for line in lines), lines
    assert any(line.startswith('walk: no fall') for line in lines), lines
    footprints = tmp_path / 'walk.footprints.png'
    assert footprints.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    assert f'wrote {footprints}' in result.stderr
    capture = tmp_path / 'walk.capture.png'
    assert capture.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    assert f'wrote {capture}' in result.stderr


def test_the_capture_point_leaves_the_support_polygon_only_while_it_steps(
        session: Path) -> None:
    """Standing before the walk and after it, both soles down and the capture point well
    inside them; walking, one sole down at times and the capture point outside its polygon,
    caught by the next step."""
    trace = capture_trace(read_bag(session))
    assert trace is not None
    for during in ((trace.t_s > WALK_AT_S - 0.5) & (trace.t_s < WALK_AT_S),
                   trace.t_s > SESSION_S - 0.5):
        assert (trace.soles_down[during] == 2).all()
        assert trace.margin_m[during].min() > STANDING_MARGIN_M, trace.margin_m[during].min()
    walking = trace.t_s > WALK_AT_S
    assert (trace.soles_down[walking] == 1).any()
    assert np.nanmin(trace.margin_m[walking]) < 0.0
