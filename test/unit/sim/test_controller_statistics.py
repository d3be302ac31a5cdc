"""Command age statistics (DRCSim's /atlas/controller_statistics), without ROS."""

from __future__ import annotations

import numpy as np
import pytest

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.sim.controller_statistics import (
    CommandAgeStatistics,
    StatisticsConfigError,
    update_period_ns,
    window_steps,
)

DT_S = 0.001
STEP_NS = 1_000_000


def held_commands_variance_s2(period_steps: int, window: int) -> float:
    """Closed form: a command held `period_steps` steps has ages d..d+P-1 steps; over a window
    of whole periods the population variance is (P^2 - 1) / 12 steps^2, times W / (W - 1)."""
    return (period_steps ** 2 - 1) / 12.0 * DT_S ** 2 * window / (window - 1)


def run_50_hz(stats: CommandAgeStatistics, steps: int, delay_steps: int = 1) -> None:
    """Commands stamped `now` every 20 ms, each applied `delay_steps` steps later."""
    for k in range(1, steps + 1):
        now_ns = k * STEP_NS
        if k > delay_steps and (k - delay_steps) % 20 == 0:
            stats.command_applied((k - delay_steps) * STEP_NS, now_ns)
        stats.update(now_ns)


def test_50_hz_commands_match_the_closed_form() -> None:
    stats = CommandAgeStatistics(DT_S, window_s=1.0)
    run_50_hz(stats, 5000)
    assert stats.window_steps == 1000 and stats.window_s == 1.0
    assert stats.mean_s == pytest.approx(0.0105, abs=1e-15)  # ages 1..20 ms
    assert stats.variance_s2 == pytest.approx(held_commands_variance_s2(20, 1000), rel=1e-12)
    assert stats.variance_s2 == pytest.approx(33.28e-6, abs=0.01e-6)
    assert stats.age_s == pytest.approx(0.001 * (5000 % 20 - 1 if 5000 % 20 else 20))


def test_mean_and_variance_equal_numpy_over_a_sliding_window() -> None:
    rng = np.random.default_rng(5)
    stats = CommandAgeStatistics(DT_S, window_s=0.25)
    ages_ns = []
    stamp_ns = 0
    for k in range(1, 3001):
        now_ns = 7 * 10 ** 12 + k * STEP_NS  # two hours in: large ages must stay exact
        if rng.random() < 0.3:
            stamp_ns = now_ns - int(rng.integers(0, 40)) * STEP_NS - int(rng.integers(0, 1000))
            stats.command_applied(stamp_ns, now_ns)
        stats.update(now_ns)
        ages_ns.append(now_ns - stamp_ns if stamp_ns else now_ns)
        window = np.array(ages_ns[-250:], dtype=np.float64) / 1e9
        assert stats.samples == len(window)
        assert stats.age_s == window[-1]
        assert stats.mean_s == pytest.approx(window.mean(), rel=1e-12)
        if len(window) > 1:
            assert stats.variance_s2 == pytest.approx(window.var(ddof=1), rel=1e-9, abs=1e-18)


def test_before_any_command_the_age_is_the_time_since_start() -> None:
    stats = CommandAgeStatistics(DT_S)
    for k in range(1, 4):
        stats.update(1_500 * STEP_NS + k * STEP_NS)
    assert stats.age_s == pytest.approx(1.503)
    assert stats.mean_s == pytest.approx(1.502)
    assert stats.variance_s2 == pytest.approx(1e-6)  # 1.501, 1.502, 1.503 s


def test_a_zero_stamp_counts_as_stamped_when_applied() -> None:
    stats = CommandAgeStatistics(DT_S)
    stats.command_applied(0, 40 * STEP_NS)
    stats.update(40 * STEP_NS)
    assert stats.age_s == 0.0
    stats.update(41 * STEP_NS)
    assert stats.age_s == pytest.approx(0.001)


def test_a_gap_or_a_rewind_starts_a_new_window() -> None:
    stats = CommandAgeStatistics(DT_S, window_s=0.01)
    for k in range(1, 21):
        stats.update(k * STEP_NS)
    assert stats.samples == 10
    stats.update(30 * STEP_NS)  # nobody subscribed for 9 steps: those ages were never taken
    assert stats.samples == 1 and stats.variance_s2 == 0.0
    assert stats.mean_s == pytest.approx(0.030)
    stats.forget_command()
    stats.update(STEP_NS)  # reset_simulation: time back to 0
    assert stats.samples == 1 and stats.mean_s == pytest.approx(0.001)


def test_publication_rate() -> None:
    every_step = CommandAgeStatistics(DT_S)
    assert all(every_step.publication_due(k * STEP_NS) for k in range(1, 10))
    at_300_hz = CommandAgeStatistics(DT_S, update_rate_hz=300.0)
    due = [k for k in range(1, 30) if at_300_hz.publication_due(k * STEP_NS)]
    assert due == [1, 5, 9, 13, 17, 21, 25, 29]  # 3.33 ms apart at least, on 1 ms steps
    assert at_300_hz.publication_due(2 * STEP_NS)  # time rewound: publish at once


@pytest.mark.parametrize(('rate_hz', 'period_ns'), [
    (None, 0), (1000.0, 1_000_000), (0.0, 10 ** 9), (-5, 10 ** 9), (1e6, 100_000),
    (250, 4_000_000)])
def test_update_rate_is_clamped_to_1_to_10000_hz(rate_hz: float | None, period_ns: int) -> None:
    assert update_period_ns(rate_hz) == period_ns


@pytest.mark.parametrize('bad', ['fast', float('nan'), float('inf'), True, [10]])
def test_bad_update_rate_names_the_parameter(bad: object) -> None:
    with pytest.raises(StatisticsConfigError,
                       match=r'^parameter /atlas/controller_statistics/update_rate '
                             r'is .*rate in Hz'):
        update_period_ns(bad)  # type: ignore[arg-type]


@pytest.mark.parametrize('bad', [0.0, -1.0, float('nan'), 1e9, 'long', False])
def test_bad_window_names_the_parameter(bad: object) -> None:
    with pytest.raises(StatisticsConfigError,
                       match=r'^parameter atlas_controller/statistics_time_window_size '
                             r'is .*seconds'):
        window_steps(bad, DT_S)  # type: ignore[arg-type]
    assert issubclass(StatisticsConfigError, AtlasControlError)


def test_window_is_whole_steps_and_at_least_two() -> None:
    assert window_steps(1.0, DT_S) == 1000
    assert window_steps(0.0104, DT_S) == 10
    assert window_steps(1e-6, DT_S) == 2
    assert CommandAgeStatistics(DT_S, window_s=0.0104).window_s == 0.01
