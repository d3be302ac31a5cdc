"""Whole-body balance without ROS, the ground the AtlasSimInterface behaviours stand on.

errors: BalanceError, what the balance refuses; blend: the smoothstep timed moves follow,
and its rate; lipm: the linear inverted pendulum and its capture point; support: the
support polygon and keeping a pressure centre in it; contact_wrench: a wrench shared
between the feet; sole: the model's sole boxes and their corners; stand_pose: DRCSim's
Stand pose placed on the ground; stance_posture: that pose's legs solved for the stance
the feet are in; manipulate: Manipulate's pelvis servo (targets clamped, the posture that
reaches them); estimator: the balance state from the model; compiled_estimator: its
per-tick work as one C call; whole_body: tasks and constraints over one state, solved into
torques (inverse statics, compiled_statics its C call, or contact_qp: the contact wrenches
by a QP); stand: the Stand
controller (its tasks: capture-point feedback, height, pelvis frame, posture);
compiled_whole_body: its tick (pressure centre, tasks, statics, posture, limits) as one C call;
stand_behaviour: that controller as the simulator's Stand behaviour, with the servo;
stand_prep: StandPrep, the harnessed robot brought to the Stand pose; push_trial: offline
trials of it on the simulator, standing and pushed; slope_trial: Stand trials on a slope.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'blend': ['smoothstep', 'smoothstep_rate'],
    'errors': ['BalanceError'],
    'compiled_estimator': ['BEARING_AT', 'CompiledEstimate', 'EstimatorGeometry',
                           'RawEstimate', 'row_offsets'],
    'compiled_statics': ['CompiledStatics'],
    'compiled_whole_body': ['JOINTS_IN_CALL', 'MOVED_IN_CALL', 'CompiledWholeBody',
                            'joints_of'],
    'estimator': ['CONTACT_HEIGHT_M', 'ESTIMATOR_ENV', 'MIN_COM_HEIGHT_M', 'BalanceEstimator',
                  'BalanceState'],
    'manipulate': ['PelvisServo'],
    'lipm': ['capture_point', 'capture_point_after', 'cop_reaching', 'dcm_feedback_cop',
             'natural_frequency'],
    'push_trial': ['Push', 'TimedStand', 'apply_pushes', 'push_events', 'standing_simulator'],
    'stand': ['WHOLE_BODY_ENV', 'MovedReference', 'StandController', 'StandGains',
              'StandReference', 'moved_reference', 'orientation_error', 'yaw_of',
              'yaw_rotation'],
    'stand_behaviour': ['StandBehaviour'],
    'sole': ['BOTTOM_CORNER_SIGNS', 'ONE_SURFACE_COS', 'PRESSED_M', 'SOLE_GEOMS', 'UPRIGHT_COS',
             'SoleBox', 'box_corners', 'sole_corners', 'sole_geom_ids'],
    'stand_pose': ['STAND_POSE_RAD', 'place_in_stand_pose'],
    'whole_body': ['INVERSE_STATICS', 'QP', 'SOLVERS', 'STATICS_ENV', 'CapturePointTask',
                   'CentroidalTask', 'ComHeightTask', 'ContactConstraint', 'JointTask',
                   'PelvisOrientationTask', 'PostureTask', 'WholeBodyLayer', 'WholeBodyOutput'],
    'slope_trial': ['place_on_slope', 'slope_model', 'slope_stand_trial'],
    'stand_prep': ['StandPrepBehaviour'],
    'support': ['clamp_into', 'convex_hull', 'signed_distance'],
})
