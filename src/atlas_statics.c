/*
 * Inverse statics in one call: the compiled twin of the whole-body layer's default solver
 * (WholeBodyLayer.solve in src/tutorial_atlas_control/balance/whole_body.py with
 * contact_wrench.split_wrench and make_feasible, whose docstrings give the rules): the
 * desired wrench about the centre of mass shared between the soles, each share made
 * feasible, and the torques tau = bias - J^T w. In Python these are some fifty small
 * float and numpy operations a tick; here one ctypes call (balance/compiled_statics.py).
 * Same operations in the same order but for J^T w's sums: the results agree to rounding
 * (test/unit/balance/test_compiled_statics.py holds them to 1e-9).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "atlas_statics.h"

size_t tac_sizeof_AtlasStatics(void) { return sizeof(AtlasStatics); }

static double clamp(double value, double low, double high) {
  /* Python's min(max(value, low), high) */
  double raised = low > value ? low : value;
  return high < raised ? high : raised;
}

static void cross(const double a[3], const double b[3], double out[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

/* A wrench's moment about `point`, given its moment about `com`. */
static void moment_about(const double point[3], const double com[3], const double force[3],
                         const double moment[3], double out[3]) {
  double arm[3] = {com[0] - point[0], com[1] - point[1], com[2] - point[2]}, lever[3];
  cross(arm, force, lever);
  for (int i = 0; i < 3; ++i) out[i] = moment[i] + lever[i];
}

static double left_share(const double force[3], const double moment_mid[3],
                         const double left[3], const double right[3], double min_share) {
  double ux = left[0] - right[0], uy = left[1] - right[1];
  double distance = hypot(ux, uy);
  if (force[2] <= 0.0 || distance == 0.0) return 0.5;
  double difference = 2.0 * (moment_mid[0] * uy - moment_mid[1] * ux) / (distance * distance);
  double share = 0.5 + difference / (2.0 * force[2]);
  return clamp(share, min_share, 1.0 - min_share);
}

static void split_wrench(const AtlasStatics *s, double w[12]) {
  const double *force = s->in + IN_FORCE, *moment = s->in + IN_MOMENT, *com = s->in + IN_COM;
  const double *left = s->in + IN_CENTRES, *right = left + 3;
  int in_left = s->feet[CARRIES] != 0.0, in_right = s->feet[FOOT + CARRIES] != 0.0;
  memset(w, 0, 12 * sizeof(double));
  if (in_left != in_right) {
    int foot = in_left ? 0 : 1;
    memcpy(w + 6 * foot, force, 3 * sizeof(double));
    moment_about(foot == 0 ? left : right, com, force, moment, w + 6 * foot + 3);
    return;
  }
  if (!in_left) return;
  double middle[3], moment_mid[3], made[3] = {0.0, 0.0, 0.0};
  for (int i = 0; i < 3; ++i) middle[i] = (left[i] + right[i]) / 2.0;
  moment_about(middle, com, force, moment, moment_mid);
  double share = left_share(force, moment_mid, left, right, s->min_load_share);
  double shares[2] = {share, 1.0 - share};
  for (int foot = 0; foot < 2; ++foot) {
    const double *sole = foot == 0 ? left : right;
    double foot_force[3], arm[3], lever[3];
    for (int i = 0; i < 3; ++i) {
      foot_force[i] = shares[foot] * force[i];
      arm[i] = sole[i] - middle[i];
    }
    cross(arm, foot_force, lever);
    for (int i = 0; i < 3; ++i) made[i] = made[i] + lever[i];
    memcpy(w + 6 * foot, foot_force, 3 * sizeof(double));
  }
  for (int i = 0; i < 3; ++i) {
    double rest = moment_mid[i] - made[i];
    w[3 + i] = share * rest;
    w[9 + i] = (1.0 - share) * rest;
  }
}

/* `f` with its part along the surface (normal n) within friction times its pressing part. */
static void within_friction(double f[3], const double n[3], double friction) {
  double pressing = f[0] * n[0] + f[1] * n[1] + f[2] * n[2];
  double tangential[3];
  for (int i = 0; i < 3; ++i) tangential[i] = f[i] - pressing * n[i];
  double size = sqrt(tangential[0] * tangential[0] + tangential[1] * tangential[1] +
                     tangential[2] * tangential[2]);
  double limit = friction * (0.0 > pressing ? 0.0 : pressing);
  if (size <= limit) return;
  double scale = 1.0 - limit / size;
  for (int i = 0; i < 3; ++i) f[i] = f[i] - scale * tangential[i];
}

static void make_feasible(double w[6], const double r[9], const double *foot) {
  double f[3] = {w[0], w[1], 0.0 > w[2] ? 0.0 : w[2]}; /* Python's max(f_z, 0.0) */
  double mx = w[3], my = w[4], mz = w[5];
  if (!isnan(foot[FRICTION])) {
    double normal[3] = {r[2], r[5], r[8]};
    within_friction(f, normal, foot[FRICTION]);
  }
  double fz = f[2];
  double lx = r[0] * mx + r[3] * my + r[6] * mz;
  double ly = r[1] * mx + r[4] * my + r[7] * mz;
  double lz = r[2] * mx + r[5] * my + r[8] * mz;
  /* the pressure centre (-ly / fz, lx / fz) within the region about its centre */
  lx = clamp(lx, fz * (foot[CENTRE_ACROSS] - foot[HALF_WIDTH]),
             fz * (foot[CENTRE_ACROSS] + foot[HALF_WIDTH]));
  ly = clamp(ly, -fz * (foot[CENTRE_ALONG] + foot[HALF_LENGTH]),
             -fz * (foot[CENTRE_ALONG] - foot[HALF_LENGTH]));
  if (!isnan(foot[TORSION])) lz = clamp(lz, -fz * foot[TORSION], fz * foot[TORSION]);
  w[0] = f[0];
  w[1] = f[1];
  w[2] = f[2];
  w[3] = r[0] * lx + r[1] * ly + r[2] * lz;
  w[4] = r[3] * lx + r[4] * ly + r[5] * lz;
  w[5] = r[6] * lx + r[7] * ly + r[8] * lz;
}

void atlas_inverse_statics(const AtlasStatics *s) {
  long n = s->n;
  double *w = s->wrenches;
  split_wrench(s, w);
  for (int foot = 0; foot < 2; ++foot)
    make_feasible(w + 6 * foot, s->in + IN_ROTATIONS + 9 * foot, s->feet + FOOT * foot);
  const double *bias = s->in + IN_BIAS, *jac = bias + n;
  for (long j = 0; j < n; ++j) {
    double sum = 0.0;
    for (int k = 0; k < 12; ++k) sum += jac[k * n + j] * w[k];
    s->torque[j] = bias[j] - sum;
  }
}
