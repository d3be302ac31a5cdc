"""DRCSim's VRC Task 2 course without ROS: its description, its world, its mud, its scoring.

errors: CourseError, what the course refuses; vrc_task_2: the course's figures (the
heightmap's scaling, the gates, the pen, the mud, the starts), the one description the
world, the mud and the scoring read; scoring: VRCScoringPlugin's rules, a Scorer fed once
per physics step (gates in order, the clock, falls, the rows due); score_log: DRCSim's
score.log (its header, whole rows).
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'errors': ['CourseError'],
    'score_log': ['DEFAULT_SCORE_DIR', 'SCORE_FILE_NAME', 'ScoreLog'],
    'scoring': ['FALL_ACCEL_THRESHOLD', 'TASK_WALKING', 'ScoreRow', 'Scorer', 'seconds'],
    'vrc_task_2': ['GATES', 'HEIGHTMAP', 'MUD_BOX', 'STARTS', 'WORLD_NAME', 'Box', 'Gate',
                   'Heightmap', 'Start'],
})
