"""A way across the rubble (course/rubble_way.py): around every block and gate post with the
clearance the feet need, on the shipped rubble and the finals' rearranged one, in few
straight lines; the blocks' footprints as they lie; refusals in one line."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tutorial_atlas_control.course import (
    BLOCKS,
    CLEARANCE_M,
    COURSE_LEGS,
    Block,
    CourseError,
    block_footprint,
    clear_path,
    distance_to_polygon,
    leg_waypoints,
    point_clearances_m,
    rearranged_blocks,
    sole_clearances_m,
)
from tutorial_atlas_control.course.grid_path import TURN_RADIUS_M, inside_turn
from tutorial_atlas_control.course.rubble_way import GRID_M, SHORTCUT_SLACK_M

#: The least a planned line keeps from a block: the clearance less the shortcut's slack, to
#: within a grid cell (the lines are checked on the cells' centres).
KEPT_M = CLEARANCE_M - SHORTCUT_SLACK_M - GRID_M

#: The gate_3 leg's end and the gate_4 leg's goal.
FROM, TO = (6.0, 7.0), (6.0, 18.5)


def nearest_block_m(blocks: tuple[Block, ...], start: tuple[float, float],
                    waypoints: tuple[tuple[float, float], ...]) -> float:
    """The closest any point of the straight lines start..waypoints comes to a block."""
    points = np.array([start, *waypoints])
    samples = np.concatenate([np.linspace(a, b, max(2, int(np.hypot(*(b - a)) / 0.01)))
                              for a, b in zip(points[:-1], points[1:])])
    return min(float(distance_to_polygon(block_footprint(b), samples[:, 0],
                                         samples[:, 1]).min()) for b in blocks)


@pytest.mark.parametrize('blocks', [BLOCKS, rearranged_blocks(BLOCKS, 2013)],
                         ids=['shipped', 'finals'])
def test_the_way_across_keeps_the_feet_clear_of_every_block(blocks: tuple[Block, ...]) -> None:
    waypoints = clear_path(blocks, (6.0, 6.6), TO)
    assert waypoints[-1] == TO
    assert nearest_block_m(blocks, (6.0, 6.6), waypoints) >= KEPT_M
    assert len(waypoints) <= 10
    legs = np.diff(np.array([(6.0, 6.6), *waypoints]), axis=0)
    assert np.hypot(*legs.T).min() > 0.2  # corners, not the grid's jitter
    # The straight line would have run into blocks.
    assert nearest_block_m(blocks, (6.0, 6.6), (TO,)) < KEPT_M


def test_without_blocks_it_goes_straight_and_one_block_makes_a_detour() -> None:
    assert clear_path((), (6.0, 8.0), (6.0, 12.0)) == ((6.0, 12.0),)
    block = Block('b', 6.0, 10.0, 0.0, 0.0, 0.0, 0.0)  # lying flat across the line
    waypoints = clear_path((block,), (6.0, 8.0), (6.0, 12.0))
    assert len(waypoints) >= 2
    assert nearest_block_m((block,), (6.0, 8.0), waypoints) >= KEPT_M


def test_a_walker_nearer_a_block_than_the_clearance_first_steps_away() -> None:
    block = Block('b', 6.0, 8.3, 0.0, 0.0, 0.0, 0.0)  # its edge 0.2 m ahead of the walker
    first = clear_path((block,), (6.0, 8.0), (6.0, 12.0))[0]
    start_m = distance_to_polygon(block_footprint(block), np.array(6.0), np.array(8.0))
    first_m = distance_to_polygon(block_footprint(block), np.array(first[0]),
                                  np.array(first[1]))
    assert start_m < CLEARANCE_M < first_m + 0.05


def test_no_way_or_a_goal_in_the_blocks_is_one_line() -> None:
    wall = tuple(Block(f'b{k}', 2.0 + 0.4 * k, 10.0, 0.0, 0.0, 0.0, 0.0) for k in range(21))
    with pytest.raises(CourseError, match=r'no way from \(6.00, 8.00\) to \(6.00, 12.00\) '
                                          'keeps 0.55 m from the blocks'):
        clear_path(wall, (6.0, 8.0), (6.0, 12.0))
    with pytest.raises(CourseError, match=r'the goal \(6.00, 10.00\) is within 0.55 m'):
        clear_path(wall, (6.0, 8.0), (6.0, 10.0))


@pytest.mark.parametrize('roll, pitch, size', [(0.0, 0.0, (0.435, 0.203)),
                                               (math.pi / 2, 0.0, (0.435, 0.203)),
                                               (0.0, math.pi / 2, (0.203, 0.203))],
                         ids=['flat', 'on its side', 'on end'])
def test_a_block_s_footprint_is_its_envelope_seen_from_above(roll: float, pitch: float,
                                                             size: tuple[float, float]) -> None:
    corners = block_footprint(Block('b', 1.0, 2.0, 0.0, roll, pitch, 0.0))
    extent = corners.max(axis=0) - corners.min(axis=0)
    assert extent == pytest.approx(size, abs=1e-6)
    # Turned about its frame (the envelope's bottom centre) it lies beside where it stood.
    centre = (corners.max(axis=0) + corners.min(axis=0)) / 2
    assert np.hypot(*(centre - (1.0, 2.0))) == pytest.approx(0.0 if roll == pitch == 0.0
                                                             else 0.1015, abs=1e-3)


def test_only_the_rubble_s_leg_is_planned_around_blocks() -> None:
    assert [leg.gate for leg in COURSE_LEGS if leg.clear_of_blocks] == ['gate_4']
    gate_2 = COURSE_LEGS[2]
    assert leg_waypoints(gate_2, 0.5, -21.0, BLOCKS) == gate_2.waypoints
    across = leg_waypoints(COURSE_LEGS[4], *FROM, BLOCKS)
    assert across[-1] == TO and len(across) > 1


#: Three blocks whose shortest way's third corner lies inside the turning circle at the second.
SLALOM = (Block('a', 20.19, 2.28, 0.0, 0.0, 0.0, 2.11),
          Block('b', 19.28, 4.59, 0.0, 0.0, 0.0, 1.15),
          Block('c', 19.05, 3.46, 0.0, 0.0, 0.0, 2.91))


@pytest.mark.parametrize('blocks, starts', [
    (BLOCKS, ((6.0, 6.6), (5.49, 6.02), (6.3, 6.7))),
    (rearranged_blocks(BLOCKS, 2013), ((6.0, 6.6), (5.49, 6.02), (6.3, 6.7))),
    (SLALOM, ((20.0, 0.0),))], ids=['shipped', 'finals', 'slalom'])
def test_every_corner_of_the_way_can_be_faced_by_a_walker_turning_in_strides(
        blocks: tuple[Block, ...], starts: tuple[tuple[float, float], ...]) -> None:
    for start in starts:
        points = [start, *clear_path(blocks, start, TO if blocks != SLALOM else (20.0, 6.0))]
        for before, corner, after in zip(points, points[1:], points[2:]):
            assert not inside_turn(before, corner, after, TURN_RADIUS_M - GRID_M)
        assert nearest_block_m(blocks, start, tuple(points[1:])) >= KEPT_M


def test_a_sole_s_clearance_is_the_gap_between_its_edge_and_a_block_s() -> None:
    block = Block('b', 6.0, 8.0, 0.0, 0.0, 0.0, 0.0)  # 0.435 m along x, 0.203 across
    half = (0.13, 0.0624)
    soles = [(6.0, 8.5, 0.0),                  # beside it: 0.5 - 0.1015 - 0.0624
             (6.0, 8.5, math.pi / 2),          # turned a quarter: 0.5 - 0.1015 - 0.13
             (6.5, 8.0, 0.0),                  # ahead: 0.5 - 0.2175 - 0.13
             (6.2, 8.05, 0.3),                 # on it
             (6.0, 8.0, math.pi / 2),          # across it, no corner on the other
             (6.0 + 0.2175 + 0.3, 8.1015 + 0.4, 0.0)]  # off its corner, diagonally
    clear = sole_clearances_m(soles, (block,), half)
    assert clear == pytest.approx([0.3361, 0.2685, 0.1525, 0.0, 0.0,
                                   math.hypot(0.3 - 0.13, 0.4 - 0.0624)], abs=1e-4)
    assert sole_clearances_m(soles[:1], (), half)[0] == math.inf
    # A point of a sensor's obstacles counts as a block does.
    near = sole_clearances_m(soles[:1], (), half, np.array([[6.0, 8.3]]))
    assert near[0] == pytest.approx(0.5 - 0.3 - 0.0624)
    # The centre line's points alike (around_blocks: where a walker beside a block is out).
    points = point_clearances_m(np.array([[6.0, 8.5], [6.0, 8.0]]), (block,),
                                np.array([[6.0, 8.3]]))
    assert points == pytest.approx([0.2, 0.0])
