"""Recorded runs: bag records and reading, analysis, comparison, reports, videos, run logs,
and the VRC course's score (vrc_score: /vrc_score as a timeline of events, the final score)
and map (course_terrain: whether a bag is a course run, the terrain under a point; course_run:
its path, landings on the terrain, falls and events; course_map: the course from above with
the run on it, a PNG); laser_scans: the head laser's recorded scans and their points in the
world.

No ROS: bags are read and written with rosbags. Synthetic bags for the tests are
test/support/synthetic_bags.py.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'analysis': ['Analysis', 'COMMAND_CHANGE_RAD', 'EFFORT_LIMIT_TOLERANCE_NM',
                 'MOVED_RANGE_RAD', 'analyze', 'analyze_bag', 'analyze_try'],
    'capture_point': ['CaptureTrace', 'capture_trace', 'plot_capture'],
    'course_map': ['COURSE_EXTENT_M', 'MAP_SIZE_PX', 'map_pixel', 'plot_course_map'],
    'laser_scans': ['LaserScans', 'hokuyo_angles', 'laser_height_map', 'map_error_lines',
                    'placed_scans', 'read_laser_scans', 'scan_cloud', 'spindle_angles',
                    'spindle_command_steps'],
    'course_run': ['CourseRun', 'MapMark', 'read_course_run', 'recorded_course_run',
                   'terrain_landings'],
    'course_terrain': ['above_ground', 'ground_under', 'is_course_run', 'terrain_heights'],
    'bag_dir': ['default_bag_dir', 'latest_bag', 'newest_bag', 'unwritable_reason'],
    'compare': ['compare_analyses', 'compare_bags', 'comparison_to_json',
                'first_applied_command_s', 'format_comparison', 'plot_comparison'],
    'feet': ['foot_displacement', 'foot_line'],
    'behaviours': ['BehaviourChange', 'behaviour_lines', 'plot_behaviours', 'read_behaviours',
                   'walk_windows'],
    'footprints': ['Landing', 'StepTarget', 'WalkSummary', 'plot_footprints',
                   'read_step_targets', 'summarise_walk', 'titled_walks', 'walk_lines'],
    'overview_plot': ['WORST_JOINTS'],
    'reader': ['BagData', 'JointStateSeries', 'read_bag'],
    'records': ['open_bag'],
    'render': ['DEFAULT_FPS', 'DEFAULT_SIZE', 'check_output_path', 'parse_fps', 'parse_size',
               'render_bag_video'],
    'report': ['analysis_to_json', 'format_summary', 'plot_joints', 'plot_run', 'short_summary',
               'write_csv'],
    'retention': ['BagFile', 'Retention', 'RetentionError', 'bag_files', 'bags_count', 'doomed',
                  'retention_from_env', 'size_mb', 'usage_line'],
    'rosbag1_fast': ['BlockBagWriter', 'RecordBlock', 'TopicConnection'],
    'run_log': ['PlayedTrajectory'],
    'tries': ['RESET_SIMULATION', 'RESET_WORLD', 'RUN_START', 'Try', 'find_tries', 'pick_try',
              'window'],
    'typestore': ['JOINT_COMMANDS_TYPE', 'load_typestore', 'rosbags_msgtype'],
    'vrc_score': ['ScoreEntry', 'read_scores', 'score_lines'],
})
