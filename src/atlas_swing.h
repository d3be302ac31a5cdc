/*
 * The swing foot's servo call (src/atlas_swing.c), shared with Walk's single-support tick
 * (src/atlas_legs.c), which fills its input from the estimate's row.
 */
#ifndef TAC_ATLAS_SWING_H
#define TAC_ATLAS_SWING_H

#define LEG 6

/* Laid out once by walking/compiled_swing.py, mirrored in native.py (same fields, same
 * order; tac_sizeof_AtlasSwing lets the loader check). */
typedef struct {
  double *in;       /* see the IN_ enum: the state's numbers and the target, or the path */
  double *torque;   /* (LEG,) out: the leg's torques (N m) */
  double swing_kp;  /* the joint PD per unit of inertia (1/s^2, 1/s) */
  double swing_kd;
  double damping;   /* the least-squares inverse's damping squared (m^2) */
  double press_m;   /* a swing path ends this far below its end (m) */
  double touchdown_speed_m_s;  /* a late foot goes on down at this speed (m/s) */
  long world;       /* 1: damp the sole's velocity in the world; 0: the leg's joint rates */
  long feedforward; /* 1: the target's acceleration is fed forward */
} AtlasSwing;

enum {
  IN_JACOBIAN = 0,          /* (6, LEG) the sole's [linear; angular] jacobian, leg columns */
  IN_CENTRE = 36,           /* (3,) the sole's centre */
  IN_ROTATION = 39,         /* (3, 3) the sole's frame */
  IN_SOLE_VELOCITY = 48,    /* (6,) the sole's [linear; angular] velocity, world */
  IN_JOINT_VELOCITY = 54,   /* (LEG,) the leg's joint rates */
  IN_INERTIA = 60,          /* (LEG, LEG) the leg's joint-space inertia */
  IN_POSITION = 96,         /* (3,) the target: position */
  IN_VELOCITY = 99,         /* (3,) velocity */
  IN_YAW = 102, IN_YAW_RATE = 103,
  IN_ACCELERATION = 104,    /* (3,) acceleration (fed forward when feedforward) */
  IN_YAW_ACCELERATION = 107,
  IN_START = 108,           /* (3,) the swing path: start, end, their yaws, duration, */
  IN_END = 111,             /* height, and the time into it */
  IN_START_YAW = 114, IN_END_YAW = 115, IN_DURATION = 116, IN_HEIGHT = 117, IN_ELAPSED = 118,
  IN_TILT = 119,            /* (2,) the target's tilt (swing.surface_tilt: x, y) */
  IN_START_TILT = 121,      /* (2,) the path's tilt at lift-off, */
  IN_END_TILT = 123,        /* (2,) and at touchdown */
  IN_SIZE = 125
};

void atlas_foot_servo(const AtlasSwing *c);
void atlas_swing_torque(const AtlasSwing *c);

#endif
