"""analyze_bag.py A.bag --compare B.bag on two synthetic runs whose differences are known."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from support.synthetic_bags import (
    clock,
    control_mode,
    joint_commands,
    joint_state,
    odometry,
    rosout,
    write_bag,
)
from tutorial_atlas_control.bags.analysis import analyze_bag
from tutorial_atlas_control.bags.compare import (
    compare_analyses,
    compare_bags,
    first_applied_command_s,
)
from tutorial_atlas_control.cli.analyze_bag import main
from tutorial_atlas_control.errors import BagAnalysisError
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.trajectories.schedule import trajectory_log_line

REPO = Path(__file__).resolve().parents[3]
ELX = JOINT_NAMES.index('l_arm_elx')


def _with_elx(value: float) -> np.ndarray:
    position = np.zeros(NUM_JOINTS)
    position[ELX] = value
    return position


def run_records(start_s: float, measured_rad: float, commanded_rad: float, standing_m: float,
                fall_s: float, end_s: float, name: str) -> list:
    """User mode and commands from `start_s` (1 s at 50 Hz; l_arm_elx steps up 0.2 rad half
    way), l_arm_elx measured `measured_rad` throughout, states and odometry every 10 ms, the
    pelvis at `standing_m` until `fall_s`, then 0.3 m."""
    records = [clock(0.0), control_mode(0.0, 'Stand'), control_mode(start_s, 'User'),
               rosout(start_s, trajectory_log_line('/data/Traj.yaml', name))]
    for k in range(50):
        step_rad = 0.2 if k >= 25 else 0.0
        records.append(joint_commands(round(start_s + 0.02 * k, 6),
                                      _with_elx(commanded_rad + step_rad)))
    for t_s in np.round(np.arange(0.0, end_s + 1e-9, 0.01), 6):
        records.append(joint_state(float(t_s), _with_elx(measured_rad)))
        records.append(odometry(float(t_s), standing_m if t_s < fall_s else 0.3))
    return records


@pytest.fixture(scope='module')
def bags(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    directory = tmp_path_factory.mktemp('compare')
    a = write_bag(directory / 'a.bag', run_records(1.0, 0.25, 0.2, 0.9, 2.0, 3.0, 'step'))
    # B: 0.5 s later, 0.1 rad further and commanded 0.05 rad further, 2 cm lower, falls
    # 0.2 s later after its command; a command before User mode does not count as applied.
    b_records = run_records(1.5, 0.35, 0.25, 0.88, 2.7, 3.5, 'step')
    b_records.append(joint_commands(0.5, _with_elx(9.9)))
    b = write_bag(directory / 'b.bag', b_records)
    return a, b


#: Pelvis A - B, at A's odometry from its first command (0.00 .. 2.00 s, 201 samples):
#: 0.02 m for 100 samples, 0.3 - 0.88 for 20 (A fell, B not yet), 0 for 81.
PELVIS_RMS_M = math.sqrt((100 * 0.02 ** 2 + 20 * 0.58 ** 2) / 201)


def test_known_differences(bags: tuple[Path, Path]) -> None:
    comparison = compare_bags(*bags)
    doc = comparison.to_dict()
    assert set(doc) == {'a', 'b', 'aligned_on', 'joints', 'pelvis_height_rms_diff',
                        'fall_time_a', 'fall_time_b'}
    assert doc['aligned_on']['time_a'] == pytest.approx(1.0, abs=1e-9)
    assert doc['aligned_on']['time_b'] == pytest.approx(1.5, abs=1e-9)
    assert doc['aligned_on']['window'] == pytest.approx([0.0, 2.0], abs=1e-9)
    assert set(doc['joints']) == set(JOINT_NAMES)
    elx = doc['joints']['l_arm_elx']
    assert set(elx) == {'rms_diff', 'max_diff', 'command_rms_diff'}
    assert elx['rms_diff'] == pytest.approx(0.1, rel=1e-9)
    assert elx['max_diff'] == pytest.approx(0.1, rel=1e-9)
    assert elx['command_rms_diff'] == pytest.approx(0.05, rel=1e-9)
    for name in JOINT_NAMES:
        if name != 'l_arm_elx':
            assert doc['joints'][name] == {'rms_diff': 0.0, 'max_diff': 0.0,
                                           'command_rms_diff': 0.0}, name
    assert doc['pelvis_height_rms_diff'] == pytest.approx(PELVIS_RMS_M, rel=1e-9)
    assert doc['fall_time_a'] == pytest.approx(1.0, abs=1e-9)
    assert doc['fall_time_b'] == pytest.approx(1.2, abs=1e-9)
    assert comparison.fall_time_diff_s == pytest.approx(0.2, abs=1e-9)
    assert comparison.moved == ['l_arm_elx']
    assert doc['a']['trajectory'] == {'file': '/data/Traj.yaml', 'name': 'step'}


def test_comparing_a_run_with_itself_gives_zero(bags: tuple[Path, Path]) -> None:
    doc = compare_bags(bags[0], bags[0]).to_dict()
    assert all(value == {'rms_diff': 0.0, 'max_diff': 0.0, 'command_rms_diff': 0.0}
               for value in doc['joints'].values())
    assert doc['pelvis_height_rms_diff'] == 0.0
    assert doc['fall_time_a'] == doc['fall_time_b']


def test_cli_json_text_and_plot(bags: tuple[Path, Path], tmp_path: Path,
                                capsys: pytest.CaptureFixture[str]) -> None:
    a, b = bags
    assert main([str(a), '--compare', str(b), '--json']) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc['joints']['l_arm_elx']['rms_diff'] == pytest.approx(0.1, rel=1e-9)
    plot = tmp_path / 'cmp.png'
    assert main([str(a), '--compare', str(b), '--plot', str(plot)]) == 0
    text = capsys.readouterr().out
    assert 'Aligned on the first applied joint command' in text
    assert 'A at 1.000 s, B at 1.500 s from bag start' in text
    assert 'A fell at 1.000 s, B fell at 1.200 s; B - A = +0.200 s' in text
    assert "trajectory 'step' of /data/Traj.yaml" in text
    assert '  l_arm_elx    0.1000    0.1000    0.0500' in text
    assert plot.stat().st_size > 10_000


def test_summary_names_the_trajectory(bags: tuple[Path, Path],
                                      capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(bags[0])]) == 0
    assert ("Trajectory: 'step' of /data/Traj.yaml (played by /tutorial_atlas_control)"
            in capsys.readouterr().out)
    assert main([str(bags[0]), '--json']) == 0
    assert json.loads(capsys.readouterr().out)['trajectory'] == {'file': '/data/Traj.yaml',
                                                                 'name': 'step'}


def test_bag_without_commands_cannot_be_aligned(tmp_path: Path) -> None:
    bare = write_bag(tmp_path / 'bare.bag', [joint_state(0.0, np.zeros(NUM_JOINTS)),
                                             joint_state(0.01, np.zeros(NUM_JOINTS))])
    with pytest.raises(BagAnalysisError, match='has no /atlas/joint_commands: cannot align'):
        first_applied_command_s(analyze_bag(bare))
    result = subprocess.run([sys.executable, str(REPO / 'scripts' / 'analyze_bag.py'),
                             str(bare), '--compare', str(bare)],
                            capture_output=True, text=True, check=False)
    assert result.returncode == 1
    assert result.stderr.count('\n') == 1 and 'cannot align it' in result.stderr


def test_csv_and_video_are_refused_with_compare(bags: tuple[Path, Path]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main([str(bags[0]), '--compare', str(bags[1]), '--csv', 'out'])
    assert exit_info.value.code == 2


def test_runs_that_share_no_time_are_refused(tmp_path: Path) -> None:
    short = write_bag(tmp_path / 's.bag', [joint_commands(1.0, np.zeros(NUM_JOINTS)),
                                           joint_state(0.5, np.zeros(NUM_JOINTS))])
    analysis = analyze_bag(short)
    with pytest.raises(BagAnalysisError, match='share no time'):
        compare_analyses(analysis, analysis)
