"""Offline replay against recordings made in-process with AtlasSimulator, and its errors."""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest

from support.synthetic_bags import TYPESTORE, Record, joint_state, write_bag
from tutorial_atlas_control.bags.reader import read_bag
from tutorial_atlas_control.cli.replay_bag import EXIT_DEVIATES, main
from tutorial_atlas_control.errors import BagAnalysisError
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.offline.replay import (
    ReplayError,
    format_report,
    load_recording,
    replay,
    replay_bag,
)
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim import vrc
from tutorial_atlas_control.sim.controller import DEFAULT_GAINS_FILE, hold_command, load_gains_yaml
from tutorial_atlas_control.sim.joint_trajectory import TrajectoryMessage, trajectory_input
from tutorial_atlas_control.sim.sim_config import SimConfig
from tutorial_atlas_control.sim.simulator import AtlasSimulator, ControlMode

SCRIPT = Path(__file__).resolve().parents[3] / 'scripts' / 'replay_bag.py'
#: Short pin so that unpinning happens inside the short synthetic runs (s).
TIME_TO_UNPIN_S = 0.05
#: Odometry every this many steps, as the simulator's 100 Hz default.
ODOM_EVERY = 10


def _t(name: str) -> Any:
    return TYPESTORE.types[name]


def odometry_record(t_s: float, position: np.ndarray, quat_wxyz: np.ndarray) -> Record:
    """A /ground_truth_odom message with the exact pelvis pose (float64)."""
    w, x, y, z = (float(v) for v in quat_wxyz)
    stamp_ns = round(t_s * 1e9)
    header = _t('std_msgs/msg/Header')(
        seq=0, stamp=_t('builtin_interfaces/msg/Time')(sec=stamp_ns // 10**9,
                                                       nanosec=stamp_ns % 10**9),
        frame_id='world')
    vector = _t('geometry_msgs/msg/Vector3')
    pose = _t('geometry_msgs/msg/PoseWithCovariance')(
        pose=_t('geometry_msgs/msg/Pose')(
            position=_t('geometry_msgs/msg/Point')(x=float(position[0]), y=float(position[1]),
                                                    z=float(position[2])),
            orientation=_t('geometry_msgs/msg/Quaternion')(x=x, y=y, z=z, w=w)),
        covariance=np.zeros(36))
    twist = _t('geometry_msgs/msg/TwistWithCovariance')(
        twist=_t('geometry_msgs/msg/Twist')(linear=vector(x=0.0, y=0.0, z=0.0),
                                            angular=vector(x=0.0, y=0.0, z=0.0)),
        covariance=np.zeros(36))
    msg = _t('nav_msgs/msg/Odometry')(header=header, child_frame_id='pelvis', pose=pose,
                                      twist=twist)
    return Record('/ground_truth_odom', 'nav_msgs/Odometry', t_s, msg)


def sim_config_record(t_s: float, config: dict[str, object] | SimConfig) -> Record:
    text = config.to_json() if isinstance(config, SimConfig) else json.dumps(config)
    msg = _t('std_msgs/msg/String')(data=text)
    return Record('/atlas/sim_config', 'std_msgs/String', t_s, msg)


@dataclass
class Run:
    """Drives an AtlasSimulator like sim_node does and records what it publishes."""

    time_to_unpin_s: float = TIME_TO_UNPIN_S
    record_from_step: int = 1
    with_config: bool = True
    records: list[Record] = field(default_factory=list)
    #: Records before a reset_simulation, in record order.
    earlier: list[Record] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.atlas = atlas_model.load_model()
        self.sim = AtlasSimulator(self.atlas, load_gains_yaml(DEFAULT_GAINS_FILE),
                                  self.time_to_unpin_s)
        self.steps = 0
        self._publish_config()

    def _t_s(self) -> float:
        return self.sim.sim_time_ns / 1e9

    def _publish_config(self) -> None:
        # Latched: the recorder gets it when it starts, stamped with the time it arrived.
        if self.with_config:
            self.records.append(sim_config_record(
                max(self._t_s(), self.record_from_step / 1000.0), self.sim.config()))

    def step(self, count: int, before: Callable[[AtlasSimulator, int], None] | None = None) -> None:
        sim = self.sim
        for _ in range(count):
            if before is not None:
                before(sim, self.steps)
            sim.step()
            self.steps += 1
            if self.steps < self.record_from_step:
                continue
            t_s = self._t_s()
            self.records.append(joint_state(t_s, sim.joint_positions(), sim.joint_velocities(),
                                            sim.torque_nm.copy(), seq=self.steps))
            if self.steps % ODOM_EVERY == 0:
                body = self.atlas.pelvis_body_id
                # As the simulator node: poses describe the step's start (state_time_ns).
                self.records.append(odometry_record(sim.state_time_ns / 1e9,
                                                    sim.data.xpos[body].copy(),
                                                    sim.data.xquat[body].copy()))

    def reset_world(self) -> None:
        self.sim.reset_world()
        self._publish_config()

    def reset_simulation(self) -> None:
        """Sim time back to 0: the records so far come first in the bag (record order)."""
        self.sim.reset_simulation()
        self.earlier += sorted(self.records, key=lambda record: record.t_s)
        self.records = []
        self._publish_config()

    def write(self, path: Path) -> Path:
        if self.earlier:
            return write_bag(path, self.earlier + sorted(self.records, key=lambda r: r.t_s),
                             in_given_order=True)
        return write_bag(path, self.records)


def crouch(sim: AtlasSimulator, step: int, user_step: int = 20, bend_step: int = 40) -> None:
    """User mode from `user_step`, knees and hips bent from `bend_step`: the robot moves."""
    if step == user_step:
        sim.set_mode(ControlMode.USER)
    if step == bend_step:
        target = np.zeros(NUM_JOINTS)
        for side in 'lr':
            target[JOINT_NAMES.index(f'{side}_leg_lhy')] = -0.6
            target[JOINT_NAMES.index(f'{side}_leg_kny')] = 1.2
            target[JOINT_NAMES.index(f'{side}_leg_uay')] = -0.6
        command = hold_command(sim.gains, target)
        sim.receive_command(list(JOINT_NAMES), {'position': command.position,
                                                'kp_position': command.kp_position,
                                                'kd_position': command.kd_position})


@pytest.fixture(scope='module')
def full_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """200 steps, every one recorded, unpinned at 50 ms, crouching."""
    run = Run()
    run.step(200, crouch)
    return run.write(tmp_path_factory.mktemp('replay') / 'full.bag')


def test_full_recording_replays_exactly(full_run: Path) -> None:
    result = replay_bag(full_run)
    assert result.reconstructed_steps == 0
    assert result.recorded_steps == 200
    assert result.joint_position.max_abs == 0.0
    assert result.joint_velocity.max_abs == 0.0
    assert result.pelvis_position is not None and result.pelvis_position.max_abs == 0.0
    assert result.pelvis_orientation is not None and result.pelvis_orientation.max_abs == 0.0
    assert result.pelvis_position.samples == 20
    assert result.model_sha1_matches is True
    assert result.reproduced and not result.warnings
    assert result.end_time_s == 0.2


def test_late_recording_recreates_the_stand_prefix(tmp_path: Path) -> None:
    """The recorder starts at step 30, still in Stand and before the torso is released."""
    run = Run(record_from_step=30)
    run.step(150, lambda sim, step: crouch(sim, step, user_step=40, bend_step=60))
    result = replay_bag(run.write(tmp_path / 'late.bag'))
    assert result.reconstructed_steps == 29 and result.recorded_steps == 121
    assert result.joint_position.max_abs == 0.0 and result.pelvis_position.max_abs == 0.0
    assert result.reproduced and not result.warnings


def test_leaving_stand_before_the_recording_is_reported(tmp_path: Path) -> None:
    run = Run(record_from_step=60)
    run.step(150, crouch)  # User mode at step 20, unseen by the recorder
    result = replay_bag(run.write(tmp_path / 'mode.bag'))
    assert any('differs by up to' in text and 'Stand-mode law' in text for text in result.warnings)


def test_mid_run_reset_replays_the_last_segment(tmp_path: Path) -> None:
    run = Run()
    run.step(120, crouch)
    run.reset_world()
    run.step(100)
    result = replay_bag(run.write(tmp_path / 'reset.bag'))
    assert result.start_time_s == 0.12 and result.resets_in_bag == 1
    assert result.recorded_steps == 100 and result.reconstructed_steps == 0
    assert result.joint_position.max_abs == 0.0 and result.pelvis_position.max_abs == 0.0
    assert any('1 reset(s); replaying the last segment' in text for text in result.warnings)
    assert result.reproduced


@pytest.fixture(scope='module')
def three_tries(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Crouch 120 steps; reset_world; 100 steps; reset_simulation; crouch 150 steps."""
    run = Run()
    run.step(120, crouch)
    run.reset_world()
    run.step(100, lambda sim, step: crouch(sim, step, user_step=10_000, bend_step=150))
    run.reset_simulation()
    run.steps = 0
    run.step(150, lambda sim, step: crouch(sim, step, user_step=10_000, bend_step=40))
    return run.write(tmp_path_factory.mktemp('replay') / 'tries.bag')


@pytest.mark.parametrize(('number', 'start_s', 'steps', 'end_s'), [
    (1, 0.0, 120, 0.12), (2, 0.12, 100, 0.22), (3, 0.0, 150, 0.15), (None, 0.0, 150, 0.15)])
def test_any_try_replays_exactly(three_tries: Path, number: int | None, start_s: float,
                                 steps: int, end_s: float) -> None:
    result = replay_bag(three_tries, try_number=number)
    assert (result.try_number, result.tries) == (number or 3, 3)
    assert result.start_time_s == start_s and result.end_time_s == pytest.approx(end_s)
    assert result.recorded_steps == steps and result.reconstructed_steps == 0
    assert result.joint_position.max_abs == 0.0 and result.joint_velocity.max_abs == 0.0
    assert result.pelvis_position is not None and result.pelvis_position.max_abs == 0.0
    assert result.pelvis_position.samples == steps // ODOM_EVERY
    assert result.reproduced and result.resets_in_bag == 2
    # The reset warning only when the try was not asked for (the report names the try).
    warned = [text for text in result.warnings if 'reset(s); replaying' in text]
    assert warned == ([] if number is not None else [
        'the bag holds 2 reset(s); replaying the last segment, from the reset at 0.000 s '
        '(sim time).'])


def test_try_that_does_not_exist_is_one_line(three_tries: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(three_tries), '--try', '4']) == 1
    assert capsys.readouterr().err == (f'replay_bag.py: error: {three_tries} holds 3 tries '
                                       '(1..3); there is no try 4.\n')


def test_bag_without_sim_config_is_refused_unless_defaults_are_assumed(tmp_path: Path) -> None:
    run = Run(time_to_unpin_s=1.0, with_config=False)
    run.step(60)
    bag = run.write(tmp_path / 'old.bag')
    with pytest.raises(ReplayError, match='has no /atlas/sim_config .*--assume-defaults'):
        replay_bag(bag)
    result = replay_bag(bag, assume_defaults=True)
    assert not result.config.recorded and result.config.time_to_unpin_s == 1.0
    assert result.model_sha1_matches is None
    assert result.joint_position.max_abs == 0.0
    assert any('no /atlas/sim_config' in text for text in result.warnings)


def test_wrong_pin_time_shows_as_a_deviation(tmp_path: Path) -> None:
    run = Run(with_config=False)  # really 0.05 s, but replay assumes the default 1 s
    run.step(200, crouch)
    result = replay_bag(run.write(tmp_path / 'pin.bag'), assume_defaults=True)
    assert not result.reproduced
    assert result.pelvis_position.max_abs > 1e-4
    assert result.joint_position.time_s is not None and result.joint_position.joint in JOINT_NAMES


def test_dropped_message_stops_the_replay_there(tmp_path: Path) -> None:
    run = Run()
    run.step(100)
    run.records = [r for r in run.records
                   if not (r.topic == '/atlas/joint_states' and round(r.t_s * 1000) == 71)]
    result = replay_bag(run.write(tmp_path / 'gap.bag'))
    assert result.recorded_steps == 70 and result.end_time_s == 0.07
    assert any('1 joint state(s) missing after 0.070 s' in text for text in result.warnings)
    assert result.joint_position.max_abs == 0.0


def test_without_odometry_only_joints_are_compared(tmp_path: Path) -> None:
    run = Run()
    run.step(30)
    run.records = [r for r in run.records if r.topic != '/ground_truth_odom']
    result = replay_bag(run.write(tmp_path / 'noodom.bag'))
    assert result.pelvis_position is None and result.joint_position.max_abs == 0.0
    assert 'pelvis position      not compared' in format_report(result)


# ---------------------------------------------------------------------------- errors


def test_divergence_in_the_replay_is_an_error(tmp_path: Path) -> None:
    """The simulator's own divergence check runs in the replay and names what happened."""
    run = Run()
    run.step(60)
    state = next(record for record in run.records[::-1] if record.topic == '/atlas/joint_states')
    state.message.effort[:] = 1e9  # a torque no step survives
    with pytest.raises(ReplayError, match=r'in the replay, physics diverged at t=0\.060 s .*'
                                          r'the bag does not mark'):
        replay_bag(run.write(tmp_path / 'diverging.bag'))


def test_no_joint_states_is_an_error(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / 'x.bag', [sim_config_record(0.0, {'timestep': 0.001,
                                                                'time_to_unpin': 1.0,
                                                                'last_reset_time': 0.0})])
    with pytest.raises(ReplayError, match=r'has no /atlas/joint_states: the replay needs'):
        load_recording(bag)


def test_missing_joint_is_an_error(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / 'x.bag', [
        joint_state(0.001, np.zeros(27), names=JOINT_NAMES[:27])])
    with pytest.raises(ReplayError, match=r'lacks joints r_arm_mwx; the replay needs'):
        load_recording(bag, assume_defaults=True)


def test_sim_time_going_backwards_is_unsupported(tmp_path: Path) -> None:
    records = [joint_state(t_s, np.zeros(NUM_JOINTS), seq=i)
               for i, t_s in enumerate((0.001, 0.002, 0.003))]
    records.append(joint_state(0.001, np.zeros(NUM_JOINTS)))
    records[-1] = Record(records[-1].topic, records[-1].msgtype, 0.004, records[-1].message)
    bag = write_bag(tmp_path / 'x.bag', records)
    with pytest.raises(ReplayError, match=r'go backwards or repeat at 0.001 s .*reset_simulation'):
        replay_bag(bag, assume_defaults=True)


def test_late_recording_after_a_reset_is_unsupported(tmp_path: Path) -> None:
    run = Run()
    run.step(50)
    run.reset_world()
    run.step(50)
    # Drop the first states after the reset: their torques are then unknown.
    run.records = [r for r in run.records
                   if not (r.topic == '/atlas/joint_states' and 0.05 < r.t_s < 0.06)]
    with pytest.raises(ReplayError, match=r'starts 9 steps after the reset at 0.050 s'):
        replay_bag(run.write(tmp_path / 'x.bag'))


def test_off_grid_stamps_are_an_error(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / 'x.bag', [joint_state(0.0015, np.zeros(NUM_JOINTS))])
    with pytest.raises(ReplayError, match=r'0.001500000 s is not a multiple of the timestep'):
        replay_bag(bag, assume_defaults=True)


def test_other_timestep_is_an_error(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / 'x.bag', [
        sim_config_record(0.0, {'timestep': 0.002, 'time_to_unpin': 1.0, 'last_reset_time': 0.0}),
        joint_state(0.002, np.zeros(NUM_JOINTS))])
    with pytest.raises(ReplayError, match=r'simulated with timestep 0.002 s but atlas_v1.xml has'):
        replay_bag(bag)


def test_bad_sim_config_is_an_error(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / 'x.bag', [
        sim_config_record(0.0, {'timestep': 0.001}), joint_state(0.001, np.zeros(NUM_JOINTS))])
    with pytest.raises(ReplayError, match=r"sim_config lacks a valid 'time_to_unpin'"):
        load_recording(bag)


@pytest.mark.parametrize(('text', 'reason'), [('{"timestep": 0.001', 'is not JSON'),
                                               ('[0.001]', 'is not a JSON object')])
def test_unparsable_sim_config_is_an_error(tmp_path: Path, text: str, reason: str) -> None:
    message = _t('std_msgs/msg/String')(data=text)
    config = Record('/atlas/sim_config', 'std_msgs/String', 0.0, message)
    bag = write_bag(tmp_path / 'x.bag', [config, joint_state(0.001, np.zeros(NUM_JOINTS))])
    with pytest.raises(ReplayError, match=rf'x\.bag: /atlas/sim_config {reason}'):
        load_recording(bag)


def test_recording_comes_from_one_reading_of_the_bag(full_run: Path, tmp_path: Path) -> None:
    """Given the BagData, load_recording does not open the bag again for /atlas/sim_config."""
    bag = tmp_path / 'once.bag'
    shutil.copy(full_run, bag)
    data = read_bag(bag)
    bag.unlink()
    recording = load_recording(bag, data)
    assert recording.config.recorded
    assert recording.config.time_to_unpin_s == TIME_TO_UNPIN_S


def test_not_a_bag_is_an_error(tmp_path: Path) -> None:
    (tmp_path / 'x.bag').write_text('hello')
    with pytest.raises(BagAnalysisError, match=r'is not a ROS 1 bag'):
        replay_bag(tmp_path / 'x.bag')


# ---------------------------------------------------------------------------- command line


def test_cli_text_and_json(full_run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(full_run)]) == 0
    out = capsys.readouterr().out
    assert 'joint positions      max |diff| 0 rad, 200 samples' in out
    assert out.rstrip().endswith('REPRODUCED (tolerance 1e-06)')
    assert main([str(full_run), '--json']) == 0
    result = json.loads(capsys.readouterr().out)
    assert result['reproduced'] is True and result['joint_position']['max'] == 0.0
    assert result['sim_config']['time_to_unpin'] == TIME_TO_UNPIN_S
    assert result['recorded_steps'] == 200 and result['pelvis_orientation']['samples'] == 20


def test_cli_deviation_exit_status(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    run = Run(with_config=False)
    run.step(200, crouch)
    assert main([str(run.write(tmp_path / 'pin.bag')), '--assume-defaults']) == EXIT_DEVIATES
    assert 'DEVIATES (tolerance 1e-06)' in capsys.readouterr().out


def test_script_errors_are_one_line(tmp_path: Path) -> None:
    env = {key: value for key, value in os.environ.items() if key != 'PYTHONPATH'}
    done = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path / 'none.bag')],
                          capture_output=True, text=True, env=env, cwd='/', check=False,
                          timeout=120)
    assert done.returncode == 1
    assert done.stderr.strip().splitlines() == [f'replay_bag.py: error: {tmp_path}/none.bag: '
                                                'no such file.']


@pytest.mark.parametrize('value', ['nan', '-1', 'abc'])
def test_bad_tolerance_is_a_usage_error(value: str, capsys: pytest.CaptureFixture[str]) -> None:
    """Exit 2, as argparse for any bad argument (the epilog says so)."""
    with pytest.raises(SystemExit) as exit_info:
        main(['x.bag', '--tolerance', value])
    assert exit_info.value.code == 2
    assert capsys.readouterr().err.splitlines()[-1].startswith(
        'replay_bag.py: error: argument --tolerance: ')


def test_debug_test_messages_are_reported(tmp_path: Path) -> None:
    """/atlas/debug/test's damping changes the model, which the torques do not carry."""
    from rosbags.typesys import get_types_from_msg

    from support.synthetic_bags import TYPESTORE
    from tutorial_atlas_control.resources import message_file

    if 'atlas_msgs/msg/Test' not in TYPESTORE.fielddefs:
        TYPESTORE.register(get_types_from_msg(message_file('atlas_msgs', 'Test').read_text(),
                                              'atlas_msgs/msg/Test'))
    run = Run()
    run.step(60)
    header = _t('std_msgs/msg/Header')(
        seq=0, stamp=_t('builtin_interfaces/msg/Time')(sec=0, nanosec=30_000_000), frame_id='')
    empty32 = np.zeros(0, dtype=np.float32)
    message = _t('atlas_msgs/msg/Test')(
        header=header, damping=np.full(NUM_JOINTS, 0.5, dtype=np.float32), kp_position=empty32,
        ki_position=empty32, kd_position=empty32, kp_velocity=empty32, i_effort_min=empty32,
        i_effort_max=empty32, k_effort=np.zeros(0, dtype=np.uint8))
    run.records.append(Record('/atlas/debug/test', 'atlas_msgs/Test', 0.03, message))
    result = replay_bag(run.write(tmp_path / 'test.bag'))
    assert ('the run has 1 /atlas/debug/test message(s): joint damping they set is not '
            're-applied offline, so the replay deviates from the first that set it.'
            in result.warnings)


# -- VRCPlugin's inputs: re-applied from /atlas/sim_inputs at the same steps ----------------

def _apply(run: Run, item: vrc.SimInput, logged: bool = True) -> None:
    """What SteppingLoop.apply_input does: apply between steps, publish the event."""
    run.sim.apply_input(item)
    if logged:
        msg = _t('std_msgs/msg/String')(data=run.sim.last_input_event().to_json())
        run.records.append(Record('/atlas/sim_inputs', 'std_msgs/String',
                                  max(run._t_s(), 0.001), msg))


def _pose(position: tuple[float, float, float], yaw: float) -> vrc.PoseInput:
    return vrc.pose_input(position, (0.0, 0.0, np.sin(yaw / 2), np.cos(yaw / 2)))


ATLAS = atlas_model.load_model()
#: Per input kind, what is applied before which step (time_to_unpin is 50 ms).
INPUT_SCRIPTS: dict[str, dict[int, list[vrc.SimInput]]] = {
    'pelvis_force': {100: [vrc.wrench_input((300, 0, 0), (0, 0, 20))],
                     250: [vrc.wrench_input((0, 0, 0), (0, 0, 0))]},
    'set_pose': {100: [_pose((0.5, 0.2, 1.0), 0.3)]},
    'modes': {
        60: [vrc.ModeInput(vrc.VrcMode.NO_GRAVITY)], 110: [vrc.ModeInput(vrc.VrcMode.FEET)],
        160: [vrc.ModeInput(vrc.VrcMode.HARNESSED)],
        210: [vrc.ModeInput(vrc.VrcMode.PINNED_WITH_GRAVITY)],
        260: [vrc.ModeInput(vrc.VrcMode.PINNED)], 310: [vrc.ModeInput(vrc.VrcMode.NOMINAL)],
        360: [vrc.ModeInput(vrc.VrcMode.BDI_STAND)]},
    'cmd_vel': {80: [vrc.ModeInput(vrc.VrcMode.PINNED)],
                100: [vrc.cmd_vel_input((0.3, 0.1, 0.0), (0.0, 0.0, 0.5))],
                300: [vrc.cmd_vel_input((0, 0, 0), (0, 0, 0)), vrc.ModeInput(vrc.VrcMode.NOMINAL)]},
    'joint_trajectory': {100: [trajectory_input(TrajectoryMessage(
        'world', 0, ('l_arm_shx', 'r_leg_kny', 'back_mby'),
        ((-0.4, 0.2, 0.1), (-0.8, 0.5, 0.2), (-0.2, 0.3, 0.0)), (0, 20_000_000, 50_000_000)),
        ATLAS.lower_rad, ATLAS.upper_rad)]},
    'joint_trajectory_in_a_foot_frame': {100: [trajectory_input(TrajectoryMessage(
        'l_foot', 0, ('l_leg_lhy', 'l_leg_kny', 'l_leg_uay'), ((-0.3, 0.6, -0.3),), (0,)),
        ATLAS.lower_rad, ATLAS.upper_rad, ('l_foot',))]},
}


def _scripted_run(script: dict[int, list[vrc.SimInput]], logged: bool = True) -> Run:
    run = Run()

    def before(sim: AtlasSimulator, step: int) -> None:
        crouch(sim, step)
        for item in script.get(step, []):
            _apply(run, item, logged)
    run.step(450, before)
    return run


@pytest.mark.parametrize('kind', sorted(INPUT_SCRIPTS))
def test_runs_with_vrc_inputs_replay_bit_exactly(kind: str, tmp_path: Path) -> None:
    bag = _scripted_run(INPUT_SCRIPTS[kind]).write(tmp_path / f'{kind}.bag')
    recording = load_recording(bag)
    assert len(recording.inputs) == sum(len(items) for items in INPUT_SCRIPTS[kind].values())
    result = replay(recording)
    assert result.joint_position.max_abs == 0.0 and result.joint_velocity.max_abs == 0.0
    assert result.pelvis_position.max_abs == 0.0 and result.pelvis_orientation.max_abs == 0.0
    assert result.reproduced and not result.warnings
    # and the inputs matter: without them the replay strays
    blind = replay(dataclasses.replace(recording, inputs=[]))
    assert blind.pelvis_position.max_abs > 1e-3 or blind.joint_position.max_abs > 1e-3


def test_a_missing_input_refuses_the_replay(tmp_path: Path) -> None:
    run = Run()
    run.step(50)
    _apply(run, vrc.wrench_input((50, 0, 0), (0, 0, 0)), logged=False)  # recorder not there yet
    run.step(20)
    _apply(run, vrc.wrench_input((0, 0, 0), (0, 0, 0)))
    run.step(20)
    with pytest.raises(ReplayError, match=r'lacks /atlas/sim_inputs input #0 after the reset at '
                                          r'0\.000 s \(the recorder started after it or '
                                          r'dropped it\); the run cannot be replayed exactly\.$'):
        load_recording(run.write(tmp_path / 'missing.bag'))


def test_inputs_before_a_reset_are_not_replayed(tmp_path: Path) -> None:
    run = Run()
    run.step(60, lambda sim, step: step == 30 and _apply(run, vrc.ModeInput(
        vrc.VrcMode.NO_GRAVITY)))
    run.reset_world()
    run.step(80, lambda sim, step: step == 100 and _apply(run, _pose((0, 0, 1.2), 0.0)))
    recording = load_recording(run.write(tmp_path / 'reset.bag'))
    assert [event.seq for event in recording.inputs] == [0]
    assert replay(recording).joint_position.max_abs == 0.0


def test_startup_mode_comes_from_sim_config(tmp_path: Path) -> None:
    run = Run()
    run.sim = AtlasSimulator(run.atlas, load_gains_yaml(DEFAULT_GAINS_FILE), TIME_TO_UNPIN_S,
                             startup_mode=vrc.VrcMode.PINNED)
    run.records.clear()
    run._publish_config()
    run.step(150, crouch)
    result = replay_bag(run.write(tmp_path / 'pinned_start.bag'))
    assert result.config.startup_mode == 'pinned'
    assert result.joint_position.max_abs == 0.0 and result.pelvis_position.max_abs == 0.0


# -- a scored run: the VRC course's score computed again on the replayed steps --------------

#: Before which step the pelvis is put where (x, y; 1 m up): through gate_0, then gate_1.
GATE_TELEPORTS = {100: (0.7, -38.0), 200: (1.3, -38.0), 300: (0.0, -22.3), 400: (0.0, -21.7)}


def _scored_run() -> Run:
    """A run whose scoring publishes /vrc_score as the node's does (after each step)."""
    from tutorial_atlas_control.stepping.course_scoring import CourseScoring

    run = Run()
    stamp = _t('builtin_interfaces/msg/Time')

    def emit(row: Any) -> None:
        times = [stamp(sec=ns // 10**9, nanosec=ns % 10**9) for ns in (
            row.wall_elapsed_ns, row.sim_time_ns, row.wall_since_gate0_ns,
            row.sim_since_gate0_ns)]
        message = _t('atlas_msgs/msg/VRCScore')(*times, completion_score=row.completion,
                                                 falls=row.falls, message=row.message,
                                                 task_type=row.task_type)
        run.records.append(Record('/vrc_score', 'atlas_msgs/VRCScore', row.sim_time_ns / 1e9,
                                  message))

    scoring = CourseScoring(run.sim, None, emit, wall_clock=lambda: run.sim.sim_time_ns)

    def before(sim: AtlasSimulator, step: int) -> None:
        if step:
            scoring()  # after the step before (nothing happened since)
        if step in GATE_TELEPORTS:
            _apply(run, vrc.pose_input((*GATE_TELEPORTS[step], 1.0), (0.0, 0.0, 0.0, 0.0)))
    run.step(1200, before)
    return run


def test_a_scored_run_scores_the_same_in_replay(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    bag = _scored_run().write(tmp_path / 'scored.bag')
    result = replay(load_recording(bag))
    assert result.score is not None and result.score.same, result.score
    assert (result.score.recorded_rows, result.score.completion) == (2, 1)
    assert result.reproduced
    assert main([str(bag)]) == 0
    assert ('  VRC score            2 rows recorded, 2 replayed (completion 1, falls 0): the same'
            in capsys.readouterr().out)


def test_a_score_the_replay_does_not_give_deviates(tmp_path: Path) -> None:
    run = _scored_run()
    rows = [record for record in run.records if record.topic == '/vrc_score']
    rows[1].message.completion_score = 2
    result = replay(load_recording(run.write(tmp_path / 'changed.bag')))
    assert result.score is not None and not result.reproduced
    assert result.score.first_difference == (
        "row 2: recorded 0.401 s completion 2 falls 0 'Successfully passed through gate 2. ', "
        "replayed 0.401 s completion 1 falls 0 'Successfully passed through gate 2. '")
