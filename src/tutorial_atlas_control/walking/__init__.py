"""Walking without ROS: the footsteps Walk and Step take and the plan they follow.

errors: WalkingError, what the walk refuses; footsteps: a step as the AtlasSimInterface
names it, DRCSim's fixed queue, straight and circular plans, a streaming client's window;
status_flags: walk_feedback's and step_feedback's status values; step_queue: Walk's queue
of steps merged by index, clamped to what the legs reach, and its feedback flags;
dcm_plan: the capture point's plan over the steps; step_adjustment: where a pushed swing
foot must land instead; swing: the swing foot's path (its apex over the higher end, the sole
laid on its surfaces' tilts); feet_surfaces: the surfaces the walk's feet stand on and the
CoM height over them (a slope's steps up or down); phases: the one phase machine
Walk and Step run (their phases in order, each one's end rule, the transition);
leg_tasks: what Walk and Step do alike each tick (the whole-body law on the carrying soles,
the swing foot, the pelvis's heading); sole_support: a lone stance sole across facets (the
course's hills) keeps its wrench's pressure centre near the one asked (off by default);
sole_footprint: the plane a step's sole rests on over a heightfield;
compiled_swing: the swing foot's path and servo as one C call (src/atlas_swing.c);
compiled_legs: a swinging tick of the legs (sole clamp, whole body, swing servo, effort
limits) as one C call (src/atlas_legs.c); compiled_walk_swing: a walking tick with the foot
in the air (reference, step adjustment, the law, the legs) as one C call
(src/atlas_walk_swing.c); walk: the walk's phases; walk_behaviour: Walk as the simulator's
behaviour;
route: footsteps through a route of waypoints (a course walker's plan) from where the
feet are; ground_strides: a straight run's strides fitted to the ground (no sole across a
bend, short slow steps on steep ground);
start_noise: a trial's start perturbed by a seed; walk_trial: offline walking trials,
landing by landing, pushed or not; static_step: one quasi-static step; step_over: its swing
over terrain higher than its line (up, across, down) and the apex that clears it;
step_behaviour: Step as the simulator's behaviour.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'errors': ['WalkingError'],
    'footsteps': ['DRCSIM_WALK_QUEUE', 'LEFT', 'QUEUE_LENGTH', 'RIGHT', 'STEP_DURATION_S',
                  'Footstep', 'circle_steps', 'placed', 'side_sign', 'straight_steps', 'window',
                  'wrap_angle'],
    'status_flags': ['CATCHING', 'ERROR_INCONSISTENT_STEPS', 'OKAY', 'STEPPING', 'SWAYING',
                     'WARNING_INSUFFICIENT_STEP_DATA'],
    'swing': ['END_CLEARANCE_M', 'SWING_HEIGHT_M', 'sole_frame', 'surface_tilt',
              'swing_height_m'],
    'feet_surfaces': ['FeetSurfaces', 'support_height_m'],
    'compiled_swing': ['CompiledSwing'],
    'compiled_legs': ['CompiledLegs'],
    'compiled_walk_swing': ['WALK_SWING_ENV', 'CompiledWalkSwing'],
    'leg_tasks': ['LEGS_ENV', 'SWING_ENV'],
    'walk': ['WalkGains'],
    'walk_behaviour': ['WalkBehaviour', 'WalkStatus'],
    'route': ['RouteGait', 'centre_line_xy', 'feet_origin', 'route_steps'],
    'ground_strides': ['SOLE_HALF_LENGTH_M', 'SOLE_HALF_WIDTH_M', 'GroundGait', 'HeightField',
                       'SoleFit', 'ground_steps', 'sole_fit'],
    'sole_footprint': ['footprint_surface'],
    'start_noise': ['perturb_start'],
    'walk_trial': ['SETTLE_S', 'WalkTrial', 'WalkingStand', 'pushed_walk_trial',
                   'random_pushes', 'run_walking_stand', 'straight_walk_trial', 'walk_trial'],
    'step_over': ['STEP_OVER_CLEARANCE_M', 'StepOverPath', 'clear_apex_m', 'needs_step_over',
                  'sweep_points', 'terrain_top_m'],
    'step_behaviour': ['StepBehaviour', 'StepStatus'],
})
