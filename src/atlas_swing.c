/*
 * The swing foot's servo in one call: the compiled twin of LegTasks.swing_torque and
 * LegTasks.foot_servo in src/tutorial_atlas_control/walking/leg_tasks.py (whose docstrings
 * give the rules) with SwingPath.at and SwingPath.acceleration (walking/swing.py): the
 * path's pose, velocity and acceleration at a time, the sole's pose error turned into the
 * leg's joint errors by its damped least-squares inverse, a joint PD scaled by the leg's
 * inertia. In Python some sixty small numpy operations a swing tick; here one ctypes call
 * (walking/compiled_swing.py). The same operations in the same order but for the 6 x 6
 * products and the solve (LU with partial pivoting here, LAPACK's there): the results agree
 * to rounding (test/unit/walking/test_compiled_swing.py holds them to 1e-9).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "atlas_swing.h"

size_t tac_sizeof_AtlasSwing(void) { return sizeof(AtlasSwing); }

static double clamp01(double s) {
  /* Python's min(max(s, 0.0), 1.0) */
  double raised = 0.0 > s ? 0.0 : s;
  return 1.0 < raised ? 1.0 : raised;
}

/* swing.quintic: value, d/ds, d2/ds2 of 10 s^3 - 15 s^4 + 6 s^5. */
static void quintic(double s, double out[3]) {
  s = clamp01(s);
  out[0] = pow(s, 3.0) * (10.0 - 15.0 * s + 6.0 * s * s);
  out[1] = 30.0 * s * s * pow(1.0 - s, 2.0);
  out[2] = 60.0 * s * (1.0 - s) * (1.0 - 2.0 * s);
}

/* swing.bump: value, d/ds, d2/ds2 of 64 s^3 (1 - s)^3. */
static void bump(double s, double out[3]) {
  s = clamp01(s);
  double u = s * (1.0 - s), du = 1.0 - 2.0 * s;
  out[0] = 64.0 * pow(u, 3.0);
  out[1] = 192.0 * u * u * du;
  out[2] = 192.0 * (2.0 * u * du * du - 2.0 * u * u);
}

/* footsteps.wrap_angle: Python's float % (the result takes the divisor's sign). */
static double wrap_angle(double angle) {
  double period = 2.0 * M_PI, shifted = angle + M_PI;
  double rest = fmod(shifted, period);
  if (rest != 0.0) {
    if ((rest < 0.0) != (period < 0.0)) rest += period;
  } else {
    rest = copysign(0.0, period);
  }
  return rest - M_PI;
}

/* LegTasks.swing_torque's target: SwingPath.at and .acceleration at the time into the path,
 * the path's end pressed below its surface, a late foot sent on down. */
static void swing_target(const AtlasSwing *c) {
  double *in = c->in;
  const double *start = in + IN_START, *end = in + IN_END;
  double duration = in[IN_DURATION], height = in[IN_HEIGHT], elapsed = in[IN_ELAPSED];
  double s = elapsed / duration, q[3], b[3], delta[3];
  quintic(s, q);
  bump(s, b);
  int inside = 0.0 < s && s < 1.0;
  double *position = in + IN_POSITION, *velocity = in + IN_VELOCITY;
  for (int i = 0; i < 3; ++i) {
    delta[i] = end[i] - start[i];
    position[i] = start[i] + q[0] * delta[i];
    velocity[i] = q[1] * delta[i] / duration;
  }
  position[2] = position[2] + height * b[0];
  velocity[2] = velocity[2] + height * b[1] / duration;
  if (!inside) memset(velocity, 0, 3 * sizeof(double));
  for (int i = 0; i < 2; ++i)  /* SwingPath.tilt */
    in[IN_TILT + i] = in[IN_START_TILT + i] + q[0] * (in[IN_END_TILT + i] - in[IN_START_TILT + i]);
  double turn = wrap_angle(in[IN_END_YAW] - in[IN_START_YAW]);
  in[IN_YAW] = wrap_angle(in[IN_START_YAW] + q[0] * turn);
  in[IN_YAW_RATE] = inside ? q[1] * turn / duration : 0.0;
  double *acceleration = in + IN_ACCELERATION;
  if (!inside) {
    memset(acceleration, 0, 3 * sizeof(double));
    in[IN_YAW_ACCELERATION] = 0.0;
  } else {
    double per_s2 = 1.0 / (duration * duration);
    for (int i = 0; i < 3; ++i) acceleration[i] = q[2] * per_s2 * delta[i];
    acceleration[2] = acceleration[2] + height * b[2] * per_s2;
    in[IN_YAW_ACCELERATION] = q[2] * per_s2 * turn;
  }
  quintic(elapsed / duration, q);
  position[2] = position[2] - c->press_m * q[0];
  double late = elapsed - duration;
  if (late > 0.0) {
    position[2] = position[2] - c->touchdown_speed_m_s * late;
    velocity[2] = -c->touchdown_speed_m_s;
  }
}

/* swing.sole_frame: the upright frame turned by yaw, then tilted about the tilt's
 * horizontal axis by its length (Rodrigues); the upright frame itself for no tilt. */
static void sole_frame(double yaw, const double tilt[2], double out[3][3]) {
  double cy = cos(yaw), sy = sin(yaw);
  double upright[3][3] = {{cy, -sy, 0.0}, {sy, cy, 0.0}, {0.0, 0.0, 1.0}};
  if (tilt[0] == 0.0 && tilt[1] == 0.0) {
    memcpy(out, upright, sizeof(upright));
    return;
  }
  double angle = hypot(tilt[0], tilt[1]);
  double kx = tilt[0] / angle, ky = tilt[1] / angle;
  double ca = cos(angle), sa = sin(angle), v = 1.0 - ca;
  double tilted[3][3] = {{ca + kx * kx * v, kx * ky * v, ky * sa},
                         {kx * ky * v, ca + ky * ky * v, -kx * sa},
                         {-ky * sa, kx * sa, ca}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out[i][j] = tilted[i][0] * upright[0][j] + tilted[i][1] * upright[1][j]
                  + tilted[i][2] * upright[2][j];
}

/* Solves a (LEG, LEG) system for `columns` right-hand sides (rhs: LEG rows of `columns`,
 * overwritten by the solution) by LU with partial pivoting; a is overwritten. */
static void solve(double a[LEG][LEG], double rhs[LEG][3], int columns) {
  for (int k = 0; k < LEG; ++k) {
    int pivot = k;
    for (int i = k + 1; i < LEG; ++i)
      if (fabs(a[i][k]) > fabs(a[pivot][k])) pivot = i;
    if (pivot != k) {
      for (int j = 0; j < LEG; ++j) {
        double t = a[k][j]; a[k][j] = a[pivot][j]; a[pivot][j] = t;
      }
      for (int j = 0; j < columns; ++j) {
        double t = rhs[k][j]; rhs[k][j] = rhs[pivot][j]; rhs[pivot][j] = t;
      }
    }
    for (int i = k + 1; i < LEG; ++i) {
      double factor = a[i][k] / a[k][k];
      for (int j = k + 1; j < LEG; ++j) a[i][j] -= factor * a[k][j];
      for (int j = 0; j < columns; ++j) rhs[i][j] -= factor * rhs[k][j];
    }
  }
  for (int k = LEG - 1; k >= 0; --k)
    for (int j = 0; j < columns; ++j) {
      double sum = rhs[k][j];
      for (int i = k + 1; i < LEG; ++i) sum -= a[k][i] * rhs[i][j];
      rhs[k][j] = sum / a[k][k];
    }
}

/* LegTasks.foot_servo: the leg's torques towards the target in `in`. */
void atlas_foot_servo(const AtlasSwing *c) {
  const double *in = c->in, *jac = in + IN_JACOBIAN, *centre = in + IN_CENTRE;
  const double *r = in + IN_ROTATION;
  int columns = c->feedforward ? 3 : 2;
  double targets[LEG][3] = {{0.0}};
  for (int i = 0; i < 3; ++i) targets[i][0] = in[IN_POSITION + i] - centre[i];
  /* orientation_error(R, sole_frame(yaw, tilt)): d = reference R^T */
  double ref[3][3], d[3][3];
  sole_frame(in[IN_YAW], in + IN_TILT, ref);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      d[i][j] = ref[i][0] * r[3 * j] + ref[i][1] * r[3 * j + 1] + ref[i][2] * r[3 * j + 2];
  targets[3][0] = 0.5 * (d[2][1] - d[1][2]);
  targets[4][0] = 0.5 * (d[0][2] - d[2][0]);
  targets[5][0] = 0.5 * (d[1][0] - d[0][1]);
  for (int i = 0; i < 3; ++i) targets[i][1] = in[IN_VELOCITY + i];
  targets[5][1] = in[IN_YAW_RATE];
  if (c->world)
    for (int i = 0; i < LEG; ++i) targets[i][1] -= in[IN_SOLE_VELOCITY + i];
  if (c->feedforward) {
    for (int i = 0; i < 3; ++i) targets[i][2] = in[IN_ACCELERATION + i];
    targets[5][2] = in[IN_YAW_ACCELERATION];
  }
  double damped[LEG][LEG];
  for (int i = 0; i < LEG; ++i)
    for (int j = 0; j < LEG; ++j) {
      double sum = 0.0;
      for (int k = 0; k < LEG; ++k) sum += jac[LEG * i + k] * jac[LEG * j + k];
      damped[i][j] = sum + (i == j ? c->damping : 0.0);
    }
  solve(damped, targets, columns);
  double accel[LEG];
  for (int j = 0; j < LEG; ++j) {
    double joint[3] = {0.0, 0.0, 0.0};
    for (int col = 0; col < columns; ++col)
      for (int i = 0; i < LEG; ++i) joint[col] += jac[LEG * i + j] * targets[i][col];
    double rate = c->world ? joint[1] : joint[1] - in[IN_JOINT_VELOCITY + j];
    accel[j] = c->swing_kp * joint[0] + c->swing_kd * rate;
    if (c->feedforward) accel[j] += joint[2];
  }
  for (int i = 0; i < LEG; ++i) {
    double sum = 0.0;
    for (int j = 0; j < LEG; ++j) sum += in[IN_INERTIA + LEG * i + j] * accel[j];
    c->torque[i] = sum;
  }
}

/* LegTasks.swing_torque: the path's target at the time into it, then the servo. */
void atlas_swing_torque(const AtlasSwing *c) {
  swing_target(c);
  atlas_foot_servo(c);
}
