"""Stand's moving reference, made every tick of a take-over (start()) and of a servoed move
(with its rates, along the squat table), has the very bits of the arrays' arithmetic and
the dataclass it replaced: the capture points' blend in plain floats, the reference made
without the frozen __init__, d(vector)/ds only where it is read."""

from __future__ import annotations

import numpy as np

from tutorial_atlas_control.balance import StandBehaviour, smoothstep, smoothstep_rate
from tutorial_atlas_control.balance.manipulate import PelvisServo
from tutorial_atlas_control.balance.push_trial import standing_simulator
from tutorial_atlas_control.balance.stand import StandReference, pelvis_frame, yaw_rotation

_UP = np.array([0.0, 0.0, 1.0])
FIELDS = ('capture_point', 'com_height_m', 'pelvis_rotation', 'posture_rad',
          'com_height_rate_m_s', 'pelvis_angular_velocity', 'posture_rate_rad_s')


def _arrays_reference(stand: StandBehaviour, time_s: float) -> StandReference:
    """_reference_at before a transition's end, as it was computed on arrays."""
    transition = stand._transition
    assert transition is not None
    duration = stand.transition_s
    fraction = (time_s - transition.started_s) / duration
    s = smoothstep(fraction)
    start, goal = transition.vectors
    vector = (1.0 - s) * start + s * goal
    per_s = goal - start
    if transition.table is not None:
        low, high, low_row, high_row = transition.table
        row, slope = stand.squats.row((1.0 - s) * low + s * high)
        vector += row - ((1.0 - s) * low_row + s * high_row)
        per_s += slope * (high - low) - (high_row - low_row)
    start_yaw, turn = transition.yaws
    yaw, pitch = start_yaw + s * turn, float(vector[28])
    capture_point = ((1.0 - s) * transition.start.capture_point
                     + s * transition.goal.capture_point)
    if not transition.with_rates:
        return StandReference(capture_point, float(vector[29]), pelvis_frame(yaw, pitch),
                              vector[:28])
    s_rate = smoothstep_rate(fraction, duration)
    rate = per_s * s_rate
    return StandReference(
        capture_point, float(vector[29]), pelvis_frame(yaw, pitch), vector[:28],
        com_height_rate_m_s=float(rate[29]),
        pelvis_angular_velocity=turn * s_rate * _UP + rate[28] * yaw_rotation(yaw)[:, 1],
        posture_rate_rad_s=rate[:28])


def _same(first: StandReference, second: StandReference) -> bool:
    return all(np.asarray(getattr(first, name)).tobytes()
               == np.asarray(getattr(second, name)).tobytes() for name in FIELDS)


def test_the_moving_references_are_the_arrays_bit_for_bit() -> None:
    sim = standing_simulator()
    stand = StandBehaviour(sim.atlas)
    sim.install_stand(stand)
    reference_at = stand._reference_at
    checked = {False: 0, True: 0}

    def checking(time_s: float) -> StandReference:
        transition = stand._transition
        assert transition is not None
        expected = (_arrays_reference(stand, time_s)
                    if time_s - transition.started_s < stand.transition_s else None)
        made = reference_at(time_s)
        if expected is not None:
            assert _same(made, expected), time_s
            checked[transition.with_rates] += 1
        return made

    stand._reference_at = checking  # type: ignore[method-assign]
    for _ in range(1100):
        sim.step()
    stand.servo(PelvisServo(height_m=0.80, yaw_rad=0.1, lateral_m=0.02), float(sim.data.time))
    for _ in range(400):
        sim.step()
    assert checked[False] > 900 and checked[True] > 300
