"""What `run_demo.py NAME` plays and with which gains (trajectories/catalog.py), checked
before anything starts; and the summary's right-foot line (bags/feet.py)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.bags.feet import foot_displacement, foot_line
from tutorial_atlas_control.bags.reader import BagData, JointStateSeries, PelvisSeries
from tutorial_atlas_control.cli import run_demo, vrc_walker
from tutorial_atlas_control.cli.convention import EXIT_REFUSED
from tutorial_atlas_control.demo import demo_node as demo
from tutorial_atlas_control.demo import walk_demo_node as walk_demo
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.sim.controller import DEFAULT_GAINS_FILE, GainsError, load_gains_yaml
from tutorial_atlas_control.sim.model import load_model
from tutorial_atlas_control.trajectories.catalog import (
    GainsChoice,
    find_trajectory,
    gains_for,
    trajectory_files,
)
from tutorial_atlas_control.trajectories.trajectory import TrajectoryError, load_trajectory_file

REPO = Path(__file__).resolve().parents[3]
TUTORIAL = REPO / 'trajectories' / 'Traj_data2.yaml'
STEPPING = REPO / 'trajectories' / 'Stepping.yaml'
QUICK_STEP = REPO / 'trajectories' / 'QuickStep.yaml'
STEPPING_GAINS = REPO / 'config' / 'stepping_gains.yaml'
WAYPOINT = '  - [1, "' + ' '.join(['0'] * NUM_JOINTS) + '"]\n'


def write_trajectories(directory: Path, files: dict[str, list[str]]) -> Path:
    """`directory`/trajectories/<file> holding the given names, each one valid waypoint."""
    folder = directory / 'trajectories'
    folder.mkdir(parents=True)
    for file, names in files.items():
        (folder / file).write_text(''.join(f'{name}:\n{WAYPOINT}' for name in names))
    return folder


# --------------------------------------------------------------------------- lookup
def test_the_tutorial_file_is_searched_first(tmp_path: Path) -> None:
    folder = write_trajectories(tmp_path, {'A.yaml': ['a'], 'Traj_data2.yaml': ['t'],
                                           'Z.yaml': ['z']})
    assert [path.name for path in trajectory_files(folder)] == [
        'Traj_data2.yaml', 'A.yaml', 'Z.yaml']


def test_a_name_in_one_file_is_found_there(tmp_path: Path) -> None:
    folder = write_trajectories(tmp_path, {'Traj_data2.yaml': ['t'], 'Other.yaml': ['o']})
    assert find_trajectory('o', folder) == folder / 'Other.yaml'
    assert find_trajectory('t', folder) == folder / 'Traj_data2.yaml'


def test_a_name_in_two_files_is_refused_naming_both(tmp_path: Path) -> None:
    folder = write_trajectories(tmp_path, {'Traj_data2.yaml': ['walk'], 'Other.yaml': ['walk']})
    with pytest.raises(TrajectoryError) as caught:
        find_trajectory('walk', folder)
    assert str(caught.value) == (
        'trajectory walk is in Traj_data2.yaml and Other.yaml (searched '
        f'{folder}/Traj_data2.yaml, {folder}/Other.yaml); choose one with --file')


def test_a_name_in_no_file_is_refused_listing_the_files(tmp_path: Path) -> None:
    folder = write_trajectories(tmp_path, {'Traj_data2.yaml': ['t'], 'Other.yaml': ['o']})
    with pytest.raises(TrajectoryError) as caught:
        find_trajectory('jump', folder)
    assert str(caught.value) == (
        "no trajectory named jump in the package's trajectory files: (valid names: "
        'Traj_data2.yaml: t; Other.yaml: o); give its file with --file')


def test_a_misspelled_name_gets_a_guess_among_trajectories_and_walks(tmp_path: Path) -> None:
    folder = write_trajectories(tmp_path, {'Traj_data2.yaml': ['step_and_fall']})
    with pytest.raises(TrajectoryError) as caught:
        find_trajectory('walk_circl', folder, walks=('walk_straight', 'walk_circle'))
    assert str(caught.value) == (
        "no trajectory or walk named walk_circl in the package's trajectory files: did you mean "
        'walk_circle? (walks: walk_straight, walk_circle; valid names: Traj_data2.yaml: '
        'step_and_fall); give its file with --file')
    with pytest.raises(TrajectoryError, match='did you mean step_and_fall'):
        find_trajectory('step_and_fal', folder)


def test_the_package_names_are_where_the_readme_says() -> None:
    assert find_trajectory('step_and_fall') == TUTORIAL
    assert find_trajectory('touchdown') == TUTORIAL
    assert find_trajectory('step_and_stand') == STEPPING


# --------------------------------------------------------------------------- gains
def test_a_companion_gains_file_is_used_when_present(tmp_path: Path) -> None:
    folder = write_trajectories(tmp_path, {'Hop.yaml': ['hop'], 'Walk.yaml': ['walk']})
    (tmp_path / 'config').mkdir()
    (tmp_path / 'config' / 'hop_gains.yaml').write_text('{}')
    assert gains_for(folder / 'Hop.yaml') == GainsChoice(
        tmp_path / 'config' / 'hop_gains.yaml', 'the companion of Hop.yaml')
    assert gains_for(folder / 'Walk.yaml') == GainsChoice(DEFAULT_GAINS_FILE, "the tutorial's")
    given = tmp_path / 'mine.yaml'
    assert gains_for(folder / 'Hop.yaml', given) == GainsChoice(given, 'given with --gains-file')


def test_the_package_companions() -> None:
    assert gains_for(STEPPING).path == STEPPING_GAINS
    assert gains_for(TUTORIAL).path == DEFAULT_GAINS_FILE


@pytest.mark.parametrize(('text', 'message'), [
    (None, 'Could not read gains from {path}: No such file or directory'),
    ('a: [', 'Could not read gains from {path}: invalid YAML at line 1, column 5: expected the '
             "node content, but found '<stream end>'"),
    ('other: 1\n', '{path} has no atlas_controller/gains section; see '
                   'config/atlas_controller.yaml for the layout'),
    ('atlas_controller:\n  gains: 3\n', '{path}: atlas_controller/gains is 3, not a dictionary'),
    ('atlas_controller:\n  gains:\n    back_lbz: {p: x}\n',
     "{path}: atlas_controller/gains/back_lbz/p is 'x', not a finite number"),
    ('atlas_controller:\n  gains:\n    back_lbz: {p: 1, i: 0, d: 0, i_clamp: 0}\n',
     '{path}: atlas_controller/gains/back_mby/p is missing'),
])
def test_a_bad_gains_file_is_named_with_the_reason(tmp_path: Path, text: str | None,
                                                    message: str) -> None:
    path = tmp_path / 'gains.yaml'
    if text is not None:
        path.write_text(text)
    with pytest.raises(GainsError) as caught:
        load_gains_yaml(path)
    assert str(caught.value) == message.format(path=path)


# --------------------------------------------------------------------------- main()
class Launched:
    """Stands in for demo.run_demo / demo.summarise: records what the demo would run."""

    def __init__(self, bag: Path) -> None:
        self.bag = bag
        self.calls: list[tuple[str, Path, GainsChoice | None]] = []
        self.bag_dirs: list[Path] = []
        self.real_time_factors: list[float] = []

    def run_demo(self, trajectory: str, trajectory_file: Path, bag_dir: Path,
                 real_time_factor: float, *_args: object, gains: GainsChoice | None = None,
                 **_kwargs: object) -> Path:
        self.calls.append((trajectory, trajectory_file, gains))
        self.bag_dirs.append(bag_dir)
        self.real_time_factors.append(real_time_factor)
        return self.bag

    @staticmethod
    def summarise(*_args: object, **_kwargs: object) -> None:
        return None


@pytest.fixture
def launched(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> Launched:
    fake = Launched(tmp_path / 'run.bag')
    monkeypatch.setattr(demo, 'run_demo', fake.run_demo)
    monkeypatch.setattr(demo, 'summarise', fake.summarise)
    return fake


@pytest.mark.parametrize(('argv', 'file', 'gains'), [
    ([], TUTORIAL, GainsChoice(DEFAULT_GAINS_FILE, "the tutorial's")),
    (['step_and_stand'], STEPPING, GainsChoice(STEPPING_GAINS, 'the companion of Stepping.yaml')),
    (['quick_step'], QUICK_STEP, GainsChoice(REPO / 'config' / 'quickstep_gains.yaml',
                                             'the companion of QuickStep.yaml')),
    (['step_and_stand', '--gains-file', str(DEFAULT_GAINS_FILE)], STEPPING,
     GainsChoice(DEFAULT_GAINS_FILE, 'given with --gains-file')),
    (['touchdown', '--file', str(TUTORIAL)], TUTORIAL,
     GainsChoice(DEFAULT_GAINS_FILE, "the tutorial's")),
], ids=['default', 'step_and_stand', 'quick_step', 'gains-file wins', '--file'])
def test_main_runs_the_name_with_its_gains(launched: Launched, argv: list[str], file: Path,
                                           gains: GainsChoice) -> None:
    assert run_demo.main(argv) == 0
    assert launched.calls == [(argv[0] if argv else 'step_and_fall', file, gains)]


@pytest.mark.parametrize(('argv', 'message'), [
    (['step_and_stand', '--gains-file', '{tmp}/missing.yaml'],
     'Could not read gains from {tmp}/missing.yaml: No such file or directory'),
    (['--gains-file', '{tmp}/bad.yaml'],
     "{tmp}/bad.yaml: atlas_controller/gains/back_lbz/p is 'x', not a finite number"),
    (['jump'], "no trajectory or walk named jump in the package's trajectory files: (walks: "
               'walk_straight, walk_twenty, walk_circle, vrc_task_2, vrc_task_2_laser; valid '
               'names: Traj_data2.yaml: step_and_fall, touchdown, touchdown_exhausted; '
               f'{QUICK_STEP.name}: {", ".join(load_trajectory_file(QUICK_STEP))}; Stepping.yaml: '
               f'{", ".join(load_trajectory_file(STEPPING))}); give its file with --file'),
    (['step_and_stand', '--file', str(TUTORIAL)],
     f'unable to find trajectory step_and_stand in {TUTORIAL}; it holds: step_and_fall, '
     'touchdown, touchdown_exhausted'),
], ids=['missing gains', 'bad gains', 'unknown name', 'name not in --file'])
def test_main_refuses_before_starting_anything(launched: Launched, tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str],
                                               argv: list[str], message: str) -> None:
    (tmp_path / 'bad.yaml').write_text('atlas_controller:\n  gains:\n    back_lbz: {p: x}\n')
    status = run_demo.main([arg.format(tmp=tmp_path) for arg in argv])
    captured = capsys.readouterr()
    assert status == EXIT_REFUSED
    assert captured.err == f'run_demo.py: error: {message.format(tmp=tmp_path)}\n'
    assert captured.out == ''
    assert launched.calls == [], 'the demo started anyway'


# --------------------------------------------------------------------------- the foot
def recorded(pelvis_xyz: list[list[float]], pelvis_xyzw: list[list[float]]) -> BagData:
    """A run of two poses (t = 0 and 1 s), every joint at 0, no commands."""
    t_s = np.array([0.0, 1.0])
    joints = np.zeros((2, NUM_JOINTS))
    return BagData(
        path=Path('synthetic.bag'), start_time_s=0.0, duration_s=1.0, topics={},
        joint_states=JointStateSeries(t_s, tuple(JOINT_NAMES), joints, joints, joints),
        commands=None,
        pelvis=PelvisSeries(t_s, np.array(pelvis_xyz, dtype=float),
                            np.array(pelvis_xyzw, dtype=float), np.zeros((2, 3)),
                            np.zeros((2, 3))),
        modes=[], sim_configs=[])


def right_foot_offset_m() -> np.ndarray:
    """The right foot's position relative to the pelvis, all joints at 0, no rotation."""
    atlas = load_model()
    data = mujoco.MjData(atlas.model)
    data.qpos[atlas.free_qpos_adr:atlas.free_qpos_adr + 7] = [0, 0, 0, 1, 0, 0, 0]
    data.qpos[atlas.qpos_adr] = 0.0
    mujoco.mj_kinematics(atlas.model, data)
    return data.xpos[atlas.model.body('r_foot').id].copy()


def test_the_foot_follows_the_pelvis() -> None:
    identity = [0.0, 0.0, 0.0, 1.0]
    moved = foot_displacement(recorded([[0, 0, 0.9], [0.25, -0.05, 0.9]], [identity] * 2))
    assert moved is not None
    np.testing.assert_allclose(moved.displacement_m, [0.25, -0.05, 0.0], atol=1e-12)
    assert (moved.start_s, moved.end_s) == (0.0, 1.0)


def test_the_foot_turns_with_the_pelvis_quaternion_xyzw() -> None:
    """Half a turn about z (x y z w = 0 0 1 0) takes the right foot to the pelvis' other side:
    a quaternion read in the wrong order would turn it about another axis."""
    offset = right_foot_offset_m()
    assert offset[1] < -0.05, 'the right foot is on the right (-y)'
    moved = foot_displacement(recorded([[0, 0, 0.9]] * 2, [[0, 0, 0, 1], [0, 0, 1, 0]]))
    assert moved is not None
    np.testing.assert_allclose(moved.displacement_m, [-2 * offset[0], -2 * offset[1], 0.0],
                               atol=1e-9)


def test_the_summary_line_and_a_bag_without_pose() -> None:
    identity = [0.0, 0.0, 0.0, 1.0]
    data = recorded([[0, 0, 0.9], [0.2, 0.0, 0.9]], [identity] * 2)
    assert foot_line(data) == ('right foot moved +0.200 m forward (x), +0.000 m sideways (y), '
                               '+0.000 m up from the start (t = 0.00 s) to the end '
                               '(t = 1.00 s)')
    assert foot_line(BagData(Path('empty.bag'), 0.0, 0.0, {}, None, None, None, [], [])) is None


@pytest.mark.parametrize('text', ['-1', 'nan', 'inf', 'abc'])
def test_a_bad_real_time_factor_is_refused(launched: Launched, text: str,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    """`make demo RTF=...` passes --real-time-factor: argparse's exit 2, nothing started."""
    with pytest.raises(SystemExit) as exit_info:
        run_demo.main(['step_and_stand', '--real-time-factor', text])
    assert exit_info.value.code == 2
    assert (f"argument --real-time-factor: real time factor '{text}' is not a finite number "
            '>= 0') in capsys.readouterr().err
    assert launched.calls == []


# ------------------------------------------- `make demo RTF=...` and $TAC_BAG_DIR, end to end
def test_make_demo_passes_rtf_to_run_demo() -> None:
    """README: `make demo RTF=0.5` runs the simulator at half real time: the target's command
    (make -n: printed, not run) gives run_demo.py --real-time-factor 0.5."""
    result = subprocess.run(['make', '-n', '-C', str(REPO), 'demo', 'RTF=0.5', 'TRAJ=touchdown'],
                            capture_output=True, text=True, check=False, timeout=60)
    assert result.returncode == 0, result.stderr
    assert 'scripts/run_demo.py "touchdown" --real-time-factor "0.5"' in result.stdout


def test_run_demo_hands_the_factor_on(launched: Launched) -> None:
    assert run_demo.main(['touchdown', '--real-time-factor', '0.5']) == 0
    assert launched.real_time_factors == [0.5]


class LaunchStarted(Exception):
    """Raised by the fake AtlasLaunch: what demo.run_demo asked for is recorded, nothing runs."""


def test_the_demo_launches_the_simulator_with_the_factor(monkeypatch: pytest.MonkeyPatch,
                                                        tmp_path: Path) -> None:
    """demo.run_demo gives atlas.launch real_time_factor:=0.5 (the fake run_demo of the tests
    above would swallow it) and its bag_dir."""
    asked: list[dict[str, object]] = []

    def fake_launch(_log_path: Path, launch_args: dict[str, object], **_kwargs: object) -> None:
        asked.append(launch_args)
        raise LaunchStarted

    monkeypatch.setattr(demo, 'AtlasLaunch', fake_launch)
    with pytest.raises(LaunchStarted):
        demo.run_demo('touchdown', TUTORIAL, tmp_path / 'bags', 0.5, tmp_path / 'logs')
    assert asked[0]['real_time_factor'] == 0.5
    assert asked[0]['bag_dir'] == tmp_path / 'bags'


def test_the_demos_bag_dir_is_tac_bag_dir(launched: Launched, monkeypatch: pytest.MonkeyPatch,
                                          tmp_path: Path) -> None:
    """README: bags go to $TAC_BAG_DIR unless told otherwise (run_demo.py's default too)."""
    monkeypatch.setenv('TAC_BAG_DIR', str(tmp_path / 'elsewhere'))
    assert run_demo.main(['touchdown']) == 0
    assert launched.bag_dirs == [(tmp_path / 'elsewhere').resolve()]


@pytest.mark.parametrize(('env', 'expected'), [
    ({'TAC_BAG_DIR': '/data/bags', 'HOME': '/home/u'}, '/data/bags'),
    ({'HOME': '/home/u'}, '/home/u/.ros/tutorial_atlas_control/bags'),
])
def test_atlas_launch_bag_dir_default_is_tac_bag_dir(env: dict[str, str], expected: str,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """README: atlas.launch's bag_dir defaults to $TAC_BAG_DIR, else
    ~/.ros/tutorial_atlas_control/bags: the launch file's own expression, evaluated by
    roslaunch's substitution code."""
    import xml.etree.ElementTree as ET

    from roslaunch.substitution_args import resolve_args

    root = ET.parse(REPO / 'launch' / 'atlas.launch').getroot()
    default, = [arg.get('default') for arg in root.iter('arg') if arg.get('name') == 'bag_dir']
    monkeypatch.delenv('TAC_BAG_DIR', raising=False)
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    assert resolve_args(default, context={'arg': {}}) == expected


@pytest.mark.parametrize('walk', sorted(walk_demo.COURSE_WALKS))
def test_each_course_walk_is_a_command_line_vrc_walker_takes(walk: str) -> None:
    args = vrc_walker._parser().parse_args(list(walk_demo.COURSE_WALKS[walk][1]))
    assert args.to == 'gate_4'
    assert args.terrain == ('laser' if walk.endswith('_laser') else 'world')
