"""The ground under a recorded run on DRCSim's VRC Task 2 course: whether the bag is such a
run, and the terrain's height under a world point.

A bag is a course run when the simulator's /atlas/sim_config names the course's model file
(as offline.world.recorded_world reads it back) or when the bag has /vrc_score. The terrain is
course/terrain.py's heights (the package's terrain image, the one the world's heightfield is
made of), re-exported here for the bag tools.
"""

from __future__ import annotations

import numpy as np

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.course import WORLD_MODEL_FILE, ground_under, terrain_heights
from tutorial_atlas_control.sim import SimConfig, SimConfigError

__all__ = ['above_ground', 'ground_under', 'is_course_run', 'terrain_heights']


def is_course_run(data: BagData) -> bool:
    """Whether `data`'s bag is a run on the VRC Task 2 course: a /atlas/sim_config naming the
    course's model file, or /vrc_score messages."""
    if getattr(data.topics.get(topics.VRC_SCORE), 'count', 0):
        return True
    for _t_s, text in data.sim_configs:
        try:
            config = SimConfig.from_json(text)
        except SimConfigError:
            continue
        if config.model_file == WORLD_MODEL_FILE:
            return True
    return False


def above_ground(position_m: np.ndarray, heights: np.ndarray | None) -> np.ndarray:
    """World points (n, 3) with z taken above the terrain under each (a copy); unchanged
    without `heights` (flat ground at z 0)."""
    above = np.array(position_m, dtype=float)
    if heights is not None:
        above[:, 2] -= ground_under(heights, above[:, 0], above[:, 1])
    return above
