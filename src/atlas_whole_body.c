/*
 * The whole-body layer's tick in one call: the compiled twin of StandController.tick and
 * StandController.whole_body (src/tutorial_atlas_control/balance/stand.py, with the tasks and
 * WholeBodyLayer of balance/whole_body.py and support.Region.clamp, whose docstrings give the
 * rules). The capture-point law's pressure centre clamped into the support region, the
 * centroidal tasks' wrench (the capture point's force, the CoM height's PD and the weight,
 * the pelvis frame's PD moment), the inverse statics (src/atlas_statics.c, called here on the
 * input the Python glue filled), the posture PD and the effort limits. In Python these are
 * some two hundred small float and numpy operations a tick; here one ctypes call
 * (balance/compiled_whole_body.py). Same operations in the same order: the results agree
 * to rounding (test/unit/balance/test_compiled_whole_body.py holds them to 1e-9).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "atlas_whole_body.h"

size_t tac_sizeof_AtlasWholeBody(void) { return sizeof(AtlasWholeBody); }

/* The state's fields from the estimate's row into the inputs (the same numbers the Python
 * copies would put there), and its joints from the estimate's scratch data where the caller
 * gave none (the fancy-indexed copies of qpos and qvel it would have made). */
static void load_row(const AtlasWholeBody *w) {
  const double *row = w->row;
  const long *at = w->row_at;
  if (row == NULL) return;
  long n = w->statics->n;
  double *in = (double *)w->in, *in_statics = (double *)w->statics->in;
  memcpy(in_statics + IN_COM, row + at[WB_ROW_COM], 3 * sizeof(double));
  memcpy(in_statics + IN_CENTRES, row + at[WB_ROW_SOLE_CENTRES], 6 * sizeof(double));
  memcpy(in_statics + IN_ROTATIONS, row + at[WB_ROW_SOLE_ROTATIONS], 18 * sizeof(double));
  memcpy(in_statics + IN_BIAS, row + at[WB_ROW_BIAS], (size_t)n * sizeof(double));
  memcpy(in_statics + IN_BIAS + n, row + at[WB_ROW_JACOBIANS], (size_t)(12 * n) * sizeof(double));
  memcpy(in + WB_IN_CAPTURE, row + at[WB_ROW_CAPTURE], 2 * sizeof(double));
  in[WB_IN_OMEGA] = row[at[WB_ROW_OMEGA]];
  memcpy(in + WB_IN_COM_VELOCITY, row + at[WB_ROW_COM_VELOCITY], 3 * sizeof(double));
  memcpy(in + WB_IN_PELVIS_ROTATION, row + at[WB_ROW_PELVIS_ROTATION], 9 * sizeof(double));
  memcpy(in + WB_IN_PELVIS_ANGULAR, row + at[WB_ROW_PELVIS_ANGULAR], 3 * sizeof(double));
  if (w->joint_qpos == NULL) return;
  double *q = in + WB_IN_JOINTS, *qd = q + n;
  for (long j = 0; j < n; ++j) {
    q[j] = w->joint_qpos[w->qpos_adr[j]];
    qd[j] = w->joint_qvel[w->dof_adr[j]];
  }
}

/* support.Region.clamp: `p` if inside the region, else the region's nearest point. */
static void clamp_into_region(const AtlasWholeBody *w, double p[2]) {
  atlas_clamp_into_rows(w->region, w->region_count, p);
}

void atlas_clamp_into_rows(const double *region, long count, double p[2]) {
  if (count == 0) return;
  if (count < 3) {
    p[0] = region[0];
    p[1] = region[1];
    return;
  }
  double x = p[0], y = p[1], distance = INFINITY;
  for (long i = 0; i < count; ++i) {
    const double *line = region + 5 * i + 2;
    double d = line[0] * x + line[1] * y - line[2];
    if (d < distance) distance = d;
  }
  if (distance >= 0.0) return;
  double best_x = x, best_y = y, best_d2 = INFINITY;
  for (long i = 0; i < count; ++i) {
    const double *a = region + 5 * i, *b = region + 5 * ((i + 1) % count);
    double ex = b[0] - a[0], ey = b[1] - a[1];
    double t = ((x - a[0]) * ex + (y - a[1]) * ey) / (ex * ex + ey * ey);
    t = t < 0.0 ? 0.0 : t; /* Python's min(max(t, 0.0), 1.0) */
    t = 1.0 < t ? 1.0 : t;
    double px = a[0] + t * ex, py = a[1] + t * ey;
    double d2 = (px - x) * (px - x) + (py - y) * (py - y);
    if (d2 < best_d2) {
      best_x = px;
      best_y = py;
      best_d2 = d2;
    }
  }
  p[0] = best_x;
  p[1] = best_y;
}

/* orientation_error: the small rotation taking `rotation` to `reference` (D = ref rot^T). */
static void orientation_error(const double rotation[9], const double reference[9],
                              double error[3]) {
  double d[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      d[3 * i + j] = reference[3 * i] * rotation[3 * j] +
                     reference[3 * i + 1] * rotation[3 * j + 1] +
                     reference[3 * i + 2] * rotation[3 * j + 2];
  error[0] = 0.5 * (d[7] - d[5]);
  error[1] = 0.5 * (d[2] - d[6]);
  error[2] = 0.5 * (d[3] - d[1]);
}

/* The centroidal tasks' wrench (CapturePointTask, ComHeightTask, PelvisOrientationTask). */
static void centroidal_wrench(const AtlasWholeBody *w, const double cop[2], double force[3],
                              double moment[3]) {
  const double *in = w->in, *ref = w->reference, *g = w->gains;
  const double *com = w->statics->in + IN_COM;
  double mass = g[WB_GAIN_MASS], stiffness = in[WB_IN_OMEGA] * in[WB_IN_OMEGA];
  force[0] = mass * (stiffness * (com[0] - cop[0]) + 0.0);
  force[1] = mass * (stiffness * (com[1] - cop[1]) + 0.0);
  double vertical = g[WB_GAIN_HEIGHT_KP] * (ref[WB_REF_HEIGHT] - com[2]) +
                    g[WB_GAIN_HEIGHT_KD] * (ref[WB_REF_HEIGHT_RATE] - in[WB_IN_COM_VELOCITY + 2]);
  force[2] = mass * (vertical + g[WB_GAIN_GRAVITY]);
  double error[3];
  orientation_error(in + WB_IN_PELVIS_ROTATION, ref + WB_REF_ROTATION, error);
  for (int i = 0; i < 3; ++i)
    moment[i] = g[WB_GAIN_ORIENTATION_KP] * error[i] +
                g[WB_GAIN_ORIENTATION_KD] * (ref[WB_REF_ANGULAR + i] - in[WB_IN_PELVIS_ANGULAR + i]);
}

/* StandController.whole_body at the pressure centre `cop`: tasks, statics, posture PD. */
static void whole_body(const AtlasWholeBody *w, const double cop[2]) {
  AtlasStatics *s = w->statics;
  long n = s->n;
  double *out = w->out, *in_statics = (double *)s->in;
  out[WB_OUT_COP] = cop[0];
  out[WB_OUT_COP + 1] = cop[1];
  centroidal_wrench(w, cop, out + WB_OUT_FORCE, out + WB_OUT_MOMENT);
  for (int i = 0; i < 3; ++i) {
    in_statics[IN_FORCE + i] = out[WB_OUT_FORCE + i];
    in_statics[IN_MOMENT + i] = out[WB_OUT_MOMENT + i];
  }
  atlas_inverse_statics(s);
  const double *q = w->in + WB_IN_JOINTS, *qd = q + n;
  const double *posture = w->reference + WB_REF_POSTURE, *rate = posture + n;
  const double *kp = w->joint_gains, *kd = kp + n;
  for (long j = 0; j < n; ++j)
    s->torque[j] = s->torque[j] + (kp[j] * (posture[j] - q[j]) + kd[j] * (rate[j] - qd[j]));
}

/* StandController.whole_body with the pressure centre given in the input. */
void atlas_whole_body(const AtlasWholeBody *w) {
  load_row(w);
  whole_body(w, w->in + WB_IN_COP);
}

/* StandController.tick: the capture-point law's pressure centre kept in the region, the
 * whole body's torques, within the effort limits (np.maximum then np.minimum). */
void atlas_stand_tick(const AtlasWholeBody *w) {
  load_row(w);
  const double *xi = w->in + WB_IN_CAPTURE, *xi_ref = w->reference + WB_REF_CAPTURE;
  double gain = 1.0 + w->gains[WB_GAIN_CAPTURE], cop[2];
  for (int i = 0; i < 2; ++i) cop[i] = xi_ref[i] + gain * (xi[i] - xi_ref[i]);
  clamp_into_region(w, cop);
  whole_body(w, cop);
  double *torque = w->statics->torque;
  const double *limit = w->effort_limit;
  for (long j = 0, n = w->statics->n; j < n; ++j) {
    double low = -limit[j], raised = low > torque[j] ? low : torque[j];
    torque[j] = limit[j] < raised ? limit[j] : raised;
  }
}
