"""A recorded run on DRCSim's VRC Task 2 course, as the map draws it: the pelvis's path,
where the feet landed on the terrain, the falls and the score's events, each placed where the
pelvis was.

The feet's landings are bags/footprints.py's, found on the height above the terrain under
the foot (bags/course_terrain.py) instead of above z 0: a foot standing on the course's
ground (z 0.03, the pit at -0.6, the hills) is down; on a cinder block it is not.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from tutorial_atlas_control.bags.course_terrain import above_ground, ground_under, terrain_heights
from tutorial_atlas_control.bags.footprints import Landing, foot_poses, landings
from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.bags.vrc_score import ScoreEntry
from tutorial_atlas_control.sim import FALL_HEIGHT_M

if TYPE_CHECKING:
    from tutorial_atlas_control.balance import SoleBox

__all__ = ['CourseRun', 'MapMark', 'read_course_run', 'recorded_course_run',
           'terrain_landings']

#: Most pelvis points kept for the path drawn.
PATH_MAX_POINTS = 5000


@dataclass(frozen=True)
class MapMark:
    """Something placed on the map: where the pelvis was (m), when (s of sim time), what."""

    x_m: float
    y_m: float
    sim_time_s: float
    text: str


@dataclass(frozen=True)
class CourseRun:
    """What the map draws of a run: the pelvis's (x, y) path (n, 2), the feet's landings on
    the terrain, the falls and the score's events (gates), and the last score row."""

    pelvis_xy: np.ndarray
    landings: list[Landing] = field(default_factory=list)
    falls: list[MapMark] = field(default_factory=list)
    events: list[MapMark] = field(default_factory=list)
    last_score: ScoreEntry | None = None
    sole: SoleBox | None = None


def _run_time_of(data: BagData, sim_times_s: list[float]) -> list[float]:
    """Each sim time (in order) on the run timeline: in the first epoch, from the previous
    one's on, that holds it (a reset_simulation sends sim time back)."""
    starts = [0.0, *data.epoch_starts_s, np.inf]
    epoch, found = 0, []
    for sim_s in sim_times_s:
        for candidate in range(epoch, len(starts) - 1):
            run_s = data.run_time_s(sim_s, candidate)
            if run_s < starts[candidate + 1] or candidate == len(starts) - 2:
                epoch = candidate
                break
        found.append(data.run_time_s(sim_s, epoch))
    return found


def _pelvis_at(data: BagData, t_s: float) -> tuple[float, float]:
    pelvis = data.pelvis
    assert pelvis is not None
    row = int(np.clip(np.searchsorted(pelvis.t_s, t_s, side='right') - 1, 0,
                      len(pelvis.t_s) - 1))
    return float(pelvis.position_m[row, 0]), float(pelvis.position_m[row, 1])


def _score_marks(data: BagData, scores: list[ScoreEntry]) -> tuple[list[MapMark],
                                                                    list[MapMark]]:
    """The scored falls (each row whose falls went up) and the events (rows with a
    message other than a fall's), placed at the pelvis."""
    run_times = _run_time_of(data, [entry.sim_time_s for entry in scores])
    falls, events, counted = [], [], 0
    for entry, run_s in zip(scores, run_times):
        x, y = _pelvis_at(data, run_s)
        if entry.falls > counted:
            falls.append(MapMark(x, y, entry.sim_time_s, f'fall {entry.falls} (scored)'))
            counted = entry.falls
        text = ' '.join(part.strip() for part in entry.message.split('. ')
                        if part.strip() and not part.strip().startswith('Damaging fall'))
        if text:
            events.append(MapMark(x, y, entry.sim_time_s, text.rstrip('.')))
    return falls, events


def terrain_landings(foot_index: int, t_s: np.ndarray, position_m: np.ndarray,
                     yaw_rad: np.ndarray, standing_m: float, heights: np.ndarray
                     ) -> list[Landing]:
    """footprints.landings on the foot link's height above the terrain under it: `heights`
    the course's (terrain_heights), `standing_m` the link's height with the sole flat on
    flat ground."""
    return landings(foot_index, t_s, above_ground(position_m, heights), yaw_rad, standing_m)


def _landings_on_terrain(data: BagData, heights: np.ndarray
                         ) -> tuple[list[Landing], SoleBox | None]:
    """Both feet's landings over the whole run, on their height above the terrain."""
    if data.joint_states is None or not len(data.joint_states.t_s):
        return [], None
    t_s, positions, yaws, standing_m, sole = foot_poses(data, 0.0)
    found = [landing for foot in (0, 1) for landing in terrain_landings(
        foot, t_s, positions[foot], yaws[foot], standing_m, heights)]
    return sorted(found, key=lambda landing: landing.t_s), sole


def _low_over_terrain(data: BagData, heights: np.ndarray) -> list[float]:
    """When the pelvis first came within FALL_HEIGHT_M of the terrain under it (s from the
    bag's start; sim/fall.py's criterion with the ground under the pelvis, not the soles),
    once per try: the run's fall time for a bag without the simulator's fall lines."""
    pelvis = data.pelvis
    assert pelvis is not None
    above = pelvis.position_m[:, 2] - ground_under(heights, pelvis.position_m[:, 0],
                                                    pelvis.position_m[:, 1])
    low = above < FALL_HEIGHT_M
    tries = [0.0, *[float(t_s) for t_s, _ in data.sim_configs[1:]], np.inf]
    found = []
    for begin, end in zip(tries, tries[1:]):
        rows = np.flatnonzero(low & (pelvis.t_s >= begin) & (pelvis.t_s < end))
        if len(rows):
            found.append(float(pelvis.t_s[rows[0]]))
    return found


def read_course_run(data: BagData, scores: list[ScoreEntry] | None,
               fall_times_s: list[float] | None = None) -> CourseRun | None:
    """The map's figures of `data`'s run (None: no pelvis pose recorded): the path, the
    landings, the scored falls and the run's own falls, `fall_times_s` (s from the bag's
    start: the simulator's fall lines; None: the pelvis low over the terrain), and the
    score's events."""
    pelvis = data.pelvis
    if pelvis is None or not len(pelvis.t_s):
        return None
    heights = terrain_heights()
    step = max(1, len(pelvis.t_s) // PATH_MAX_POINTS)
    path = pelvis.position_m[::step, :2].copy()
    falls, events = _score_marks(data, scores) if scores else ([], [])
    if fall_times_s is None:
        fall_times_s = _low_over_terrain(data, heights)
    for t_s in fall_times_s:
        x, y = _pelvis_at(data, t_s)
        falls.append(MapMark(x, y, data.sim_time_s(t_s), 'fell (pelvis low)'))
    found, sole = _landings_on_terrain(data, heights)
    return CourseRun(path, found, falls, events, scores[-1] if scores else None, sole)


def recorded_course_run(data: BagData, scores: list[ScoreEntry] | None) -> CourseRun | None:
    """read_course_run with the run's falls as the bag tells them: the simulator's fall
    lines, or, when it logged none, the pelvis low over the terrain."""
    return read_course_run(data, scores, [t_s for t_s, _ in data.logged_falls] or None)
