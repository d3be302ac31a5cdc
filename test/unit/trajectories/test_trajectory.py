"""Unit tests for tutorial_atlas_control.trajectories.trajectory.

File validation, the tutorial's file, interpolation.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from tutorial_atlas_control.joints import JOINT_INDEX, NUM_JOINTS
from tutorial_atlas_control.trajectories.trajectory import (
    PUBLISH_PERIOD_S,
    TrajectoryError,
    Waypoint,
    interpolate,
    load_trajectory,
    load_trajectory_file,
    parse_trajectory,
    sample_count,
)

TRAJECTORY_FILE = Path(__file__).resolve().parents[3] / 'trajectories' / 'Traj_data2.yaml'

ZEROS = ' '.join(['0'] * NUM_JOINTS)


def positions_text(count: int = NUM_JOINTS, value: str = '0') -> str:
    return ' '.join([value] * count)


def write(tmp_path: Path, text: str, name: str = 'Traj.yaml') -> Path:
    path = tmp_path / name
    path.write_text(text, encoding='utf-8')
    return path


# --- the tutorial's file ----------------------------------------------------------------


def test_tutorial_file_has_the_three_trajectories() -> None:
    doc = load_trajectory_file(TRAJECTORY_FILE)
    assert sorted(doc) == ['step_and_fall', 'touchdown', 'touchdown_exhausted']
    counts = {name: len(parse_trajectory(doc, name, TRAJECTORY_FILE)) for name in doc}
    assert counts == {'step_and_fall': 4, 'touchdown': 3, 'touchdown_exhausted': 4}


def test_tutorial_file_values() -> None:
    step = load_trajectory(TRAJECTORY_FILE, 'step_and_fall')
    assert [wp.duration_s for wp in step] == [1.0, 0.5, 1.5, 1.0]
    assert step[0].positions[JOINT_INDEX['r_leg_kny']] == 1.4
    assert step[0].positions[JOINT_INDEX['neck_ay']] == 0.2
    assert step[0].positions[JOINT_INDEX['r_leg_uay']] == -1.4
    assert step[1].positions[JOINT_INDEX['l_leg_lhy']] == 1.2
    assert step[2].positions[JOINT_INDEX['back_ubx']] == 1.0
    assert not step[3].positions.any()
    touchdown = load_trajectory(TRAJECTORY_FILE, 'touchdown')
    assert [wp.duration_s for wp in touchdown] == [2.0, 3.0, 1.0]
    assert touchdown[0].positions[JOINT_INDEX['l_arm_elx']] == 2.0
    assert touchdown[0].positions[JOINT_INDEX['r_arm_elx']] == -2.0
    assert touchdown[1].positions[JOINT_INDEX['l_arm_shx']] == 1.2
    exhausted = load_trajectory(TRAJECTORY_FILE, 'touchdown_exhausted')
    assert exhausted[2].positions[JOINT_INDEX['l_arm_usy']] == -1.0
    assert exhausted[2].positions[JOINT_INDEX['r_arm_usy']] == -1.0
    assert exhausted[2].positions[JOINT_INDEX['r_arm_shx']] == 1.0
    for wp in step + touchdown + exhausted:
        assert wp.positions.shape == (NUM_JOINTS,)
        assert wp.positions.dtype == np.float64


def test_tutorial_file_uses_the_tutorial_format() -> None:
    """Positions are strings of numbers, as in the tutorial, not YAML lists."""
    doc = yaml.safe_load(TRAJECTORY_FILE.read_text(encoding='utf-8'))
    for rows in doc.values():
        for duration, positions in rows:
            assert isinstance(duration, float)
            assert isinstance(positions, str)


# --- accepted forms ---------------------------------------------------------------------


def test_positions_as_yaml_list_and_integer_duration(tmp_path: Path) -> None:
    values = [0.1 * i for i in range(NUM_JOINTS)]
    path = write(tmp_path, yaml.safe_dump({'wave': [[2, values]]}))
    (waypoint,) = load_trajectory(path, 'wave')
    assert waypoint.duration_s == 2.0
    np.testing.assert_array_equal(waypoint.positions, values)


def test_every_trajectory_of_the_file_is_validated(tmp_path: Path) -> None:
    path = write(tmp_path, f'good:\n  - [1.0, "{ZEROS}"]\nbroken:\n  - [0.0, "{ZEROS}"]\n')
    with pytest.raises(TrajectoryError, match="trajectory 'broken', waypoint 0: .*duration"):
        load_trajectory(path, 'good')
    with pytest.raises(TrajectoryError, match='unable to find trajectory absent in'):
        load_trajectory(path, 'absent')


# --- file-level errors ------------------------------------------------------------------


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / 'absent.yaml'
    with pytest.raises(TrajectoryError,
                       match=r'absent\.yaml: cannot read trajectory file: No such file'):
        load_trajectory(path, 'x')


def test_directory_instead_of_file(tmp_path: Path) -> None:
    with pytest.raises(TrajectoryError, match='cannot read trajectory file'):
        load_trajectory_file(tmp_path)


def test_not_utf8(tmp_path: Path) -> None:
    path = tmp_path / 'Traj.yaml'
    path.write_bytes(b'\xff\xfe\x00garbage')
    with pytest.raises(TrajectoryError,
                       match=r'Traj\.yaml: cannot read trajectory file: not UTF-8'):
        load_trajectory_file(path)


@pytest.mark.parametrize('text', ['', '   \n', '# only a comment\n'])
def test_empty_file(tmp_path: Path, text: str) -> None:
    path = write(tmp_path, text)
    with pytest.raises(TrajectoryError, match=r'Traj\.yaml: the file is empty'):
        load_trajectory_file(path)


def test_yaml_syntax_error(tmp_path: Path) -> None:
    path = write(tmp_path, 'step:\n  - [1.0, "0 0"\n  - [oops\n')
    with pytest.raises(TrajectoryError,
                       match=r'Traj\.yaml: invalid YAML at line \d+, column \d+: ') as info:
        load_trajectory_file(path)
    assert '\n' not in str(info.value)


def test_python_tag_is_refused(tmp_path: Path) -> None:
    path = write(tmp_path, "step: !!python/object/apply:os.system ['echo pwned']\n")
    with pytest.raises(TrajectoryError, match=r'Traj\.yaml: unsupported YAML at line 1'
                                              r'.*python/object/apply') as info:
        load_trajectory_file(path)
    assert '\n' not in str(info.value)


@pytest.mark.parametrize(
    ('text', 'kind'),
    [('- [1.0, "0"]\n', 'a list of 1 items'), ('42\n', 'int 42'),
     ('just text\n', "str 'just text'")],
)
def test_root_must_be_a_mapping(tmp_path: Path, text: str, kind: str) -> None:
    path = write(tmp_path, text)
    with pytest.raises(TrajectoryError, match=rf'Traj\.yaml: expected a mapping .* got {kind}'):
        load_trajectory_file(path)


# --- trajectory-level errors ------------------------------------------------------------


def test_unknown_trajectory_keeps_the_tutorial_message(tmp_path: Path) -> None:
    path = write(tmp_path, f'good:\n  - [1.0, "{ZEROS}"]\n')
    with pytest.raises(TrajectoryError) as info:
        load_trajectory(path, 'nope')
    assert str(info.value) == f'unable to find trajectory nope in {path}; it holds: good'


def test_an_unknown_name_lists_the_file_s_trajectories(tmp_path: Path) -> None:
    many = ''.join(f'traj_{index}:\n  - [1.0, "{ZEROS}"]\n' for index in range(25))
    path = write(tmp_path, many)
    with pytest.raises(TrajectoryError) as info:
        load_trajectory(path, 'nope')
    listed = ', '.join(f'traj_{index}' for index in range(20))
    assert str(info.value) == (f'unable to find trajectory nope in {path}; it holds: {listed}, '
                               '... (25 in all)')


def test_unknown_name_is_reported_before_other_problems(tmp_path: Path) -> None:
    path = write(tmp_path, 'broken: 7\n')
    with pytest.raises(TrajectoryError, match='unable to find trajectory nope in'):
        load_trajectory(path, 'nope')


@pytest.mark.parametrize(
    ('body', 'problem'),
    [
        ('step: 7\n', r'expected a list of waypoints .* got int 7'),
        ('step: {a: 1}\n', r'expected a list of waypoints .* got a mapping'),
        ('step:\n', r'expected a list of waypoints .* got nothing \(null\)'),
        ('step: []\n', 'has no waypoints'),
    ],
)
def test_trajectory_must_be_a_non_empty_list(tmp_path: Path, body: str, problem: str) -> None:
    path = write(tmp_path, body)
    with pytest.raises(TrajectoryError, match=rf"^.*Traj\.yaml: trajectory 'step': {problem}$"):
        load_trajectory(path, 'step')


# --- waypoint-level errors --------------------------------------------------------------

GOOD_ROW = f'  - [1.0, "{ZEROS}"]\n'


@pytest.mark.parametrize(
    ('row', 'problem'),
    [
        (f'  - [1.0, "{positions_text(27)}"]\n', 'expected 28 joint positions, got 27'),
        (f'  - [1.0, "{positions_text(29)}"]\n', 'expected 28 joint positions, got 29'),
        ('  - [1.0, ""]\n', 'expected 28 joint positions, got 0'),
        (f'  - [1.0, {[0] * 27}]\n', 'expected 28 joint positions, got 27'),
        ('  - [1.0]\n',
         r'expected a pair \[duration_s, "28 joint positions"\], got a list of 1 items'),
        (f'  - [1.0, "{ZEROS}", 3]\n', 'expected a pair .* got a list of 3 items'),
        ('  - 1.0\n', 'expected a pair .* got float 1.0'),
        (f'  - {{duration: 1.0, positions: "{ZEROS}"}}\n', 'expected a pair .* got a mapping'),
        (f'  - [0, "{ZEROS}"]\n', 'duration must be positive, got 0 s'),
        (f'  - [-1.5, "{ZEROS}"]\n', r'duration must be positive, got -1\.5 s'),
        (f'  - [.nan, "{ZEROS}"]\n', 'duration must be a finite number of seconds, got nan'),
        (f'  - [.inf, "{ZEROS}"]\n', 'duration must be a finite number of seconds, got inf'),
        (f'  - [true, "{ZEROS}"]\n', 'duration must be a finite number of seconds, got True'),
        (f'  - ["1.0", "{ZEROS}"]\n', "duration must be a finite number of seconds, got '1.0'"),
        (f'  - [~, "{ZEROS}"]\n', 'duration must be a finite number of seconds, got None'),
        ('  - [1.0, 5]\n',
         'joint positions must be a string of 28 numbers or a list of them, got int 5'),
        ('  - [1.0, ~]\n', r'joint positions must be .* got nothing \(null\)'),
        (f'  - [1.0, "abc {positions_text(27)}"]\n',
         r"joint position 0 \(back_lbz\) must be a finite number, got 'abc'"),
        (f'  - [1.0, "{positions_text(13)} nan {positions_text(14)}"]\n',
         r"joint position 13 \(r_leg_kny\) must be a finite number, got 'nan'"),
        (f'  - [1.0, "{positions_text(27)} 1e999"]\n',
         r"joint position 27 \(r_arm_mwx\) .* got '1e999'"),
        (f'  - [1.0, [{", ".join(["0"] * 27)}, .inf]]\n',
         r'joint position 27 \(r_arm_mwx\) .* got inf'),
        (f'  - [1.0, [true, {", ".join(["0"] * 27)}]]\n',
         r'joint position 0 \(back_lbz\) .* got True'),
        (f'  - [1.0, ["0", {", ".join(["0"] * 27)}]]\n',
         r"joint position 0 \(back_lbz\) .* got '0'"),
    ],
)
def test_bad_waypoint_is_named(tmp_path: Path, row: str, problem: str) -> None:
    path = write(tmp_path, 'step_and_fall:\n' + GOOD_ROW + GOOD_ROW + row)
    with pytest.raises(TrajectoryError,
                       match=rf"^.*Traj\.yaml: trajectory 'step_and_fall', waypoint 2: {problem}$"):
        load_trajectory(path, 'step_and_fall')


def test_huge_integer_duration_is_not_finite(tmp_path: Path) -> None:
    path = write(tmp_path, f'step:\n  - [{10 ** 400}, "{ZEROS}"]\n')
    with pytest.raises(TrajectoryError, match="waypoint 0: duration must be a finite number"):
        load_trajectory(path, 'step')


def test_error_uses_the_path_as_given() -> None:
    doc = {'step': [[1.0, positions_text(27)]]}
    with pytest.raises(TrajectoryError) as info:
        parse_trajectory(doc, 'step', 'Traj.yaml')
    assert str(info.value) == \
        "Traj.yaml: trajectory 'step', waypoint 0: expected 28 joint positions, got 27"


# --- property: malformed documents raise TrajectoryError, never anything else ------------

yaml_scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10 ** 400), max_value=10 ** 400),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=30),
    st.sampled_from([ZEROS, positions_text(27), positions_text(28, 'nan'),
                     positions_text(28, '1e999')]),
)
yaml_values = st.recursive(
    yaml_scalars,
    lambda children: st.one_of(
        st.lists(children, max_size=30),
        st.dictionaries(st.text(max_size=5), children, max_size=4),
    ),
    max_leaves=60,
)
waypoint_like = st.one_of(
    yaml_values,
    st.tuples(yaml_scalars, yaml_values).map(list),
    st.tuples(
        st.floats(min_value=1e-6, max_value=10.0),
        st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=27, max_size=29),
    ).map(list),
)
docs = st.one_of(
    yaml_values,
    st.dictionaries(st.sampled_from(['step', 'other']),
                    st.one_of(yaml_values, st.lists(waypoint_like, max_size=4))),
)


@settings(max_examples=400, deadline=None)
@given(doc=docs)
def test_malformed_documents_raise_only_trajectory_error(doc: object) -> None:
    if not isinstance(doc, dict):
        doc = {'step': doc}
    try:
        waypoints = parse_trajectory(doc, 'step', 'Traj.yaml')
    except TrajectoryError as err:
        message = str(err)
        assert '\n' not in message
        assert (message.startswith('unable to find trajectory step in Traj.yaml')
                or message.startswith("Traj.yaml: trajectory 'step'"))
        return
    # Anything accepted is a valid trajectory.
    assert waypoints
    for waypoint in waypoints:
        assert math.isfinite(waypoint.duration_s) and waypoint.duration_s > 0
        assert waypoint.positions.shape == (NUM_JOINTS,)
        assert np.isfinite(waypoint.positions).all()


@settings(max_examples=200, deadline=None)
@given(text=st.text(max_size=200))
def test_arbitrary_file_text_raises_only_trajectory_error(
        tmp_path_factory: pytest.TempPathFactory, text: str) -> None:
    path = tmp_path_factory.mktemp('prop') / 'Traj.yaml'
    path.write_text(text, encoding='utf-8')
    try:
        load_trajectory(path, 'step')
    except TrajectoryError as err:
        assert '\n' not in str(err)


# --- sampling and interpolation ---------------------------------------------------------


@pytest.mark.parametrize(
    ('duration_s', 'count'),
    [(1.0, 50), (0.5, 25), (1.5, 75), (2.0, 100), (3.0, 150), (0.14, 7), (0.03, 2), (0.02, 1),
     (0.001, 1), (1e-300, 1)],
)
def test_sample_count(duration_s: float, count: int) -> None:
    result = sample_count(duration_s)
    assert type(result) is int
    assert result == count


@pytest.mark.parametrize('duration_s', [0.0, -1.0, math.nan, math.inf])
def test_sample_count_rejects_bad_durations(duration_s: float) -> None:
    with pytest.raises(ValueError):
        sample_count(duration_s)


def test_interpolate_follows_the_tutorial() -> None:
    initial = np.linspace(-1.0, 1.0, NUM_JOINTS)
    target = np.full(NUM_JOINTS, 0.5)
    samples = list(interpolate(initial, target, 1.0))
    assert len(samples) == 50
    np.testing.assert_array_equal(samples[0][0], initial)
    np.testing.assert_array_equal(samples[-1][0], target)
    for sleep_s in (s for _, s in samples):
        assert sleep_s == pytest.approx(PUBLISH_PERIOD_S)
    assert sum(s for _, s in samples) == pytest.approx(1.0)
    # Exactly the tutorial's formula.
    for (positions, _), ratio in zip(samples, np.linspace(0, 1, 50)):
        np.testing.assert_allclose(positions, (1 - ratio) * initial + ratio * target,
                                   rtol=0, atol=1e-12)


def test_interpolate_is_50_hz_or_faster_and_lasts_the_duration() -> None:
    for duration_s in (0.03, 0.05, 0.14, 0.5, 1.5, 2.37):
        samples = list(interpolate(np.zeros(NUM_JOINTS), np.ones(NUM_JOINTS), duration_s))
        assert len(samples) == sample_count(duration_s)
        assert all(0 < s <= PUBLISH_PERIOD_S + 1e-12 for _, s in samples)
        assert sum(s for _, s in samples) == pytest.approx(duration_s)
        np.testing.assert_array_equal(samples[-1][0], np.ones(NUM_JOINTS))


def test_interpolate_single_sample_commands_the_target() -> None:
    """The tutorial's linspace(0, 1, 1) == [0] would never command the target."""
    samples = list(interpolate(np.zeros(NUM_JOINTS), np.ones(NUM_JOINTS), 0.01))
    assert len(samples) == 1
    positions, sleep_s = samples[0]
    np.testing.assert_array_equal(positions, np.ones(NUM_JOINTS))
    assert sleep_s == pytest.approx(0.01)


def test_interpolate_does_not_alias_its_inputs() -> None:
    initial = np.zeros(NUM_JOINTS)
    target = np.ones(NUM_JOINTS)
    for positions, _ in interpolate(initial, target, 0.1):
        positions[:] = 7.0
    for positions, _ in interpolate(initial, target, 0.01):
        positions[:] = 7.0
    assert not initial.any() and (target == 1.0).all()


def test_interpolate_is_lazy() -> None:
    samples = interpolate(np.zeros(NUM_JOINTS), np.ones(NUM_JOINTS), 1e12)
    first, sleep_s = next(samples)
    assert not first.any()
    assert sleep_s == pytest.approx(PUBLISH_PERIOD_S)


def test_interpolate_rejects_mismatched_shapes() -> None:
    with pytest.raises(ValueError, match='shape'):
        next(interpolate(np.zeros(NUM_JOINTS), np.zeros(NUM_JOINTS - 1), 1.0))


def test_waypoint_is_a_plain_record() -> None:
    waypoint = Waypoint(duration_s=1.0, positions=np.zeros(NUM_JOINTS))
    assert waypoint.duration_s == 1.0


def test_odd_trajectory_names_are_listed_quoted_on_one_line(tmp_path: Path) -> None:
    path = write(tmp_path, f'"a, b":\n  - [1.0, "{ZEROS}"]\n"x\\ny":\n  - [1.0, "{ZEROS}"]\n'
                           f'7:\n  - [1.0, "{ZEROS}"]\n')
    with pytest.raises(TrajectoryError) as info:
        load_trajectory(path, 'nope')
    assert str(info.value) == (f"unable to find trajectory nope in {path}; it holds: 'a, b', "
                               "'x\\ny', 7")
