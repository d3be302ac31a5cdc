"""Whole-body balance without ROS, the ground the AtlasSimInterface behaviours stand on.

errors: BalanceError, what the balance refuses; blend: the smoothstep timed moves follow,
and its rate; lipm: the linear inverted pendulum and its capture point; support: the
support polygon and keeping a pressure centre in it; contact_wrench: a wrench shared
between the feet; sole: the model's sole boxes and their corners; stand_pose: DRCSim's
Stand pose placed on the ground; stance_posture: that pose's legs solved for the stance
the feet are in; manipulate: Manipulate's pelvis servo (targets clamped, the posture that
reaches them); estimator: the balance state from the model; whole_body: tasks and
constraints over one state, solved into torques (inverse statics, or contact_qp: the
contact wrenches by a QP); stand: the Stand controller (its tasks: capture-point feedback,
height, pelvis frame, posture); stand_behaviour: that controller as the simulator's Stand
behaviour, with the servo; stand_prep: StandPrep, the harnessed robot brought to the
Stand pose; push_trial: offline trials of it on the simulator, standing and pushed;
slope_trial: Stand trials on a slope.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'blend': ['smoothstep', 'smoothstep_rate'],
    'contact_wrench': ['make_feasible', 'split_wrench'],
    'errors': ['BalanceError'],
    'estimator': ['CONTACT_HEIGHT_M', 'MIN_COM_HEIGHT_M', 'BalanceEstimator', 'BalanceState',
                  'SoleContacts'],
    'manipulate': ['PelvisServo', 'SquatTable', 'bent_posture', 'clamp_servo'],
    'lipm': ['capture_point', 'capture_point_after', 'com_acceleration', 'cop_reaching',
             'dcm_feedback_cop', 'lipm_state', 'natural_frequency'],
    'push_trial': ['Push', 'TimedStand', 'TrialResult', 'apply_pushes',
                   'push_events', 'push_survived', 'stand_trial', 'standing_simulator'],
    'slope_trial': ['SLOPE_TRIAL_S', 'SlopeResult', 'place_on_slope', 'slope_model',
                    'slope_stand_trial', 'sole_cop_margins'],
    'stance_posture': ['Stance', 'StancePosture'],
    'stand': ['StandController', 'StandGains', 'StandOutput', 'StandReference',
              'orientation_error', 'yaw_of', 'yaw_rotation'],
    'stand_behaviour': ['TRANSITION_S', 'StandBehaviour', 'stand_pose_com_height_m'],
    'sole': ['BOTTOM_CORNER_SIGNS', 'SOLE_GEOMS', 'SoleBox', 'box_corners',
             'lowest_sole_corner_m', 'sole_corners', 'sole_geom_ids'],
    'stand_pose': ['STAND_POSE_RAD', 'place_in_stand_pose'],
    'whole_body': ['INVERSE_STATICS', 'QP', 'SOLVERS', 'CapturePointTask', 'CentroidalTask',
                   'ComHeightTask', 'ContactConstraint', 'JointTask', 'PelvisOrientationTask',
                   'PostureTask', 'WholeBodyLayer', 'WholeBodyOutput', 'ground_normal'],
    'contact_qp': ['contact_frame', 'solve_contact_qp'],
    'stand_prep': ['PREP_S', 'StandPrepBehaviour'],
    'support': ['Region', 'clamp_into', 'convex_hull', 'inside', 'shrink', 'signed_distance'],
})
