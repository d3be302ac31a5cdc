"""Step adjustment: where the swing foot must land for the capture point a push left.

During a step the pressure centre stays inside the stance sole, so the walk's law
p = p_ref + (1 + k) e (e = xi - xi_ref) can take back only so much of an error e before it
saturates at the sole's edge; beyond that edge e grows as exp(omega t) and the planned next
foothold no longer catches the robot. The law and its clamp act on each axis of the stance
sole's frame apart (leg_tasks clamps the pressure centre to the sole's rectangle there), so
each axis is a 1-D system with a known solution:

    |e| <= a / (1 + k)   e(t) = e0 exp(-k omega t)                 (the law, unsaturated)
    beyond               e(t) = a + (e0 - a) exp(omega t)           (p held at the edge a)

until |e| comes back within a / (1 + k), after which it decays. The error predicted at
touchdown, carried to the next step, is what the foothold must move by: with the next step's
pressure centre moved by d, the capture point's plan at the start of that step moves by
d (1 - exp(-omega T_next)) (dcm_plan's backward recursion, the steps after it unchanged), so
the foot moves by e_td / (1 - exp(-omega T_next)). An undisturbed walk's small error decays
before touchdown and barely moves its feet; a push that saturates the sole moves them.
"""

from __future__ import annotations

import math

from tutorial_atlas_control.balance import capture_point_after


def predicted_error(error_m: float, reach_m: float, gain: float, omega: float,
                    remaining_s: float) -> float:
    """One axis's capture-point error (m) after `remaining_s` (s) under the law
    p - p_ref = (1 + gain) e with |p - p_ref| held within `reach_m` (m) towards the error."""
    if remaining_s <= 0.0:
        return error_m
    reach = max(reach_m, 0.0)
    magnitude, sign = abs(error_m), math.copysign(1.0, error_m)
    linear = reach / (1.0 + gain)  # the largest error the law takes back unsaturated
    if magnitude <= linear:
        return error_m * math.exp(-gain * omega * remaining_s)
    if magnitude < reach:  # saturated, but coming back: until it is within `linear`
        back_s = math.log((reach - linear) / (reach - magnitude)) / omega
        if back_s < remaining_s:
            return sign * linear * math.exp(-gain * omega * (remaining_s - back_s))
    return sign * capture_point_after(magnitude, reach, omega, remaining_s)  # p at the edge


def foothold_shift(error_xy: tuple[float, float], sole_heading: tuple[float, float],
                   cop_ref_offset: tuple[float, float], reach_xy: tuple[float, float],
                   gain: float, omega: float, remaining_s: float,
                   next_duration_s: float | None) -> tuple[float, float]:
    """How far (world x, y, m) the swing foot's landing moves for the capture-point error
    `error_xy` (world, m) with `remaining_s` (s) of the step left.

    `sole_heading`: the stance sole's x axis in the world (cos, sin of its yaw);
    `cop_ref_offset`: the plan's pressure centre less the sole's centre (world, m);
    `reach_xy`: how far the pressure centre may go from the sole's centre along its length
    and across it (m); `next_duration_s`: the step after this one (None: the walk catches
    itself on both feet after it, and nothing is carried). Plain floats: Walk calls it every
    1 ms of a step, where numpy's small-array overhead costs more than the arithmetic."""
    c, s = sole_heading
    error_x, error_y = error_xy
    offset_x, offset_y = cop_ref_offset
    predicted = []
    for error, offset, reach in ((c * error_x + s * error_y, c * offset_x + s * offset_y,
                                  reach_xy[0]),
                                 (c * error_y - s * error_x, c * offset_y - s * offset_x,
                                  reach_xy[1])):
        # The room from the plan's pressure centre to the sole's edge on the error's side.
        room = reach - (offset if error >= 0.0 else -offset)
        predicted.append(predicted_error(error, room, gain, omega, remaining_s))
    carried = 1.0 if next_duration_s is None else 1.0 / (
        1.0 - math.exp(-omega * next_duration_s))
    along, across = predicted
    return carried * (c * along - s * across), carried * (s * along + c * across)
