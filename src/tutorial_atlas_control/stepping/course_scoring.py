"""The VRC course's scoring in the tick: course/scoring.py's Scorer fed after every step.

The tick calls it after the step's state is published, in the node's loop and offline runs
alike, so a run's score depends on its physics only (the wall-time columns aside). It reads
what VRCScoringPlugin read: the pelvis's position (the Atlas model's pose) and the head
link's z velocity at its origin, both as MuJoCo computed them at the step's start, and
gives them the sim time after the step: Gazebo called the plugin with the sim time already
advanced and the state of the step before. Each row goes to score.log and to `emit` (the
node's latched /vrc_score, an offline bag).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np

from tutorial_atlas_control.course import CourseError, ScoreLog, Scorer, ScoreRow
from tutorial_atlas_control.sim import AtlasSimulator

__all__ = ['HEAD_BODY', 'CourseScoring']

#: The link whose z acceleration counts falls (VRCScoringPlugin's atlasHead).
HEAD_BODY = 'head'


class CourseScoring:
    """One Scorer and its score.log for a simulator; call it after each step.

    Args:
        score_dir: where score.log goes (created if missing); None: no log (a replay's
            re-scoring).
        emit: each row, after it is in score.log (None: the log only).
        wall_clock: wall time (ns); the run's start is its first reading.

    Raises:
        CourseError: the model has no head link, or score.log cannot be written.
    """

    def __init__(self, sim: AtlasSimulator, score_dir: Path | None,
                 emit: Callable[[ScoreRow], None] | None = None,
                 wall_clock: Callable[[], int] = time.time_ns) -> None:
        self.sim = sim
        self.head = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, HEAD_BODY)
        if self.head < 0:
            raise CourseError(f'the model has no {HEAD_BODY!r} body: falls cannot be scored')
        self.pelvis = sim.atlas.pelvis_body_id
        self.emit = emit
        self.wall_clock = wall_clock
        start_ns = wall_clock()
        self.scorer = Scorer(start_ns)
        self.log = ScoreLog(score_dir, start_ns) if score_dir is not None else None
        self.rows = 0
        self._velocity = np.zeros(6)

    def __call__(self) -> None:
        """Score the step just taken; write and emit its row, if one is due."""
        sim = self.sim
        data = sim.data
        mujoco.mj_objectVelocity(sim.model, data, mujoco.mjtObj.mjOBJ_BODY, self.head,
                                 self._velocity, 0)
        pelvis = data.xpos[self.pelvis]
        row = self.scorer.step(sim.sim_time_ns, self.wall_clock(), float(pelvis[0]),
                               float(pelvis[1]), float(self._velocity[5]))
        if row is None:
            return
        self.rows += 1
        if self.log is not None:
            self.log.write(row)
        if self.emit is not None:
            self.emit(row)

    def close(self) -> None:
        if self.log is not None:
            self.log.close()
