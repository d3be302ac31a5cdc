"""Trajectory files (lookup, validation, interpolation) and the 50 Hz schedule. No ROS,
except the tutorial's player, traj_yaml_node.py (import it by its module).
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'catalog': ['GainsChoice', 'find_trajectory', 'gains_for'],
    'schedule': ['TRAJECTORY_LOG_PREFIX', 'done_line', 'parse_trajectory_log_line', 'playing_line',
                 'run_trajectory', 'trajectory_log_line'],
    'trajectory': ['TrajectoryError', 'Waypoint', 'load_trajectory', 'locate_trajectory_file',
                   'sample_count'],
})
