"""DRCSim's VRC Task 2 course without ROS: its description, its world, its mud, its scoring.

errors: CourseError, what the course refuses; mud: DRCSim's MudPlugin as a law (the drag a
touching link feels, explicit and as ODE solved it, moved to the centre of mass);
vrc_task_2: the course's figures (the heightmap's scaling, the gates, the pen, the mud, the
blocks, the starts), the one description the world, the mud and the scoring read; legs:
the course as a walker's legs, gate to gate, and the ones ahead of a walker; rubble_way: a
way across the rubble that keeps the feet clear of every block; hill_way: a way over the
hills on their gentle ground; grid_path: the shortest way over a grid's free cells, in few
straight lines, for both; terrain: the course's heights from its terrain image; starts:
where a run starts Atlas (a world's start by name, or 'x y z yaw'), checked once for the
node, the launches and offline runs; scoring: VRCScoringPlugin's rules, a Scorer fed once per
physics step (gates in order, the clock, falls, the rows due); score_log: DRCSim's score.log
(its header, whole rows); variants: the VRC finals' changes to the course (the mud floor's
friction, the mud's damping, the rubble rearranged by a seed); markers: the course's static
shapes for a viewer (the terrain as a height-coloured triangle mesh over the walked area, the
boxes welded to the world), plain arrays; its rospy side, markers_node.py (rviz's
MarkerArray), is imported by its module.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'errors': ['CourseError'],
    'rubble_way': ['CLEARANCE_M', 'GRID_M', 'SHORTCUT_SLACK_M', 'SOLE_CLEARANCE_M', 'block_corners',
                   'block_footprint', 'clear_path', 'distance_to_polygon', 'gate_posts',
                   'point_clearances_m', 'sole_clearances_m'],
    'legs': ['COURSE_LEGS', 'LEG_PAUSE_S', 'Leg', 'leg_waypoints', 'legs_ahead', 'rest_of_leg'],
    'markers': ['COURSE_AREA', 'MAX_TRIANGLES', 'Area', 'BoxShape', 'CourseShapes',
                'TerrainMesh', 'course_shapes', 'height_colours', 'terrain_mesh'],
    'mud': ['MAX_MUD_DAMPING', 'check_mud_damping', 'drag_at_point', 'drag_wrench',
            'implicit_drag', 'wrench_at_com'],
    'score_log': ['DEFAULT_SCORE_DIR', 'SCORE_FILE_NAME', 'ScoreLog'],
    'scoring': ['FALL_ACCEL_THRESHOLD', 'TASK_WALKING', 'ScoreRow', 'Scorer', 'seconds'],
    'variants': ['COURSE_VARIANTS', 'RUBBLE_SEED', 'CourseVariant', 'course_variant',
                 'rearranged_blocks'],
    'terrain': ['course_height_m', 'ground_under', 'terrain_heights'],
    'hill_way': ['STEEPEST_DEG', 'Heights', 'course_heights', 'gentle_path', 'slope_deg'],
    'starts': ['TERRAIN_FILE', 'WORLD_MODEL_FILE', 'parse_start', 'start_text', 'world_start'],
    'vrc_task_2': ['BLOCKS', 'BLOCK_ENVELOPE_M', 'BLOCK_INERTIA', 'BLOCK_MASS_KG', 'BLOCK_WALLS',
                   'GATES', 'HEIGHTMAP', 'MUD_BOX', 'MUD_DAMPING',
                   'MUD_DAMPING_FINALS', 'MUD_LINKS', 'PEN_POSE', 'PEN_WALLS', 'STARTS',
                   'WORLD_NAME', 'Block', 'Box', 'Gate', 'Heightmap', 'Start'],
})
