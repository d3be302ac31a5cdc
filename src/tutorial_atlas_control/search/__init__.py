"""Sweeps of many offline runs on Dask (trajectories; walks: the walk map; the VRC course
over its variants and seeds: course_sweep), and the CMA-ES search over them. No ROS."""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'cmaes': ['LATENCY_SEED', 'SearchProblem', 'SearchResult', 'gains_yaml', 'parse_parameter',
              'run_search', 'runs_per_candidate', 'trajectory_yaml'],
    'course_sweep': ['COURSE_COLUMNS', 'CourseSpec', 'VariantLine', 'course_specs', 'run_course',
                     'run_course_sweep', 'variant_lines', 'variant_table'],
    'objectives': ['OBJECTIVES', 'parse_objective'],
    'runs': ['RunSpec', 'SweepError', 'run_one'],
    'sweep': ['SweepEngine', 'SweepInputs', 'atomic_write', 'build_specs', 'check_output',
              'parse_latency', 'parse_push', 'run_sweep', 'table_texts', 'write_table'],
    'walk_map': ['MapCell', 'WalkMapInputs', 'WalkSpec', 'fastest_walking', 'map_cells',
                 'map_csv', 'plot_map', 'run_walk', 'run_walk_map', 'walk_specs', 'write_map'],
})
