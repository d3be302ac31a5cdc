/*
 * Walk's single-support tick of the legs in one call: the compiled twin of LegTasks.torque
 * then LegTasks.finish with a foot swinging (src/tutorial_atlas_control/walking/leg_tasks.py,
 * whose docstrings give the rules): the pressure centre clamped to the stance sole's
 * rectangle (_clamp_to_sole), the whole-body solve there (atlas_whole_body, its input loaded
 * by the Python glue for this tick), the swing leg's servo along its path (atlas_swing_torque,
 * its state's numbers read here from the estimate's row and the leg's inertia from MuJoCo's
 * mass matrix of the estimate's scratch data), their sum within the effort limits. In Python
 * the glue around the two calls (the sole clamp, the swing input's copies, the inertia block,
 * the results' arrays, the sum and the clamp) cost more than the calls themselves; here it is
 * one ctypes call (walking/compiled_legs.py). The same operations in the same order as the
 * compiled pieces: the results agree with them and with the Python to rounding
 * (test/unit/walking/test_compiled_legs.py holds them to 1e-9). With both feet able to
 * carry, LegTasks.torque's pressure centre kept in the carrying soles' hull shrunk by the
 * margin (box_corners, support.convex_hull, support.clamp_into: some hundred Python
 * operations a tick) is one call too.
 */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "atlas_legs.h"

size_t tac_sizeof_AtlasLegs(void) { return sizeof(AtlasLegs); }
size_t tac_sizeof_AtlasLegsSupport(void) { return sizeof(AtlasLegsSupport); }

/* _clamp_to_sole: `p` moved to the nearest point of the stance sole's rectangle. */
static void clamp_to_sole(const AtlasLegs *legs, const double *centre, const double *r,
                          double p[2]) {
  double dx = p[0] - centre[0], dy = p[1] - centre[1];
  double reach_x = legs->reach[0], reach_y = legs->reach[1];
  double along = r[0] * dx + r[3] * dy, across = r[1] * dx + r[4] * dy;
  along = -reach_x > along ? -reach_x : along; /* Python's min(max(v, -reach), reach) */
  along = reach_x < along ? reach_x : along;
  across = -reach_y > across ? -reach_y : across;
  across = reach_y < across ? reach_y : across;
  p[0] = centre[0] + (r[0] * along + r[1] * across);
  p[1] = centre[1] + (r[3] * along + r[4] * across);
}

/* sole_support.near_asked: the stance sole's constraint `foot` (FOOT numbers) kept to the
 * rectangle within near_m of the pressure centre `p` or of the bearing box, along and across
 * the sole, and on it. */
static void near_asked(const AtlasLegs *legs, const double *centre, const double *r,
                       const double p[2], double *foot) {
  double dx = p[0] - centre[0], dy = p[1] - centre[1], near = legs->near_m;
  double asked[2] = {r[0] * dx + r[3] * dy, r[1] * dx + r[4] * dy};
  double halves[2] = {foot[HALF_LENGTH], foot[HALF_WIDTH]}, low[2], high[2];
  for (int k = 0; k < 2; ++k) { /* Python's max(min(a, s) - near, -h), min(max(a, s) + near, h) */
    double lowest = legs->bearing[2 * k], highest = legs->bearing[2 * k + 1];
    double a = (asked[k] <= lowest ? asked[k] : lowest) - near;
    double b = (asked[k] >= highest ? asked[k] : highest) + near;
    low[k] = a >= -halves[k] ? a : -halves[k];
    high[k] = b <= halves[k] ? b : halves[k];
    high[k] = high[k] >= low[k] ? high[k] : low[k]; /* a point at worst */
  }
  foot[HALF_LENGTH] = 0.5 * (high[0] - low[0]);
  foot[HALF_WIDTH] = 0.5 * (high[1] - low[1]);
  foot[CENTRE_ALONG] = 0.5 * (low[0] + high[0]);
  foot[CENTRE_ACROSS] = 0.5 * (low[1] + high[1]);
}

/* The whole body at the kept pressure centre: across facets (near_m > 0) on a copy of the
 * soles' constraints with the stance sole's kept near it (the loaded ones left as they are). */
static void stance_whole_body(const AtlasLegs *legs, const double *centre, const double *r,
                              const double cop[2]) {
  const AtlasWholeBody *w = legs->whole_body;
  if (!(legs->near_m > 0.0)) {
    atlas_whole_body(w);
    return;
  }
  AtlasStatics *statics = w->statics;
  const double *loaded = statics->feet;
  double feet[2 * FOOT];
  memcpy(feet, loaded, sizeof feet);
  near_asked(legs, centre, r, cop, feet + FOOT * legs->stance);
  statics->feet = feet;
  atlas_whole_body(w);
  statics->feet = loaded;
}

/* CompiledSwing._load from the row: the swing sole's jacobian (its leg's columns), pose and
 * velocity, the leg's joint rates, and its inertia block (mj_fullM; mj_crb first unless the
 * estimate copied the step's mass matrix: the same numbers). */
static void load_swing(const AtlasLegs *legs) {
  const AtlasWholeBody *w = legs->whole_body;
  const double *row = w->row;
  const long *at = w->row_at;
  long n = w->statics->n, foot = 1 - legs->stance, start = legs->leg_start;
  double *in = legs->swing->in;
  const double *jacobian = row + at[WB_ROW_JACOBIANS] + 6 * n * foot;
  for (int i = 0; i < 6; ++i)
    memcpy(in + IN_JACOBIAN + LEG * i, jacobian + n * i + start, LEG * sizeof(double));
  memcpy(in + IN_CENTRE, row + at[WB_ROW_SOLE_CENTRES] + 3 * foot, 3 * sizeof(double));
  memcpy(in + IN_ROTATION, row + at[WB_ROW_SOLE_ROTATIONS] + 9 * foot, 9 * sizeof(double));
  memcpy(in + IN_SOLE_VELOCITY, row + legs->sole_velocities_at + 6 * foot, 6 * sizeof(double));
  memcpy(in + IN_JOINT_VELOCITY, w->in + WB_IN_JOINTS + n + start, LEG * sizeof(double));
  if (legs->mass_current == NULL || !*legs->mass_current) mj_crb(legs->model, legs->data);
  mj_fullM(legs->model, legs->data, legs->mass_matrix);
  long nv = legs->model->nv;
  for (int i = 0; i < LEG; ++i)
    for (int j = 0; j < LEG; ++j)
      in[IN_INERTIA + LEG * i + j] = legs->mass_matrix[nv * legs->leg_dofs[i] + legs->leg_dofs[j]];
}

/* WholeBodyLayer.limit on the legs' torques: np.maximum then np.minimum. */
static void limit_efforts(const AtlasWholeBody *w, double *torque) {
  const double *limit = w->effort_limit;
  for (long j = 0; j < w->statics->n; ++j) {
    double low = -limit[j], raised = low > torque[j] ? low : torque[j];
    torque[j] = limit[j] < raised ? limit[j] : raised;
  }
}

/* LegTasks.torque then LegTasks.finish, one foot swinging. */
void atlas_legs_swing_tick(const AtlasLegs *legs) {
  const AtlasWholeBody *w = legs->whole_body;
  const double *row = w->row;
  long n = w->statics->n, stance = legs->stance;
  double *cop = (double *)w->in + WB_IN_COP;
  const double *centre = row + w->row_at[WB_ROW_SOLE_CENTRES] + 3 * stance;
  const double *r = row + w->row_at[WB_ROW_SOLE_ROTATIONS] + 9 * stance;
  clamp_to_sole(legs, centre, r, cop);
  stance_whole_body(legs, centre, r, cop);
  load_swing(legs);
  atlas_swing_torque(legs->swing);
  double *torque = legs->out;
  memcpy(torque, w->statics->torque, (size_t)n * sizeof(double));
  for (long j = 0; j < LEG; ++j)
    torque[legs->leg_start + j] = torque[legs->leg_start + j] + legs->swing->torque[j];
  limit_efforts(w, torque);
  torque[n] = cop[0];
  torque[n + 1] = cop[1];
}

/* Points ordered as Python orders tuples: by x, then y. */
static int by_x_then_y(const void *first, const void *second) {
  const double *a = first, *b = second;
  if (a[0] != b[0]) return a[0] < b[0] ? -1 : 1;
  if (a[1] != b[1]) return a[1] < b[1] ? -1 : 1;
  return 0;
}

/* support.convex_hull's chain over `count` ordered points (step 2 or -2 doubles). */
static long chain(const double *points, long count, long step, double hull[][2]) {
  long size = 0;
  for (long i = 0; i < count; ++i) {
    double x = points[step * i], y = points[step * i + 1];
    while (size >= 2) {
      double ox = hull[size - 2][0], oy = hull[size - 2][1];
      double ax = hull[size - 1][0], ay = hull[size - 1][1];
      if ((ax - ox) * (y - oy) - (ay - oy) * (x - ox) > 0.0) break;
      --size;
    }
    hull[size][0] = x;
    hull[size][1] = y;
    ++size;
  }
  return size;
}

/* support._inward_lines: each edge's inward unit normal and offset, into the rows' 2..4. */
static void inward_lines(double rows[][5], long count) {
  for (long i = 0; i < count; ++i) {
    const double *a = rows[i], *b = rows[(i + 1) % count];
    double nx = a[1] - b[1], ny = b[0] - a[0], length = hypot(nx, ny);
    nx = nx / length;
    ny = ny / length;
    rows[i][2] = nx;
    rows[i][3] = ny;
    rows[i][4] = nx * a[0] + ny * a[1];
  }
}

/* The smallest signed distance of (x, y) to the rows' edge lines (support._distance). */
static double distance(double rows[][5], long count, double x, double y) {
  double least = INFINITY;
  for (long i = 0; i < count; ++i) {
    double d = rows[i][2] * x + rows[i][3] * y - rows[i][4];
    if (d < least) least = d;
  }
  return least;
}

/* support.Region(hull, margin): the hull's vertices shrunk into `region` (rows of vertex
 * x, y and its edge's line); its row count. */
static long shrunk_region(double hull[][2], long count, double margin, double region[][5]) {
  for (long i = 0; i < count; ++i) {
    region[i][0] = hull[i][0];
    region[i][1] = hull[i][1];
  }
  if (count < 3) return count;
  if (!(margin <= 0.0)) {
    double cx = 0.0, cy = 0.0, lines[8][5];
    for (long i = 0; i < count; ++i) {
      cx = cx + hull[i][0];
      cy = cy + hull[i][1];
      lines[i][0] = hull[i][0];
      lines[i][1] = hull[i][1];
    }
    cx = cx / (double)count;
    cy = cy / (double)count;
    inward_lines(lines, count);
    if (distance(lines, count, cx, cy) <= margin) {
      region[0][0] = cx;
      region[0][1] = cy;
      return 1;
    }
    for (long i = 0; i < count; ++i) { /* Cramer's rule on edges i - 1 and i, moved */
      const double *a = lines[(i + count - 1) % count], *b = lines[i];
      double a_off = a[4] + margin, b_off = b[4] + margin;
      double det = a[2] * b[3] - a[3] * b[2];
      region[i][0] = (a_off * b[3] - b_off * a[3]) / det;
      region[i][1] = (a[2] * b_off - b[2] * a_off) / det;
    }
  }
  inward_lines(region, count);
  return count;
}

/* LegTasks.torque's pressure centre with no foot swinging: out's pressure centre (after the
 * n torques) clamped into the carrying soles' hull shrunk by the margin. */
void atlas_legs_support_clamp(const AtlasLegs *legs) {
  const AtlasWholeBody *w = legs->whole_body;
  const double *centres = legs->row + w->row_at[WB_ROW_SOLE_CENTRES];
  const double *rotations = legs->row + w->row_at[WB_ROW_SOLE_ROTATIONS];
  static const double signs[4][2] = {{1.0, 1.0}, {1.0, -1.0}, {-1.0, -1.0}, {-1.0, 1.0}};
  double points[8][2], hull[18][2], region[8][5];
  long count = 0;
  for (int foot = 0; foot < 2; ++foot) {
    if (!legs->carrying[foot]) continue;
    const double *p = centres + 3 * foot, *r = rotations + 9 * foot;
    for (int c = 0; c < 4; ++c) { /* box_corners: position + offsets @ rotation.T */
      double ox = signs[c][0] * legs->half_size[0], oy = signs[c][1] * legs->half_size[1];
      double oz = -1.0 * 0.0;
      for (int k = 0; k < 2; ++k)
        points[count][k] = p[k] + (ox * r[3 * k] + oy * r[3 * k + 1] + oz * r[3 * k + 2]);
      ++count;
    }
  }
  qsort(points, (size_t)count, sizeof(points[0]), by_x_then_y);
  long unique = 0; /* the set's duplicates dropped */
  for (long i = 0; i < count; ++i)
    if (unique == 0 || by_x_then_y(points[i], points[unique - 1]) != 0) {
      points[unique][0] = points[i][0];
      points[unique][1] = points[i][1];
      ++unique;
    }
  long size;
  if (unique < 3) {
    for (long i = 0; i < unique; ++i) {
      hull[i][0] = points[i][0];
      hull[i][1] = points[i][1];
    }
    size = unique;
  } else {
    double lower[9][2], upper[9][2];
    long low = chain(&points[0][0], unique, 2, lower);
    long up = chain(&points[unique - 1][0], unique, -2, upper);
    size = 0;
    for (long i = 0; i + 1 < low; ++i, ++size) {
      hull[size][0] = lower[i][0];
      hull[size][1] = lower[i][1];
    }
    for (long i = 0; i + 1 < up; ++i, ++size) {
      hull[size][0] = upper[i][0];
      hull[size][1] = upper[i][1];
    }
  }
  long rows = shrunk_region(hull, size, legs->margin_m, region);
  atlas_clamp_into_rows(&region[0][0], rows, legs->out + w->statics->n);
}

/* LegTasks.flat_down: the sole's centre within flat_height_m over its surface and its normal
 * within acos(flat_cos) of the surface's. */
static int flat_down(const AtlasLegsSupport *s, const double *row, const long *at, int foot) {
  const double *centre = row + at[WB_ROW_SOLE_CENTRES] + 3 * foot;
  const double *r = row + at[WB_ROW_SOLE_ROTATIONS] + 9 * foot;
  const double *pose = s->feet[foot];
  if (!(centre[2] - pose[FOOT_Z] < s->flat_height_m)) return 0;
  const double *normal = pose + FOOT_NORMAL;
  return r[2] * normal[0] + r[5] * normal[1] + r[8] * normal[2] > s->flat_cos;
}

/* LegTasks.put_down_torque added to `torque` (LegTasks.finish's sum: every joint, the leg's
 * the servo's, the others + 0.0): the foot's sole servoed onto its pose, pressed down. */
static void add_put_down(const AtlasLegsSupport *s, int foot, double *torque) {
  AtlasLegs *legs = s->legs;
  AtlasSwing *swing = (AtlasSwing *)legs->swing;
  legs->stance = 1 - foot;
  legs->leg_start = s->leg_starts[foot];
  memcpy(legs->leg_dofs, s->leg_dofs[foot], sizeof(legs->leg_dofs));
  load_swing(legs);
  const double *pose = s->feet[foot];
  double *in = swing->in;
  in[IN_POSITION] = pose[FOOT_X];
  in[IN_POSITION + 1] = pose[FOOT_Y];
  in[IN_POSITION + 2] = pose[FOOT_Z_PRESSED];
  for (int k = 0; k < 3; ++k) in[IN_VELOCITY + k] = in[IN_ACCELERATION + k] = 0.0;
  in[IN_YAW] = pose[FOOT_YAW];
  in[IN_YAW_RATE] = in[IN_YAW_ACCELERATION] = 0.0;
  in[IN_TILT] = pose[FOOT_TILT_X];
  in[IN_TILT + 1] = pose[FOOT_TILT_Y];
  swing->world = 0;
  swing->feedforward = 0;
  atlas_foot_servo(swing);
  long n = legs->whole_body->statics->n, start = legs->leg_start;
  for (long j = 0; j < n; ++j)
    torque[j] = torque[j] + (j >= start && j < start + LEG ? swing->torque[j - start] : 0.0);
}

/* LegTasks.torque then LegTasks.finish with no foot swinging: the law's pressure centre kept
 * in the carrying soles' hull shrunk by the margin, the whole body there, each foot that
 * should carry but is not flat down put back on its pose, the sum within the effort limits. */
void atlas_legs_support_tick(const AtlasLegsSupport *s) {
  AtlasLegs *legs = s->legs;
  const AtlasWholeBody *w = legs->whole_body;
  long n = w->statics->n;
  double *torque = legs->out;
  atlas_legs_support_clamp(legs);
  double *cop = (double *)w->in + WB_IN_COP;
  cop[0] = torque[n];
  cop[1] = torque[n + 1];
  atlas_whole_body(w);
  memcpy(torque, w->statics->torque, (size_t)n * sizeof(double));
  for (int foot = 0; foot < 2; ++foot)
    if (!legs->carrying[foot] || !flat_down(s, w->row, w->row_at, foot))
      add_put_down(s, foot, torque);
  limit_efforts(w, torque);
}
