"""DRCSim's VRC Task 2 scoring on synthetic runs: the pelvis teleported through the gates
(in order, out of order, backwards, twice, without gate_0) and the head's velocity jumping,
stepped at 1 ms as the simulator steps it; scores, times and messages as the plugin's code
gives them."""

from __future__ import annotations

import math

import pytest

from tutorial_atlas_control.course import GATES, STARTS, CourseError, Scorer, ScoreRow

MS = 1_000_000
S = 1_000_000_000
WALL_START_NS = 1_700_000_000 * S
START = STARTS['vrc_task_2']
#: East of every gate's width: no gate's side there (0).
OFF_THE_GATES = (20.0, -30.0)


def at_gate(index: int, local_x_m: float, local_y_m: float = 0.0) -> tuple[float, float]:
    """A world (x, y) in gate `index`'s frame (x along the way through, y across)."""
    gate = GATES[index]
    c, s = math.cos(gate.yaw_rad), math.sin(gate.yaw_rad)
    return gate.x_m + c * local_x_m - s * local_y_m, gate.y_m + s * local_x_m + c * local_y_m


def through(index: int, t_s: float) -> list[tuple[float, tuple[float, float]]]:
    """Teleports just before gate `index` at t_s and just after it 1 ms later."""
    return [(t_s, at_gate(index, -0.3)), (t_s + 0.001, at_gate(index, 0.3))]


def run(teleports: list[tuple[float, tuple[float, float]]], end_s: float,
        head_vz: list[tuple[float, float]] = (), wall_per_sim: float = 2.0) -> list[ScoreRow]:
    """The scorer stepped every 1 ms up to end_s: the pelvis where the last teleport put it
    (from DRCSim's start in the pen), the head's z velocity the last value set (0 at first),
    wall time running `wall_per_sim` times sim time; every row it gave."""
    scorer = Scorer(WALL_START_NS)
    moves = sorted((round(t * 1000), pos) for t, pos in teleports)
    speeds = sorted((round(t * 1000), vz) for t, vz in head_vz)
    position, vz, rows = (START.x_m, START.y_m), 0.0, []
    for step in range(1, round(end_s * 1000) + 1):
        while moves and moves[0][0] <= step:
            position = moves.pop(0)[1]
        while speeds and speeds[0][0] <= step:
            vz = speeds.pop(0)[1]
        row = scorer.step(step * MS, WALL_START_NS + round(step * MS * wall_per_sim),
                          position[0], position[1], vz)
        if row is not None:
            rows.append(row)
    return rows


def events(rows: list[ScoreRow]) -> list[tuple[int, str]]:
    return [(row.sim_time_ns, row.message) for row in rows if row.message]


def test_every_gate_in_order_scores_4_and_times_gate_0_to_gate_4() -> None:
    teleports = [pose for k, t in enumerate((20, 30, 40, 50, 60)) for pose in through(k, t)]
    rows = run(teleports, 70.0)
    assert events(rows) == [
        (20_001 * MS, 'Successfully passed through gate 1. Starting clock. '),
        (30_001 * MS, 'Successfully passed through gate 2. '),
        (40_001 * MS, 'Successfully passed through gate 3. '),
        (50_001 * MS, 'Successfully passed through gate 4. '),
        (60_001 * MS, 'Successfully passed through gate 5. Stopping clock. ')]
    last = rows[-1]
    assert (last.completion, last.falls) == (4, 0)
    assert last.sim_since_gate0_ns == 40 * S  # stopped at gate_4
    assert last.wall_since_gate0_ns == 80 * S
    # The 1 s rows run on from the last event's row (at 60.001 s).
    assert last.sim_time_ns == 69_001 * MS and last.wall_elapsed_ns == 138_002 * MS
    at_gate_2 = next(row for row in rows if row.sim_time_ns == 30_001 * MS)
    assert (at_gate_2.completion, at_gate_2.sim_since_gate0_ns) == (1, 10 * S)


def test_gates_out_of_order_count_only_the_next_one() -> None:
    # Gate_1 and gate_2 share one width (x within ±2.6 m): anywhere north of gate_1 there
    # is its far side, so the robot leaves the width before it is put at gate_2.
    teleports = (through(0, 20) + [(24.0, OFF_THE_GATES)] + through(2, 25) + through(1, 30)
                 + through(3, 35) + through(4, 40))
    rows = run(teleports, 45.0)
    assert events(rows) == [(20_001 * MS, 'Successfully passed through gate 1. Starting clock. '),
                            (30_001 * MS, 'Successfully passed through gate 2. ')]
    last = rows[-1]
    assert last.completion == 1
    assert last.sim_since_gate0_ns == last.sim_time_ns - 20_001 * MS  # the clock runs on


def test_teleporting_past_a_gate_within_its_width_passes_it() -> None:
    """DRCSim's rule has no line to cross: from gate_0's exit (behind gate_1, within its
    width) a teleport to gate_2's approach is on gate_1's far side, and passes it."""
    rows = run(through(0, 20) + through(2, 25), 30.0)
    assert events(rows)[-1] == (25_000 * MS, 'Successfully passed through gate 2. ')
    # One teleport from before gate_1 to past gate_2 passes gate_1 only: the side resets to
    # 0 on a pass, so gate_2 needs its own -1 first.
    rows = run(through(0, 20) + [(25.0, at_gate(1, -0.3)), (26.0, at_gate(2, 0.3))], 30.0)
    assert events(rows)[-1] == (26_000 * MS, 'Successfully passed through gate 2. ')
    assert rows[-1].completion == 1


def test_backwards_through_a_gate_scores_nothing_and_forwards_again_does() -> None:
    # Gate_0 entered from its far side (from beyond its width), then left backwards.
    rows = run([(10.0, at_gate(0, 0.3, 4.0)), (11.0, at_gate(0, 0.3)), (12.0, at_gate(0, -0.3))],
               15.0)
    assert events(rows) == [] and rows[-1].sim_since_gate0_ns == 0
    # Gate_1 the same way, then forwards again: it counts.
    rows = run(through(0, 10.0) + [(15.0, OFF_THE_GATES), (19.0, at_gate(1, 0.3)),
                                   (20.0, at_gate(1, -0.3)), (21.0, at_gate(1, 0.3))], 25.0)
    assert events(rows)[-1] == (21_000 * MS, 'Successfully passed through gate 2. ')
    assert rows[-1].completion == 1


def test_a_repeated_gate_counts_once() -> None:
    teleports = through(0, 20) + through(1, 30) + through(1, 31) + through(1, 32)
    rows = run(teleports, 35.0)
    assert [t for t, _ in events(rows)] == [20_001 * MS, 30_001 * MS]
    last = rows[-1]
    assert last.completion == 1
    assert last.sim_since_gate0_ns == last.sim_time_ns - 20_001 * MS  # the clock still runs


def test_without_gate_0_no_gate_scores_and_no_clock_starts() -> None:
    teleports = [pose for k, t in enumerate((30, 40, 50, 60), 1) for pose in through(k, t)]
    # Gate_0's +1 side is never reached with the side at -1 just before: from outside its
    # width (the gate_1 approach is 16 m north of it), the side went 0.
    rows = run([(10.0, at_gate(0, -0.3, 10.0))] + teleports, 65.0)
    assert events(rows) == []
    assert (rows[-1].completion, rows[-1].sim_since_gate0_ns,
            rows[-1].wall_since_gate0_ns) == (0, 0, 0)


def test_passing_needs_the_side_change_inside_the_width() -> None:
    # -1 inside, then beyond the post (|y| > 2.6), then +1 inside: the side went 0.
    rows = run([(10.0, at_gate(0, -0.3, 2.5)), (11.0, at_gate(0, 0.3, 2.61)),
                (12.0, at_gate(0, 0.3, 2.0)), (13.0, at_gate(0, -0.3, 2.0))], 14.0)
    assert events(rows) == []
    # Just inside the width's edge, and x = 0 is the far side.
    rows = run([(10.0, at_gate(0, -0.3, 2.599)), (11.0, at_gate(0, 0.0, 2.599))], 12.0)
    assert events(rows) == [(11_000 * MS, 'Successfully passed through gate 1. Starting clock. ')]


def test_rows_every_second_of_sim_time_and_at_each_event() -> None:
    rows = run(through(0, 3.5), 6.0)
    assert [row.sim_time_ns for row in rows] == [
        1 * S, 2 * S, 3 * S, 3_501 * MS, 4_501 * MS, 5_501 * MS]
    assert rows[0].message == '' and rows[0].sim_since_gate0_ns == 0
    assert rows[-1].sim_since_gate0_ns == 2 * S and rows[-1].wall_since_gate0_ns == 4 * S


def test_head_velocity_jump_counts_one_fall_and_none_within_15_s() -> None:
    # At 20 s the head's z velocity drops by 2 m/s in one step: 2000 m/s² > 1000.
    rows = run([], 40.0, head_vz=[(20.0, -2.0), (21.0, 0.0), (34.9, -2.0), (35.1, 0.0)])
    assert events(rows) == [
        (20_000 * MS, 'Damaging fall detected, acceleration of: -2000 m/s^2. '),
        (35_100 * MS, 'Damaging fall detected, acceleration of: 2000 m/s^2. ')]
    assert [row.falls for row in rows if row.message] == [1, 2]


def test_no_fall_counts_over_the_first_15_s_nor_below_the_threshold() -> None:
    rows = run([], 20.0, head_vz=[(5.0, -3.0), (14.99, 0.0), (16.0, -0.99), (17.0, 0.0)])
    assert events(rows) == [] and rows[-1].falls == 0


def test_falls_stop_counting_5_s_after_the_clock_stopped() -> None:
    teleports = [pose for k, t in enumerate((20, 21, 22, 23, 24)) for pose in through(k, t)]
    within = run(teleports, 40.0, head_vz=[(28.9, -2.0)])
    assert within[-1].falls == 1
    after = run(teleports, 40.0, head_vz=[(29.002, -2.0)])
    assert after[-1].falls == 0 and after[-1].completion == 4


def test_a_start_on_the_far_side_of_gate_0_passes_it_at_once() -> None:
    """The plugin's first side is -1, so a robot put down past gate_0 passes it in the first
    update (DRCSim's own quirk, kept)."""
    rows = run([(0.001, at_gate(0, 0.3))], 2.0)
    assert events(rows) == [(1 * MS, 'Successfully passed through gate 1. Starting clock. ')]


def test_log_line_is_drcsims_row() -> None:
    row = ScoreRow(12_345_678_901, 20_001 * MS, 4 * S, 2 * S, 1, 0,
                   'Successfully passed through gate 2. ')
    assert row.log_line() == ('12.346,20.001,4.000,2.000,1,0,'
                              '"Successfully passed through gate 2. "\n')


def test_bad_settings_are_refused() -> None:
    with pytest.raises(CourseError, match='no gates'):
        Scorer(0, gates=())
    with pytest.raises(CourseError, match='fall_accel_threshold'):
        Scorer(0, fall_accel_threshold=float('nan'))
