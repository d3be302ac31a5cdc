"""A lone stance sole across facets: its wrench's pressure centre kept near the one asked
or where the sole bears.

The whole-body layer keeps each sole's pressure centre inside the sole's rectangle, and the
pelvis task's moment moves it there from where the capture point's law asks (on the floor
by up to 7 cm: 60 N m of pitch on 900 N). The whole sole bears on a plane (the floor, a
ramp, one facet), and a pressure centre at its edge is one it can hold. The course's hills
are a heightfield of 0.195 m cells in 14 mm height steps, facets 4 to 13 degrees apart: a
sole on them rests on two or three points, near one end or one edge. There the pelvis's
moment took the stance sole's pressure centre to its edge (6 cm ahead and 3 cm across of the
asked one, 50 to 100 N m) where nothing bore: the sole rolled over about its points, 10 to 30
degrees within 0.1 s of taking the weight (30 of 178 steps), and the walker fell.

So a stance sole whose contacts are not on one plane (their normals more than 2 degrees
apart) keeps its wrench's pressure centre within SHIFT_M of the one asked or of the points
it bears on, whichever reaches further (`bearing_span`: the box of its contacts within
PRESSED_M of their surface, along and across it): the pelvis task gets what moment that
leaves. A sole on one plane is left as it was (any flat walk: the same torques). Near the
asked one alone was too little on the pit's ramps (heightfield too, curved: a sole on them
is across facets nearly all the way down, bearing at both ends), and every walk from the mud
start fell on the entry ramp; with the bearing points the ramp's soles keep most of their
length. The rule acts with LegGains.near_cop_m set (SHIFT_M by default; None: off).

A compiled estimate sums each sole's contacts up as it copies them (BalanceState.sole_bearing:
the flag and the box, src/atlas_estimator.c), and stance_rule reads that; the functions below
are the reference, for a state without a row (a Python estimate's, or one made from fields).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tutorial_atlas_control.balance import (
    ONE_SURFACE_COS,
    PRESSED_M,
    UPRIGHT_COS,
    BalanceState,
    ContactConstraint,
)

__all__ = ['NO_SPAN', 'ONE_SURFACE_COS', 'PRESSED_M', 'SHIFT_M', 'Span', 'UPRIGHT_COS',
           'across_facets', 'bearing_span', 'near_asked', 'stance_contacts', 'stance_rule']

#: How far (m) along and across the sole the wrench's pressure centre may be from the one
#: asked or from the points the sole bears on, across facets.
SHIFT_M = 0.02

#: The box of a sole's bearing points in its own frame (m, from its centre): lowest and
#: highest along it, lowest and highest across it.
Span = tuple[float, float, float, float]
#: No bearing point: the box of the asked pressure centre alone (the sole's centre's).
NO_SPAN: Span = (np.inf, -np.inf, np.inf, -np.inf)


def _bearing(state: BalanceState, foot: int) -> tuple[list[list[float]], list[list[float]]]:
    """The points and normals (world, as lists: a sole has a few, and a Python loop over them
    costs less than numpy's calls, every swinging tick) of the sole `foot`'s bearing
    contacts: within PRESSED_M of their surface, facing within acos(UPRIGHT_COS) of up."""
    contacts = state.sole_contacts[foot]
    if not len(contacts.distances_m):
        return [], []
    points, normals = contacts.points.tolist(), contacts.normals.tolist()
    kept = [k for k, (gap, normal) in enumerate(zip(contacts.distances_m.tolist(), normals))
            if gap <= PRESSED_M and normal[2] >= UPRIGHT_COS]
    return [points[k] for k in kept], [normals[k] for k in kept]


def _apart(normals: list[list[float]]) -> bool:
    """Whether some of `normals` lie more than acos(ONE_SURFACE_COS) from the first."""
    if len(normals) < 2:
        return False
    x, y, z = normals[0]
    return any(x * a + y * b + z * c < ONE_SURFACE_COS for a, b, c in normals[1:])


def across_facets(state: BalanceState, foot: int) -> bool:
    """Whether the sole `foot` bears on more than one plane (the normals of its bearing
    contacts apart)."""
    return _apart(_bearing(state, foot)[1])


def _span_of(state: BalanceState, foot: int, points: list[list[float]]) -> Span:
    """The box (sole frame, m) of `points` (world) on the sole `foot`; NO_SPAN for none."""
    if not points:
        return NO_SPAN
    (r00, r01, _), (r10, r11, _), (r20, r21, _) = state.sole_rotations[foot].tolist()
    cx, cy, cz = state.sole_centres[foot].tolist()
    along, across = [], []
    for x, y, z in points:
        dx, dy, dz = x - cx, y - cy, z - cz
        along.append(dx * r00 + dy * r10 + dz * r20)
        across.append(dx * r01 + dy * r11 + dz * r21)
    return min(along), max(along), min(across), max(across)


def bearing_span(state: BalanceState, foot: int) -> Span:
    """The box (sole frame, m) of the bearing contacts of the sole `foot` (within PRESSED_M
    of their surface, facing up): where it bears; NO_SPAN when none does."""
    return _span_of(state, foot, _bearing(state, foot)[0])


def near_asked(state: BalanceState, foot: int, contact: ContactConstraint,
               cop: np.ndarray, shift_m: float = SHIFT_M, span: Span = NO_SPAN
               ) -> ContactConstraint:
    """`contact` (the sole `foot`'s) with its pressure centre kept within `shift_m` of `cop`
    ((2,) m, world; on the sole) or of the box `span` (bearing_span's), along and across the
    sole, and on the sole."""
    rotation, centre = state.sole_rotations[foot], state.sole_centres[foot]
    (r00, r01, _), (r10, r11, _), _ = rotation.tolist()
    dx, dy = float(cop[0] - centre[0]), float(cop[1] - centre[1])
    asked = (r00 * dx + r10 * dy, r01 * dx + r11 * dy)
    halves = (contact.half_length_m, contact.half_width_m)
    low = [max(min(a, s) - shift_m, -h) for a, s, h in zip(asked, span[0::2], halves)]
    high = [min(max(a, s) + shift_m, h) for a, s, h in zip(asked, span[1::2], halves)]
    high = [max(hi, lo) for lo, hi in zip(low, high)]  # a point at worst
    return replace(contact, half_length_m=0.5 * (high[0] - low[0]),
                   half_width_m=0.5 * (high[1] - low[1]),
                   centre_m=(0.5 * (low[0] + high[0]), 0.5 * (low[1] + high[1])))


def stance_rule(state: BalanceState, stance: int, near_cop_m: float | None
                ) -> tuple[float, Span]:
    """How near (m) the lone stance sole `stance`'s wrench's pressure centre stays to the one
    asked or its bearing points, and their box: (`near_cop_m`, bearing_span's box) across
    facets; (0.0, NO_SPAN), the whole sole, on one plane or with the rule off (None). The
    one decision both the compiled tick and the Python read; from the compiled estimate's
    summary of the sole's contacts where the state has one (BalanceState.sole_bearing: five
    floats, about 0.5 us), else from its contacts (the reference)."""
    if near_cop_m is None:
        return 0.0, NO_SPAN
    summed = state.sole_bearing(stance)
    if summed is not None:
        across, *box = summed
        return (near_cop_m, (box[0], box[1], box[2], box[3])) if across else (0.0, NO_SPAN)
    points, normals = _bearing(state, stance)
    if not _apart(normals):
        return 0.0, NO_SPAN
    return near_cop_m, _span_of(state, stance, points)


def stance_contacts(state: BalanceState, stance: int,
                    contacts: tuple[ContactConstraint, ContactConstraint], cop: np.ndarray,
                    near_cop_m: float | None
                    ) -> tuple[ContactConstraint, ContactConstraint] | None:
    """`contacts` (the soles' while the other foot swings) with the stance sole's kept
    within stance_rule's distance of `cop` or its bearing points across facets; None
    (`contacts` as they are) else."""
    near, span = stance_rule(state, stance, near_cop_m)
    if near <= 0.0:
        return None
    kept = list(contacts)
    kept[stance] = near_asked(state, stance, kept[stance], cop, near, span)
    return kept[0], kept[1]
