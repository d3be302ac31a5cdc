"""A launch with several tries (resets) in one bag: splitting, per-try metrics, --try,
--compare windows, --latest, and the truncated-bag line."""

from __future__ import annotations

import csv
import dataclasses
import json
import os
from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag1 import Writer

from support.synthetic_bags import (
    TrySpec,
    clock,
    joint_state,
    tries_records,
    write_bag,
    write_run_bag,
)
from tutorial_atlas_control.bags.analysis import analyze, analyze_bag
from tutorial_atlas_control.bags.reader import read_bag
from tutorial_atlas_control.bags.report import format_summary
from tutorial_atlas_control.bags.tries import (
    RESET_SIMULATION,
    RESET_WORLD,
    RUN_START,
    TIME_WENT_BACK,
    find_tries,
)
from tutorial_atlas_control.cli import analyze_bag as analyze_cli
from tutorial_atlas_control.cli import replay_bag as replay_cli
from tutorial_atlas_control.joints import NUM_JOINTS

#: The issue's session: step_and_fall, reset_world, touchdown, reset_simulation,
#: touchdown_exhausted. Falls 3.0 s and 4.0 s into tries 1 and 3 (pelvis 1 m/s down from
#: 0.93 m: below 0.5 m 0.43 s later), first commands 1 s into each try.
SESSION = [TrySpec(None, 'step_and_fall', fall_s=3.0),
           TrySpec('reset_world', 'touchdown'),
           TrySpec('reset_simulation', 'touchdown_exhausted', fall_s=4.0)]


@pytest.fixture(scope='module')
def session_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_bag(tmp_path_factory.mktemp('tries') / 'session.bag', tries_records(SESSION),
                     in_given_order=True)


def json_of(capsys: pytest.CaptureFixture[str], *args: str) -> dict:
    assert analyze_cli.main([*args, '--json']) == 0
    return json.loads(capsys.readouterr().out)


# ---------------------------------------------------------------- splitting


def test_session_is_split_into_three_tries(session_bag: Path) -> None:
    data = read_bag(session_bag)
    tries = find_tries(data)
    assert [t.cause for t in tries] == [RUN_START, RESET_WORLD, RESET_SIMULATION]
    # Run timeline: try 2 starts at its reset (sim 6.0 s); try 3 one gap after try 2's end.
    assert tries[1].start_s == pytest.approx(6.0 - 0.0005 + 0.0005, abs=1e-6)
    assert tries[2].start_s == pytest.approx(tries[1].start_s + 6.0 + 1.0 - 0.01, abs=0.011)
    assert data.sim_time_s(tries[2].start_s + 2.0) == pytest.approx(2.0, abs=0.011)
    assert np.all(np.diff(data.joint_states.t_s) > 0)  # one rising timeline, no interleaving
    # Topic rates over the time recorded: not inflated by the rewind, nor diluted by the gap.
    assert data.topics['/atlas/joint_states'].rate_hz == pytest.approx(100.0, rel=1e-3)


def test_each_try_gets_its_own_summary(session_bag: Path) -> None:
    analysis = analyze_bag(session_bag)
    summary = [each.to_dict() for each in analysis.tries]
    assert [t['trajectory']['name'] for t in summary] == ['step_and_fall', 'touchdown',
                                                          'touchdown_exhausted']
    assert [t['fell'] for t in summary] == [True, False, True]
    assert summary[0]['fall_after_command'] == pytest.approx(2.0 + 0.43, abs=0.011)
    assert summary[2]['fall_after_command'] == pytest.approx(3.0 + 0.43, abs=0.011)
    for each in summary:
        assert each['command_count'] == 100
        assert each['command_rate'] == pytest.approx(50.0)
        assert each['command_age']['max'] == pytest.approx(0.02)
    # Whole run: the rate while commands arrive, not 300 commands over 19 s.
    assert analysis.command_rate_hz == pytest.approx(50.0)
    assert analysis.command_age_max_s == pytest.approx(0.02)
    assert analysis.falls() == pytest.approx([summary[0]['fall_time'], summary[2]['fall_time']])
    assert analysis.warnings == [
        'the bag holds 3 tries (reset_world at 6.000 s, reset_simulation at '
        f'{analysis.tries[2].window.start_s:.3f} s); the whole-run figures span them all: see '
        'each try (--try N).']


def test_text_summary_lists_the_tries_and_resets(session_bag: Path) -> None:
    text = format_summary(analyze_bag(session_bag))
    assert 'Tries (3; a try starts' in text
    assert "try 2: 6.000 to 12.9" in text and "trajectory 'touchdown'" in text
    assert '6.000 s  reset_world: try 2 begins' in text
    assert "FELL at sim time 3.430 s, 2.430 s after the try's first command" in text


#: How far a starved recorder's record times lagged the stamps of what it recorded (s), seen
#: beside a busy core; twice that here.
RECORDER_LAG_S = 0.88


def test_a_lagging_recorder_keeps_each_message_in_the_try_it_was_stamped_in(
        tmp_path: Path) -> None:
    """A starved recorder's clock (its /clock thread) lags the simulator's: every record time
    of the try after reset_simulation is behind its message's stamp. Nothing moves to another
    try for it: the session reads as it does with a recorder on time."""
    on_time = tries_records(SESSION)
    after_reset = len(tries_records(SESSION[:2]))
    lagging = on_time[:after_reset] + [
        dataclasses.replace(record, t_s=max(record.t_s - RECORDER_LAG_S, 0.0))
        for record in on_time[after_reset:]]
    analysis = analyze_bag(write_bag(tmp_path / 'lagging.bag', lagging, in_given_order=True))
    assert [each.window.cause for each in analysis.tries] == [RUN_START, RESET_WORLD,
                                                              RESET_SIMULATION]
    summary = [each.to_dict() for each in analysis.tries]
    assert [each['command_count'] for each in summary] == [100, 100, 100]
    assert [each['fell'] for each in summary] == [True, False, True]
    assert summary[2]['fall_after_command'] == pytest.approx(3.0 + 0.43, abs=0.011)
    states = analysis.tries[2].analysis.data.joint_states
    assert len(states.t_s) == round(SESSION[2].duration_s / 0.01) - 1


def test_a_reset_world_recorded_by_a_lagging_recorder_starts_its_try_at_the_reset(
        tmp_path: Path) -> None:
    """The config re-published at reset_world reaches a recorder whose clock lags: its record
    time is before the reset. The try still begins at the reset (the config's
    last_reset_time), so the robot lying after try 1's fall is no fall of try 2."""
    records = tries_records(SESSION)
    at = len(tries_records(SESSION[:1]))
    config = records[at]
    assert config.topic == '/atlas/sim_config'
    late = dataclasses.replace(config, t_s=config.t_s - RECORDER_LAG_S)
    arrival = next(i for i, record in enumerate(records) if record.t_s > late.t_s)
    records = records[:arrival] + [late] + records[arrival:at] + records[at + 1:]
    analysis = analyze_bag(write_bag(tmp_path / 'late_config.bag', records,
                                     in_given_order=True))
    assert [each.window.cause for each in analysis.tries] == [RUN_START, RESET_WORLD,
                                                              RESET_SIMULATION]
    assert analysis.tries[1].window.start_s == pytest.approx(SESSION[0].duration_s, abs=0.001)
    assert [each.to_dict()['fell'] for each in analysis.tries] == [True, False, True]


def test_messages_recorded_across_a_reset_from_their_stamps_keep_the_try_stamped_in(
        tmp_path: Path) -> None:
    """Around reset_simulation the recorder writes in arrival order: the last joint states
    stamped before it can be written after the first ones stamped after it, and the other
    way round. Each is counted in the try its stamp belongs to."""
    records = tries_records(SESSION)
    after_reset = len(tries_records(SESSION[:2]))
    states = [i for i, record in enumerate(records) if record.topic == '/atlas/joint_states']
    last_before = [i for i in states if i < after_reset][-3:]
    first_after = [i for i in states if i >= after_reset][:2]
    late = [dataclasses.replace(records[i], t_s=0.001 * (n + 1))  # stamped ~12.97-12.99 s
            for n, i in enumerate(last_before)]
    early = [dataclasses.replace(records[i], t_s=records[after_reset - 1].t_s)  # ~0.01 s
             for i in first_after]
    moved = set(last_before) | set(first_after)
    kept = [record for i, record in enumerate(records) if i not in moved]
    at = after_reset - len(last_before)
    reordered = kept[:at] + early + kept[at:at + 1] + late + kept[at + 1:]
    analysis = analyze_bag(write_bag(tmp_path / 'across.bag', reordered, in_given_order=True))
    assert [each.window.cause for each in analysis.tries] == [RUN_START, RESET_WORLD,
                                                              RESET_SIMULATION]
    counts = [len(each.analysis.data.joint_states.t_s) for each in analysis.tries]
    on_time = [len(each.analysis.data.joint_states.t_s) for each in analyze_bag(
        write_bag(tmp_path / 'on_time.bag', records, in_given_order=True)).tries]
    assert counts == on_time


def test_single_run_is_one_try_without_warning(tmp_path: Path) -> None:
    analysis = analyze_bag(write_run_bag(tmp_path / 'run.bag', 2.0, with_imu=False))
    assert len(analysis.tries) == 1 and analysis.tries[0].window.cause == RUN_START
    assert analysis.warnings == []
    assert 'Tries' not in format_summary(analysis)


def test_time_going_back_without_config_starts_a_try(tmp_path: Path) -> None:
    """An older bag (no /atlas/sim_config): the rewind of sim time alone splits it."""
    records = []
    for start_s in (0.0, 0.0):
        for step in range(1, 200):
            records += [joint_state(start_s + step * 0.01, np.zeros(NUM_JOINTS)),
                        clock(start_s + step * 0.01)]
    data = read_bag(write_bag(tmp_path / 'old.bag', records, in_given_order=True))
    tries = analyze(data).tries
    assert [each.window.cause for each in tries] == [RUN_START, TIME_WENT_BACK]
    assert [len(each.analysis.data.joint_states.t_s) for each in tries] == [199, 199]


def test_bag_written_topic_by_topic_is_one_try(tmp_path: Path) -> None:
    """Writers that write a block per topic (offline runs): times go back in file order
    between topics, never within one; that is no reset."""
    records = sorted(tries_records(SESSION[:1]), key=lambda record: record.topic)
    analysis = analyze_bag(write_bag(tmp_path / 'blocks.bag', records, in_given_order=True))
    assert len(analysis.tries) == 1 and analysis.warnings == []
    assert analysis.command_rate_hz == pytest.approx(50.0)


# ---------------------------------------------------------------- command line


def test_json_has_tries(session_bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    doc = json_of(capsys, str(session_bag))
    assert [t['try'] for t in doc['tries']] == [1, 2, 3]
    assert [t['began_with'] for t in doc['tries']] == ['start', 'reset_world',
                                                       'reset_simulation']
    assert doc['tries'][2]['sim_start'] == pytest.approx(0.0, abs=1e-9)
    assert len(doc['warnings']) == 1 and doc['command_rate'] == pytest.approx(50.0)


def test_try_option_limits_summary_and_csv(session_bag: Path, tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    doc = json_of(capsys, str(session_bag), '--try', '2', '--csv', str(tmp_path / 'csv'))
    assert doc['trajectory']['name'] == 'touchdown' and doc['fell'] is False
    assert doc['command_count'] == 100 and [t['try'] for t in doc['tries']] == [2]
    with (tmp_path / 'csv' / 'joint_commands.csv').open() as stream:
        times = [float(row['t']) for row in csv.DictReader(stream)]
    assert len(times) == 100 and times[0] > 6.0 and times[-1] < 9.0


def test_start_end_window(session_bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    doc = json_of(capsys, str(session_bag), '--start', '1.5', '--end', '2.5')
    assert doc['command_count'] == 50 and doc['fell'] is False


def test_plot_of_one_try(session_bag: Path, tmp_path: Path) -> None:
    assert analyze_cli.main([str(session_bag), '--try', '-1', '--plot',
                             str(tmp_path / 'p.png')]) == 0
    assert (tmp_path / 'p.png').stat().st_size > 10_000


def test_missing_try_is_one_line(session_bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert analyze_cli.main([str(session_bag), '--try', '4']) == 1
    assert capsys.readouterr().err == (f'analyze_bag.py: error: {session_bag} holds 3 tries '
                                       '(1..3); there is no try 4.\n')


def test_compare_tries_of_one_bag(session_bag: Path, tmp_path: Path,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    doc = json_of(capsys, str(session_bag), '--try', '1', '--compare', str(session_bag),
                  '--plot', str(tmp_path / 'c.png'))
    assert doc['a']['trajectory']['name'] == 'step_and_fall'
    assert doc['b']['trajectory']['name'] == 'touchdown_exhausted'  # B's default: its last
    assert doc['aligned_on']['time_a'] == pytest.approx(0.9995, abs=1e-6)
    # Compared until try 1 ends (6 s after its start, 5 s after its first command).
    assert doc['aligned_on']['window'] == pytest.approx([0.0, 5.0], abs=0.011)
    assert doc['fall_time_a'] == pytest.approx(2.43, abs=0.011)
    assert doc['fall_time_b'] == pytest.approx(3.43, abs=0.011)
    assert (tmp_path / 'c.png').exists()


def test_compare_try_b(session_bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    doc = json_of(capsys, str(session_bag), '--compare', str(session_bag), '--try-b', '2')
    assert doc['a']['trajectory']['name'] == 'touchdown_exhausted'
    assert doc['b']['trajectory']['name'] == 'touchdown'
    assert doc['fall_time_b'] is None


def test_try_b_needs_compare(session_bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        analyze_cli.main([str(session_bag), '--try-b', '2'])
    assert exit_info.value.code == 2
    assert capsys.readouterr().err.splitlines()[-1] == (
        'analyze_bag.py: error: --try-b chooses the try of the --compare bag; give --compare '
        'B.bag')


# ---------------------------------------------------------------- --latest


@pytest.fixture()
def bag_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    directory = tmp_path / 'bags'
    directory.mkdir()
    monkeypatch.setenv('TAC_BAG_DIR', str(directory))
    return directory


@pytest.mark.parametrize('args', [[], ['--latest']])
def test_newest_bag_is_the_default(bag_dir: Path, args: list[str],
                                   capsys: pytest.CaptureFixture[str]) -> None:
    older = write_run_bag(bag_dir / 'atlas_2026-01-01-00-00-02.bag', 1.0, with_imu=False)
    newer = write_run_bag(bag_dir / 'atlas_2026-01-01-00-00-01.bag', 0.5, with_imu=False)
    os.utime(older, (1_000_000, 1_000_000))
    os.utime(newer, (2_000_000, 2_000_000))
    (bag_dir / 'atlas_2026-01-01-00-00-03.bag.active').write_bytes(b'')
    doc = json_of(capsys, *args)
    assert doc['bag'] == str(newer)


def test_latest_replay(bag_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = write_run_bag(bag_dir / 'atlas_x.bag', 0.05, with_imu=False)
    # No sim_config, and not a simulator's run: it deviates.
    assert replay_cli.main(['--json', '--assume-defaults']) == replay_cli.EXIT_DEVIATES
    captured = capsys.readouterr()
    assert captured.err == f'replaying {bag} (the newest bag)\n'
    assert json.loads(captured.out)['bag'] == str(bag)


def test_no_bag_in_the_bag_dir_is_one_line(bag_dir: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    (bag_dir / 'atlas_1.bag.active').write_bytes(b'')
    assert analyze_cli.main(['--latest']) == 1
    assert capsys.readouterr().err == (
        f'analyze_bag.py: error: no bag given and no .bag in {bag_dir} (atlas_1.bag.active is '
        f'an interrupted recording: run `rosbag reindex {bag_dir / "atlas_1.bag.active"}`); '
        'give BAG, or set TAC_BAG_DIR.\n')


def test_bag_and_latest_conflict(capsys: pytest.CaptureFixture[str]) -> None:
    for cli, prog in ((analyze_cli, 'analyze_bag.py'), (replay_cli, 'replay_bag.py')):
        with pytest.raises(SystemExit) as exit_info:
            cli.main(['run.bag', '--latest'])
        assert exit_info.value.code == 2
        assert capsys.readouterr().err.splitlines()[-1] == (
            f'{prog}: error: give BAG or --latest, not both')


# ---------------------------------------------------------------- truncated bag


@pytest.mark.parametrize('cli', [analyze_cli, replay_cli])
def test_truncated_bag_is_one_line_naming_reindex(tmp_path: Path, cli: object,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    full = write_run_bag(tmp_path / 'full.bag', 1.0, with_imu=False)
    truncated = tmp_path / 'cut.bag'
    truncated.write_bytes(full.read_bytes()[:full.stat().st_size * 9 // 10])
    assert cli.main([str(truncated)]) == 1  # type: ignore[attr-defined]
    assert capsys.readouterr().err == (
        f'{cli.PROG}: error: {truncated} is truncated or its index is damaged (was '  # type: ignore[attr-defined]
        f'the recording cut short?); run `rosbag reindex {truncated}` and analyze it again.\n')


def _empty_bag(path: Path) -> Path:
    with Writer(path):
        pass
    return path


def test_the_newest_bag_skips_empty_and_unreadable_ones_and_says_so(
        bag_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    good = write_run_bag(bag_dir / 'atlas_2026-01-01-00-00-01.bag', 0.5, with_imu=False)
    empty = _empty_bag(bag_dir / 'atlas_2026-01-01-00-00-02.bag')
    broken = bag_dir / 'atlas_2026-01-01-00-00-03.bag'
    broken.write_bytes(b'#ROSBAG V2.0\n' + bytes(64))
    for age_s, path in enumerate([broken, empty, good]):
        os.utime(path, (2_000_000 - age_s, 2_000_000 - age_s))
    assert analyze_cli.main(['--latest', '--json']) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)['bag'] == str(good)
    err = captured.err
    assert err.startswith(f'analyzing {good} (the newest bag; skipped {broken.name} '
                          '(unreadable: ')
    assert err.endswith(f'), {empty.name} (empty))\n'), err


def test_only_empty_bags_in_the_bag_dir_is_one_line(
        bag_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _empty_bag(bag_dir / 'atlas_1.bag')
    assert analyze_cli.main([]) == 1
    assert capsys.readouterr().err == (
        f'analyze_bag.py: error: no bag given and no usable .bag in {bag_dir} (atlas_1.bag: '
        'empty); give BAG, or set TAC_BAG_DIR.\n')


def test_an_empty_bag_given_by_name_exits_1_with_one_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = _empty_bag(tmp_path / 'atlas_1.bag')
    assert analyze_cli.main([str(bag)]) == 1
    assert capsys.readouterr().err == (
        f'analyze_bag.py: error: {bag} holds no message (a launch that stopped before its '
        'simulator was ready records nothing); give a bag of a run.\n')
