"""Whole-body balance without ROS, the ground the AtlasSimInterface behaviours stand on.

lipm: the linear inverted pendulum and its capture point; support: the support polygon
and keeping a pressure centre in it; contact_wrench: a wrench shared between the feet;
stand_pose: DRCSim's Stand pose placed on the ground; stance_posture: that pose's legs
solved for the stance the feet are in; manipulate: Manipulate's pelvis servo
(targets clamped, the posture that reaches them); estimator: the balance state from the
model; stand: the Stand controller (capture-point feedback, inverse statics, joint PD);
stand_behaviour: that controller as the simulator's Stand behaviour, with the servo;
stand_prep: StandPrep, the harnessed robot brought to the Stand pose;
push_trial: offline trials of it on the simulator, standing and pushed.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'contact_wrench': ['make_feasible', 'split_wrench'],
    'estimator': ['CONTACT_HEIGHT_M', 'MIN_COM_HEIGHT_M', 'BalanceEstimator', 'BalanceState'],
    'manipulate': ['PelvisServo', 'SquatTable', 'bent_posture', 'clamp_servo'],
    'lipm': ['capture_point', 'com_acceleration', 'dcm_feedback_cop', 'lipm_state',
             'natural_frequency'],
    'push_trial': ['Push', 'TimedStand', 'TrialResult', 'apply_pushes',
                   'push_events', 'push_survived', 'stand_trial', 'standing_simulator'],
    'stance_posture': ['Stance', 'StancePosture'],
    'stand': ['StandController', 'StandGains', 'StandOutput', 'StandReference',
              'orientation_error', 'yaw_of', 'yaw_rotation'],
    'stand_behaviour': ['TRANSITION_S', 'StandBehaviour', 'smoothstep', 'stand_pose_com_height_m'],
    'stand_pose': ['SOLE_GEOMS', 'STAND_POSE_RAD', 'place_in_stand_pose', 'sole_corners'],
    'stand_prep': ['PREP_S', 'StandPrepBehaviour'],
    'support': ['Region', 'clamp_into', 'convex_hull', 'inside', 'shrink', 'signed_distance'],
})
