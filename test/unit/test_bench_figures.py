"""The benchmark's arithmetic and its verdicts, from synthetic figures (bench/run_bench.py).

Speed is never asserted here: these check that the figures the bench derives are the
right formulas of what it measured, that a missed target says MISSED, and that a missing
or NaN figure makes the bench fail. `make test` also runs `run_bench.py --quick`.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import load
import numpy as np
import pytest
import run_bench

PER_SIM_S = 1000.0  # simulated steps per sim second (1 ms steps)


def fast_samples() -> dict[str, list[float]]:
    """Two fast runs and three physics runs, with figures easy to check by hand."""
    return {
        'fast_rtf': [8.0, 10.0],
        'fast_node_cpu': [0.8, 0.9],
        'fast_recorder_cpu': [0.5, 0.6],
        'fast_state_publisher_cpu': [0.1, 0.1],
        'fast_master_cpu': [0.1, 0.1],
        'bare_physics_steps_per_s': [20000.0, 25000.0, 22000.0],
        'physics_limit_steps_per_s': [16000.0, 20000.0, 18000.0],
    }


def test_per_step_figures_are_cpu_over_simulated_steps() -> None:
    samples = fast_samples()
    medians = run_bench.summarize(samples, per_sim_s=PER_SIM_S)
    # node: 0.8 cores at 8x real time = 0.8e6 µs per 8000 steps = 100 µs; then 90 µs.
    assert samples['node_us_per_step'] == pytest.approx([100.0, 90.0])
    assert medians['node_us_per_step'] == pytest.approx(95.0)
    assert samples['recorder_us_per_step'] == pytest.approx([62.5, 60.0])
    # all four processes: 1.5 cores / 8000 steps, 1.7 cores / 10000 steps.
    assert samples['fast_cpu_us_per_step'] == pytest.approx([187.5, 170.0])
    assert medians['fast_cpu_us_per_step'] == pytest.approx(178.75)
    # ratios to the median plain loop (18000/s) and the median bare mj_step (22000/s).
    assert medians['fast_ratio'] == pytest.approx(9.0 * 1000 / 18000)
    assert medians['fast_bare_ratio'] == pytest.approx(9.0 * 1000 / 22000)
    assert medians['node_bare_ratio'] == pytest.approx(95.0 / (1e6 / 22000))


def test_controller_costs_as_ratios_to_bare_physics() -> None:
    """The compiled core's figures (compiled and its Python reference, paired) as multiples
    of the same run's bare mj_step, and the offline walk against bare physics's speed."""
    samples = {'bare_physics_steps_per_s': [10000.0, 12500.0, 8000.0],  # median 100 µs
               'stand_us_per_step': [60.0, 50.0, 70.0],
               'stand_python_us_per_step': [300.0, 250.0, 350.0],
               'walk_us_per_step': [150.0], 'walk_python_us_per_step': [400.0],
               'walk_offline_rtf': [4.0],
               'controller_tcp_node_us_per_step': [120.0, 130.0]}
    medians = run_bench.summarize(samples, per_sim_s=PER_SIM_S)
    assert medians['stand_bare_ratio'] == pytest.approx(0.6)
    assert samples['stand_bare_ratio'] == pytest.approx([0.6, 0.5, 0.7])
    assert medians['stand_python_bare_ratio'] == pytest.approx(3.0)
    assert medians['walk_bare_ratio'] == pytest.approx(1.5)
    assert medians['walk_python_bare_ratio'] == pytest.approx(4.0)
    # bare physics runs at 10x real time, the walk at 4x: 2.5 times slower.
    assert medians['walk_offline_bare_ratio'] == pytest.approx(2.5)
    assert medians['controller_tcp_node_bare_ratio'] == pytest.approx(1.25)
    assert 'unheard_topic_bare_ratio' not in medians
    judged = run_bench.verdicts(medians, run_bench.DEFAULT_COMPRESSION)
    assert {key: judged[key] for key in ('stand_bare_ratio', 'walk_bare_ratio',
                                         'walk_offline_bare_ratio')} == {
        'stand_bare_ratio': 'met', 'walk_bare_ratio': 'MISSED',
        'walk_offline_bare_ratio': 'MISSED'}


def test_per_step_cpu_sum_skips_a_process_missing_from_some_runs() -> None:
    samples = fast_samples()
    samples['fast_state_publisher_cpu'] = [0.1]  # one run without robot_state_publisher
    run_bench.summarize(samples, per_sim_s=PER_SIM_S)
    assert samples['fast_cpu_us_per_step'] == pytest.approx([1.4e6 / 8000, 1.6e6 / 10000])


def test_headline_command_latency_is_the_worse_rate() -> None:
    medians = run_bench.summarize({'cmd_latency_p99_ms_50hz': [1.0, 3.0, 2.0],
                                   'cmd_latency_p99_ms_1khz': [1.5, 1.5, 1.6],
                                   'cmd_latency_p50_ms_50hz': [0.5],
                                   'cmd_latency_p50_ms_1khz': [0.7]}, per_sim_s=PER_SIM_S)
    assert medians['cmd_latency_p99_ms'] == 2.0
    assert medians['cmd_latency_p50_ms'] == 0.7


@pytest.mark.parametrize(('key', 'value', 'verdict'), [
    ('offline_ratio', 0.8, 'met'),             # >= 0.8: the bound itself meets it
    ('offline_ratio', 0.79, 'MISSED'),
    ('lateness_p99_ms', 1.99, 'met'),
    ('lateness_p99_ms', 2.0, 'MISSED'),       # < 2: the bound itself misses
    ('realtime_rtf', 1.009, 'met'),
    ('realtime_rtf', 0.989, 'MISSED'),
    ('realtime_rtf', 1.011, 'MISSED'),
    ('load_commands_lost', 0.0, 'met'),
    ('load_commands_lost', 1.0, 'MISSED'),
    ('fast_recorded_fraction', 1.0, 'met'),
    ('fast_recorded_fraction', 0.9999, 'MISSED'),
    ('tutorial_command_rate_hz', 50.1, 'met'),
    ('tutorial_command_rate_hz', 44.9, 'MISSED'),
    ('tutorial_command_rate_hz', 51.1, 'MISSED'),
    ('tutorial_age_closed_form_share', 0.8, 'met'),
    ('tutorial_age_closed_form_share', 0.79, 'MISSED'),
    ('load_publish_rate_hz', 5900.0, 'met'),
    ('load_publish_rate_hz', 5800.0, 'MISSED'),
    ('unheard_topic_us_per_step', 1.0, 'MISSED'),
    ('analysis_speedup', 5.0, 'met'),
])
def test_verdict_of_a_plain_target(key: str, value: float, verdict: str) -> None:
    assert run_bench.verdicts({key: value}, 'lz4') == {key: verdict}


def test_targets_relative_to_bare_physics() -> None:
    medians = run_bench.summarize(fast_samples(), per_sim_s=PER_SIM_S)
    judged = run_bench.verdicts(medians, run_bench.DEFAULT_COMPRESSION)
    # fast_rtf 9 < 0.6 x 22 = 13.2; node 95 µs > 1.5 x 45.5 µs: the ratios say the same.
    assert {key: judged[key] for key in ('fast_rtf', 'fast_bare_ratio', 'node_us_per_step',
                                         'node_bare_ratio')} == dict.fromkeys(
        ('fast_rtf', 'fast_bare_ratio', 'node_us_per_step', 'node_bare_ratio'), 'MISSED')
    met = run_bench.verdicts({'bare_physics_steps_per_s': 20000.0, 'fast_rtf': 12.0,
                              'node_us_per_step': 75.0}, 'lz4')
    assert met == {'fast_rtf': 'met', 'node_us_per_step': 'met'}  # 12 >= 12, 75 <= 75


def test_relative_target_without_bare_physics_is_not_judged() -> None:
    judged = run_bench.verdicts({'fast_rtf': 12.0}, 'lz4')
    assert judged == {'fast_rtf': 'unjudged (no bare_physics_steps_per_s: run the physics '
                                  'section)'}


def test_bag_size_target_applies_to_lz4_only() -> None:
    assert run_bench.verdicts({'bag_mb_per_min': 90.0}, 'lz4') == {'bag_mb_per_min': 'MISSED'}
    assert run_bench.verdicts({'bag_mb_per_min': 70.0}, run_bench.DEFAULT_COMPRESSION) == {
        'bag_mb_per_min': 'met'}
    assert run_bench.verdicts({'bag_mb_per_min': 143.0}, 'none') == {
        'bag_mb_per_min': 'unjudged (none chunks; the target is for lz4)'}


def test_figures_without_target_get_no_verdict() -> None:
    assert run_bench.verdicts({'lateness_p50_ms': 9.0, 'fast_node_cpu': 2.0}, 'lz4') == {}


def test_missing_and_nan_figures_are_invalid() -> None:
    physics = {key: 1.0 for key in run_bench.EXPECTED['physics']}
    assert run_bench.invalid_figures(physics, ['physics']) == []
    del physics['unheard_topic_us_per_step']
    physics['bare_physics_steps_per_s'] = math.nan
    assert run_bench.invalid_figures(physics, ['physics']) == [
        'bare_physics_steps_per_s', 'unheard_topic_us_per_step']
    # physics and fast together also owe the ratios between them.
    both = {key: 1.0 for section in ('physics', 'fast') for key in run_bench.EXPECTED[section]}
    assert run_bench.invalid_figures(both, ['physics', 'fast']) == [
        'fast_bare_ratio', 'fast_ratio', 'node_bare_ratio']


def run_main_with(monkeypatch: pytest.MonkeyPatch, figures: dict[str, list[float]],
                  argv: list[str]) -> int:
    """run_bench.main() with its sections replaced by `figures` (no ROS, no timing)."""
    monkeypatch.setattr(run_bench, 'check_environment', lambda: None)
    monkeypatch.setattr(run_bench, 'run_offline',
                        lambda args, samples, loads: samples.update(figures))
    monkeypatch.setattr(run_bench, 'run_online', lambda *args: None)
    monkeypatch.setattr(run_bench, 'run_tutorial', lambda *args: None)
    monkeypatch.setattr(run_bench, 'run_walking', lambda *args: None)
    return run_bench.main(argv)


def test_main_fails_on_a_nan_figure_and_keeps_the_json_last(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    figures = {key: [1.0] for key in run_bench.EXPECTED['analysis']}
    figures['analysis_speedup'] = [math.nan]
    assert run_main_with(monkeypatch, figures, ['--only', 'analysis', '--runs', '1']) == 1
    out, err = capsys.readouterr()
    result = json.loads(out.strip().splitlines()[-1])
    assert result['invalid'] == ['analysis_speedup']
    assert err.strip().splitlines()[-1] == 'run_bench: missing or not finite: analysis_speedup'


def test_main_lists_missed_targets_and_still_succeeds(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    figures = {key: [1.0] for key in run_bench.EXPECTED['analysis']}
    figures['analysis_speedup'] = [4.0, 6.0, 3.0]   # median 4: below 5
    figures['analysis_s'] = [0.3, 0.3, 0.3]         # < 2 s: met
    assert run_main_with(monkeypatch, figures, ['--only', 'analysis', '--runs', '3']) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    result = json.loads(lines[-1])
    assert result['missed'] == ['analysis_speedup']
    assert result['invalid'] == []
    speedup_row = next(line for line in lines if line.startswith('analyze_bag / rosbag'))
    assert speedup_row.split()[-1] == 'MISSED'
    time_row = next(line for line in lines if line.startswith('analyze_bag, 60 s bag')
                    and ' s ' in line)
    assert time_row.split()[-1] == 'met'
    assert 'targets: 1 of 2 met; MISSED: analysis_speedup' in lines


@pytest.mark.parametrize(('value', 'verdict'), [(1.0, 'met'), (2.0, 'MISSED')])
def test_the_synchronization_window_owes_one_step_of_age(value: float, verdict: str) -> None:
    assert run_bench.verdicts({'controller_window_age_p99_ms': value}, 'lz4') == {
        'controller_window_age_p99_ms': verdict}


def test_controller_section_without_udp_says_so_and_passes(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    figures = {key: [1.0] for key in run_bench.EXPECTED['controller']}

    def online(args, samples, loads, work_dir) -> None:
        samples.update(figures)
        args.udp = run_bench.NO_UDP
    monkeypatch.setattr(run_bench, 'check_environment', lambda: None)
    monkeypatch.setattr(run_bench, 'run_offline', lambda *args: None)
    monkeypatch.setattr(run_bench, 'run_online', online)
    monkeypatch.setattr(run_bench, 'run_tutorial', lambda *args: None)
    monkeypatch.setattr(run_bench, 'run_walking', lambda *args: None)
    monkeypatch.setattr(run_bench, 'summarize', lambda samples: {
        key: values[0] for key, values in samples.items()})
    assert run_bench.main(['--only', 'controller', '--runs', '1']) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    result = json.loads(lines[-1])
    assert result['controller_udp'] == 'n/a (no UDP connection)'
    assert result['invalid'] == []
    assert 'controller_udp_age_p99_ms' not in result
    row = next(line for line in lines if line.startswith('echo_controller UDP: command age p99'))
    assert row.endswith('  n/a (no UDP connection)')


def test_command_age_is_read_from_the_wire_message() -> None:
    import controller

    from tutorial_atlas_control.msgs.wire import ControllerStatisticsWire

    wire = ControllerStatisticsWire()
    wire.set_values(0.001, 0.002, 3e-7, 1.0)
    assert controller.command_age_s(bytes(wire.stamped(5_000_000))) == 0.001


def sawtooth_window(hold_steps: list[int]) -> tuple[float, float]:
    """A window's command-age mean (s) and variance (s^2, n - 1) when its commands are held
    `hold_steps` steps each, each applied one step after its stamp."""
    ages_s = np.concatenate([np.arange(1, hold + 1) for hold in hold_steps]) * load.STEP_S
    return float(ages_s.mean()), float(ages_s.var(ddof=1))


def test_the_closed_form_is_the_50_hz_ports_sawtooth() -> None:
    mean_s, variance_s2 = sawtooth_window([20] * 50)  # 1000 steps
    assert mean_s == pytest.approx(load.CLOSED_FORM_MEAN_S, rel=1e-12)
    assert variance_s2 == pytest.approx(load.CLOSED_FORM_VARIANCE_S2, rel=1e-12)


def test_closed_form_share_counts_the_windows_within_the_commands() -> None:
    """Windows from one window after the first command to the last: a window of a port that
    kept up counts, one whose command ages doubled (a 25 Hz port) does not."""
    kept_up = sawtooth_window([20] * 50)
    late = sawtooth_window([40] * 25)
    first_ns, step_ns = 1_000_000_000, 1_000_000
    start_ns = first_ns + 1020 * step_ns
    stamps = [start_ns - step_ns, start_ns, start_ns + step_ns, start_ns + 2 * step_ns,
              start_ns + 3 * step_ns]
    windows = [late, kept_up, late, kept_up, late]  # the first before the span, the last after
    last_ns = start_ns + 2 * step_ns
    share = load.closed_form_share(stamps, [w[0] for w in windows], [w[1] for w in windows],
                                   first_ns, last_ns)
    assert share == pytest.approx(2 / 3)
    assert load.closed_form_share(stamps[:1], [late[0]], [late[1]], first_ns, last_ns) is None


@pytest.mark.parametrize(('key', 'value', 'verdict'), [
    ('controller_tcp_node_us_per_step', 150.0, 'met'),      # <= 150: the bound meets it
    ('controller_tcp_node_us_per_step', 150.1, 'MISSED'),
    ('controller_udp_node_us_per_step', 149.0, 'met'),
    ('controller_udp_node_us_per_step', 380.0, 'MISSED'),
    ('controller_tcp_age_p99_ms', 1.0, 'met'),              # every state answered in time
    ('controller_udp_age_p99_ms', 2.0, 'MISSED'),
])
def test_serving_a_controller_has_targets(key: str, value: float, verdict: str) -> None:
    assert run_bench.verdicts({key: value}, 'lz4') == {key: verdict}


def test_the_floor_without_a_controller_is_expected_and_unjudged() -> None:
    assert 'controller_none_node_us_per_step' in run_bench.EXPECTED['controller']
    assert run_bench.verdicts({'controller_none_node_us_per_step': 300.0}, 'lz4') == {}
    figures = {key: 1.0 for key in run_bench.EXPECTED['controller']}
    del figures['controller_none_node_us_per_step']
    assert run_bench.invalid_figures(figures, ['controller']) == [
        'controller_none_node_us_per_step']


@pytest.mark.parametrize(('argv', 'budget', 'whole_search'), [
    ([], 'default', False),                       # make bench: the search's speed only
    (['--full'], 'full', True),
    (['--only', 'search'], 'default', True),      # asked for by name: the whole search
    (['--only', 'sweep,search'], 'default', True),
    (['--only', 'search', '--quick'], 'quick', False),
    (['--only', 'physics'], 'default', False),
    (['--quick'], 'quick', False),
])
def test_windows_and_search_by_flag(argv: list[str], budget: str, whole_search: bool) -> None:
    args = run_bench.parse_args(argv)
    assert args.budget is run_bench.BUDGETS[budget]
    assert args.whole_search is whole_search


def test_default_search_is_a_short_fixed_budget_and_full_the_whole() -> None:
    assert run_bench.BUDGETS['default'].search_generations == 1
    assert run_bench.BUDGETS['quick'].search_generations == 1
    assert run_bench.BUDGETS['full'].search_generations is None


def test_quick_and_full_exclude_each_other(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        run_bench.parse_args(['--quick', '--full'])
    assert exit_info.value.code == 2
    assert 'not allowed with argument' in capsys.readouterr().err


@pytest.mark.parametrize(('argv', 'budget', 'search', 'line'), [
    (['--only', 'search', '--runs', '1'], 'default', 'whole',
     'windows: the default (--full: the longer windows and the whole search); the whole search'),
    (['--runs', '1'], 'default', 'short', 'windows: the default (--full: the longer windows '
     'and the whole search); the search for 1 generation(s)'),
    (['--full', '--only', 'analysis', '--runs', '1'], 'full', None, 'windows: --full'),
])
def test_json_and_table_say_which_windows_and_search(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], argv: list[str],
        budget: str, search: str | None, line: str) -> None:
    monkeypatch.setattr(run_bench, 'run_search', lambda *args: None)
    monkeypatch.setattr(run_bench, 'run_sweep', lambda *args: None)
    monkeypatch.setattr(run_bench, 'invalid_figures', lambda medians, sections: [])
    assert run_main_with(monkeypatch, {}, argv) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    result = json.loads(lines[-1])
    assert result['budget'] == budget
    assert result.get('search') == search
    assert line in lines


def test_search_time_plays_the_generations_asked(monkeypatch: pytest.MonkeyPatch,
                                                 tmp_path: Path) -> None:
    import search_time

    commands = []

    def fake_run(command: list[str], **kwargs: object) -> object:  # subprocess.run's shape
        commands.append(command)
        log = tmp_path / 'search.jsonl'
        log.write_text(json.dumps({'kind': 'search', 'config': {}}) + '\n'
                       + json.dumps({'kind': 'generation', 'x': [[0.0]] * 8}) + '\n')
        return type('Done', (), {'returncode': 0, 'stderr': ''})()
    monkeypatch.setattr(search_time.subprocess, 'run', fake_run)
    monkeypatch.setattr(search_time, 'runs_per_candidate', lambda config: 9)
    timed = search_time.search_time(tmp_path, 2)
    generations = commands[-1][commands[-1].index('--generations') + 1]
    assert generations == '2'
    assert timed.reproduced is None  # a short search is not judged on the step it finds
    assert timed.runs == 9 * 9 and timed.generations == 1


@pytest.mark.parametrize(('budget', 'runs', 'side'), [
    ('default', 3, 1),   # the untargeted launches once, the targeted figures every run
    ('default', 1, 1),
    ('full', 3, 3),
    ('quick', 2, 2),
])
def test_untargeted_launches_run_once_by_default(budget: str, runs: int, side: int) -> None:
    assert run_bench.BUDGETS[budget].side(runs) == side


def test_fast_variants_only_in_the_side_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    import online

    launched: list[str] = []

    def fast_run(*args: object, prefix: str, **kwargs: object) -> dict[str, float]:
        launched.append(f'{prefix}{len(launched)}')
        return {f'{prefix}_rtf': 1.0, f'{prefix}_master_cpu': 0.0}
    monkeypatch.setattr(online, 'fast_run', fast_run)
    monkeypatch.setattr(run_bench, 'log', lambda text: None)
    samples: dict[str, list[float]] = {}
    run_bench.run_fast(run_bench.parse_args(['--runs', '3']), samples, None, None, None)
    assert [name.rstrip('0123456789') for name in launched] == [
        'fast', 'fast_rosbag', 'fast_rsp', 'fast', 'fast']
    assert len(samples['fast_rtf']) == 3 and len(samples['fast_rosbag_rtf']) == 1


def test_walking_fractions_are_falls_over_runs() -> None:
    import walking

    assert walking.fell_fraction([False] * 8) == 0.0
    assert walking.fell_fraction([True, False, False, False, False, False, False, False]) == 0.125
    assert walking.fell_fraction([True, True]) == 1.0
    with pytest.raises(ValueError):
        walking.fell_fraction([])
    assert walking.force_key('walk_pushes', 175.0) == 'walk_pushes_fell_fraction_175n'
    assert walking.force_key('walk_phase_pushes', 150.0, adjust=False) == (
        'walk_phase_pushes_fell_fraction_150n_unadjusted')


def test_phase_pushes_are_every_step_phase_and_side_each_its_own_seed() -> None:
    import walking

    cases = walking.phase_pushes((4, 5), 7, 150.0, True)
    assert len(cases) == 28  # the docs' "0 of 28": 2 steps x 7 phases x 2 sides
    assert [case.index for case in cases] == list(range(28))
    assert {(case.step, round(case.phase * 7), case.side) for case in cases} == {
        (step, k, side) for step in (4, 5) for k in range(7) for side in (1.0, -1.0)}


def test_walking_section_figures_from_synthetic_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    """The section's arithmetic with the runs replaced: seed 5 of the README's circle lands
    4 cm off, seed 7's mode-switching demo falls, seed 3 of the pushed walks falls at every
    force, phase case 0 falls, variation seed 2 falls."""
    import walking

    monkeypatch.setattr(walking, 'course_walk', lambda job: (
        (False, 0.04) if job[0] == 'circle' and job[2] == 5 else (True, 0.01 + job[2] / 1000)))
    monkeypatch.setattr(walking, 'mode_switching_fell', lambda seed: seed == 7)
    monkeypatch.setattr(walking, '_pushed_fell', lambda job: job[0] == 3)
    monkeypatch.setattr(walking, 'phase_push_fell', lambda case: case.index == 0)
    monkeypatch.setattr(walking, '_varied_fell', lambda seed: seed == 2)
    figures = walking.walking_figures(walking.BUDGETS['default'], log=lambda text: None,
                                      pool_map=lambda function, jobs: map(function, jobs))
    assert figures == {
        'walk_straight_runs': 8.0, 'walk_straight_within_fraction': 1.0,
        'walk_straight_worst_landing_m': 0.017, 'walk_circle_runs': 8.0,
        'walk_circle_within_fraction': 0.875, 'walk_circle_worst_landing_m': 0.04,
        'mode_switching_runs': 8.0, 'mode_switching_fell_fraction': 0.125,
        'walk_pushes_runs': 8.0, 'walk_pushes_fell_fraction_150n': 0.125,
        'walk_pushes_fell_fraction_175n': 0.125, 'walk_phase_pushes_runs': 28.0,
        'walk_phase_pushes_fell_fraction_150n': 1 / 28, 'walk_variations_runs': 8.0,
        'walk_variations_fell_fraction': 0.125}
    assert run_bench.invalid_figures(figures, ['walking']) == []
    quick = walking.walking_figures(walking.BUDGETS['quick'], log=lambda text: None,
                                    pool_map=lambda function, jobs: map(function, jobs))
    assert run_bench.invalid_figures(quick, ['walking']) == []  # --quick: every key too
    assert quick['walk_phase_pushes_runs'] == 2.0 and quick['walk_variations_runs'] == 1.0
    assert quick['walk_straight_runs'] == quick['walk_circle_runs'] == 1.0


@pytest.mark.parametrize(('key', 'value', 'verdict'), [
    ('walk_pushes_fell_fraction_150n', 0.0, 'met'),   # the push: no seed falls
    ('walk_pushes_fell_fraction_150n', 0.125, 'MISSED'),
    ('walk_phase_pushes_fell_fraction_150n', 1 / 28, 'MISSED'),
    ('walk_variations_fell_fraction', 0.0, 'met'),
    ('walk_circle_within_fraction', 1.0, 'met'),  # the README's walks: every seed
    ('walk_circle_within_fraction', 0.875, 'MISSED'),
])
def test_walking_targets_are_no_fall(key: str, value: float, verdict: str) -> None:
    assert run_bench.verdicts({key: value}, 'lz4') == {key: verdict}
    assert run_bench.verdicts({'walk_pushes_fell_fraction_175n': 0.5}, 'lz4') == {}
