"""Runs without ROS: the offline trajectory player, an AtlasSimInterface session played again,
and the replay of a recorded run (replay_score: a scored run's /vrc_score computed again on
the replayed steps); world: the model and start they simulate (a VRC world by name, or the
recorded run's); course_route: a course walker's streamed walk, leg by leg, on a VRC world,
scored (planned on the world's ground or its laser's map: laser_terrain); course_variant: a
finals' variant of the course's world (course/variants.py) compiled in memory;
terrain_trial: straight walks on the course's kinds of ground one at a time (mud, slopes),
over seeds; block_step: static steps onto a cinder block and off again, from a
seeded start."""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'asi_playback': ['AsiStream', 'read_asi_stream', 'run_asi_offline'],
    'block_step': ['PLANS', 'BlockRun', 'BlockStep', 'CinderBlock', 'block_model', 'block_plan',
                   'block_step_trial'],
    'course_route': ['MAX_LOOKS', 'PLANNING_GROUNDS', 'WALK_OVERHEAD_S', 'CourseWalk',
                     'LegFigures', 'around_blocks', 'course_walk', 'leg_plan', 'resumed_leg',
                     'walk_time_limit_s'],
    'laser_terrain': ['LOOK_AGAIN_AFTER_STEPS', 'LOOK_AGAIN_SLOPE_RAD', 'SPIN_RAD_S',
                      'LaserLegFigures', 'LaserTerrain', 'PlanningGround', 'footstep_errors',
                      'level_footstep', 'seen_prefix', 'unlike_plan'],
    'course_variant': ['BLOCK_CLEARANCE_M', 'MUD_FLOOR_GEOM', 'block_placement',
                       'highest_ground_m', 'variant_model'],
    'player': ['CommandLatency', 'DEFAULT_SETTLE_S', 'DEFAULT_START_AFTER_S', 'OfflineRunError',
               'run_offline', 'write_offline_bag'],
    'replay': ['DEFAULT_TOLERANCE', 'ReplayError', 'format_report', 'replay_bag'],
    'terrain_trial': ['MUD_DEPTH_M', 'TERRAINS', 'Terrain', 'mud_model', 'planned_steps',
                      'terrain_plan', 'terrain_walk'],
    'world': ['OfflineWorld', 'named_world', 'recorded_world'],
    'replay_score': ['ScoreComparison', 'ScoreReplay'],
})
