/*
 * The balance estimator's per-tick work in one call: the compiled twin of
 * BalanceEstimator.estimate in src/tutorial_atlas_control/balance/estimator.py (whose
 * docstring says what it computes and why). Python's estimate spends more time in numpy's
 * indexing and copies than MuJoCo spends in its passes; here the passes and the arithmetic
 * run in one ctypes call (balance/compiled_estimator.py) that writes one flat array.
 *
 * MuJoCo is the one the Python bindings loaded: this library is linked against the wheel's
 * libmujoco.so.4.0.0 (CMakeLists.txt), whose soname the dynamic linker finds already loaded,
 * and the model and data are the bindings' own (MjModel._address, MjData._address).
 * The results agree with Python's to rounding (sums in another order), not bit for bit:
 * test/unit/balance/test_compiled_estimator.py holds them to 1e-9.
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include <mujoco/mujoco.h>

/* What the estimator keeps between calls; laid out once by balance/compiled_estimator.py,
 * mirrored in native.py (same fields, same order; tac_sizeof_AtlasEstimator lets the
 * loader check). */
typedef struct {
  const mjModel *model;       /* the estimator's copy of the model (wide sole margins) */
  mjData *data;               /* its scratch MjData */
  const double *qpos;         /* (nq,) the state to estimate, copied in by Python */
  const double *qvel;         /* (nv,) */
  double *out;                /* this tick's output (the layout below), set each tick */
  const ptrdiff_t *dof_adr;   /* (n,) qvel index of each joint, tutorial order */
  double *jac;                /* (2, 6, nv) scratch: [linear; angular] per sole */
  double *bias;               /* (nv,) scratch: qfrc_bias */
  double half_thickness[2];   /* the sole boxes' half thickness (m), left, right */
  double gravity_m_s2;        /* lipm.GRAVITY_M_S2 */
  double min_com_height_m;    /* estimator.MIN_COM_HEIGHT_M */
  double ground_m;            /* the pendulum's ground (m, world z): its height is over it */
  long n;                     /* joints */
  long soles[2];              /* the sole geoms, left, right */
  long sole_bodies[2];        /* their bodies */
  long pelvis;                /* the pelvis body: the robot's subtree */
  long free_dof;              /* the floating base's first dof */
  long contact_capacity;      /* contact rows the output holds */
  /* The support polygon's cache (estimator._support_polygon's): the sole poses and contact
   * flags the last handed-over polygon was made from, set by Python when it hands one over
   * (NULL: none yet). Python keeps them because it alone knows which estimate's polygon was
   * asked for (Walk's single support never asks): the reference moves only then. */
  const double *polygon_positions;   /* (2, 3) sole box centres */
  const double *polygon_rotations;   /* (2, 3, 3) */
  long polygon_contact[2];
  double polygon_tolerance_m;        /* estimator.POLYGON_TOLERANCE_M */
  double rotation_tolerance;         /* the rotation entries' change that moves a corner so */
  double corner_offsets[2][4][3];    /* each sole's bottom corners in its own frame */
  long mass_current;          /* 1: the scratch data's mass matrix (d->M) is the last estimate's
                               * state's, copied from the step (atlas_estimate_stepped); 0: not
                               * computed (atlas_estimate). Walk's legs run mj_crb only then. */
  /* Which contacts bear and when a sole is across facets (balance/sole.py's PRESSED_M,
   * UPRIGHT_COS, ONE_SURFACE_COS): each sole's bearing summary (OUT_BEARING). */
  double pressed_m;
  double upright_cos;
  double one_surface_cos;
} AtlasEstimator;

/* The output, flat doubles (compiled_estimator.py's FIXED_FIELDS and POLYGON_* say the same). */
enum {
  OUT_COM = 0, OUT_COM_VELOCITY = 3, OUT_PELVIS_POSITION = 6, OUT_PELVIS_ROTATION = 9,
  OUT_PELVIS_ANGULAR_VELOCITY = 18, OUT_SOLE_POSITIONS = 21, OUT_SOLE_CENTRES = 27,
  OUT_SOLE_ROTATIONS = 33, OUT_IN_CONTACT = 51, OUT_OMEGA = 53, OUT_CAPTURE_POINT = 54,
  OUT_SOLE_VELOCITIES = 56, OUT_POLYGON_KEPT = 68, OUT_POLYGON_COUNT = 69, OUT_POLYGON = 70,
  OUT_BEARING = 86, OUT_FIXED = 96
  /* OUT_POLYGON_KEPT: 1 when the cached polygon still holds, else the hull of the touching
   * soles' corners is at OUT_POLYGON (OUT_POLYGON_COUNT vertices, x y each); OUT_BEARING:
   * each sole's bearing summary (bearings()); then bias (n),
   * sole jacobians (2, 6, n), contact counts (2), contact rows (capacity, ROW): point (3),
   * normal into the sole (3), distance, surface geom */
};
#define ROW 8

size_t tac_sizeof_AtlasEstimator(void) { return sizeof(AtlasEstimator); }

/* Each sole's rows of the contact list (left's, then right's) into rows[capacity][ROW];
 * counts[foot] = that sole's rows. Returns the total, written only while within capacity.
 * MuJoCo's normal points from geom[0] to geom[1]: into the sole when the sole is geom[1]. */
long atlas_estimator_contacts(const AtlasEstimator *e, double *counts, double *rows,
                              long capacity) {
  const mjData *d = e->data;
  long total = 0;
  for (int foot = 0; foot < 2; ++foot) {
    long sole = e->soles[foot], count = 0;
    for (int c = 0; c < d->ncon; ++c) {
      const mjContact *con = &d->contact[c];
      if (con->geom[0] != sole && con->geom[1] != sole) continue;
      if (total < capacity) {
        double *row = rows + ROW * total;
        double sign = con->geom[1] == sole ? 1.0 : -1.0;
        memcpy(row, con->pos, 3 * sizeof(double));
        for (int i = 0; i < 3; ++i) row[3 + i] = sign * con->frame[i];
        row[6] = con->dist;
        row[7] = (double)(con->geom[1] == sole ? con->geom[0] : con->geom[1]);
      }
      ++count;
      ++total;
    }
    counts[foot] = (double)count;
  }
  return total;
}

/* The sole boxes' poses, their bottom-face centres, jacobians and velocities. */
static void soles(const AtlasEstimator *e, double *out) {
  const mjModel *m = e->model;
  mjData *d = e->data;
  long nv = m->nv, n = e->n;
  double *jac_out = out + OUT_FIXED + n;
  for (int foot = 0; foot < 2; ++foot) {
    const double *pos = d->geom_xpos + 3 * e->soles[foot];
    const double *mat = d->geom_xmat + 9 * e->soles[foot];
    double *centre = out + OUT_SOLE_CENTRES + 3 * foot;
    memcpy(out + OUT_SOLE_POSITIONS + 3 * foot, pos, 3 * sizeof(double));
    memcpy(out + OUT_SOLE_ROTATIONS + 9 * foot, mat, 9 * sizeof(double));
    for (int i = 0; i < 3; ++i) centre[i] = pos[i] - mat[3 * i + 2] * e->half_thickness[foot];
    double *jac = e->jac + 6 * nv * foot;
    mj_jac(m, d, jac, jac + 3 * nv, centre, (int)e->sole_bodies[foot]);
    for (int r = 0; r < 6; ++r) {
      double sum = 0.0;
      for (long k = 0; k < nv; ++k) sum += jac[r * nv + k] * d->qvel[k];
      out[OUT_SOLE_VELOCITIES + 6 * foot + r] = sum;
      for (long j = 0; j < n; ++j)
        jac_out[(6 * foot + r) * n + j] = jac[r * nv + e->dof_adr[j]];
    }
  }
}

/* Whether every a[i] - b[i] is within +-tolerance (NaN: not): estimator._within. */
static int within(const double *a, const double *b, int count, double tolerance) {
  for (int i = 0; i < count; ++i) {
    double difference = a[i] - b[i];
    if (!(-tolerance < difference && difference < tolerance)) return 0;
  }
  return 1;
}

/* Whether the polygon last handed over still holds: the same contacts, and neither sole box
 * moved its tolerance (estimator.BalanceEstimator._support_polygon's test). */
static int polygon_kept(const AtlasEstimator *e, const double *out) {
  if (e->polygon_positions == NULL) return 0;
  for (int foot = 0; foot < 2; ++foot)
    if ((out[OUT_IN_CONTACT + foot] != 0.0) != (e->polygon_contact[foot] != 0)) return 0;
  return within(out + OUT_SOLE_POSITIONS, e->polygon_positions, 6, e->polygon_tolerance_m) &&
         within(out + OUT_SOLE_ROTATIONS, e->polygon_rotations, 18, e->rotation_tolerance);
}

/* Lexicographic order of (x, y) points, as Python orders tuples. */
static int before(const double *a, const double *b) {
  return a[0] < b[0] || (a[0] == b[0] && a[1] < b[1]);
}

/* One chain of Andrew's monotone chain over points[0..count) taken in `step` order
 * (support.convex_hull's chain, the same arithmetic); returns its length in chain. */
static int chain(const double (*points)[2], int count, int step, double (*hull)[2]) {
  int length = 0;
  for (int k = 0; k < count; ++k) {
    const double *p = points[step > 0 ? k : count - 1 - k];
    while (length >= 2) {
      const double *o = hull[length - 2], *a = hull[length - 1];
      if ((a[0] - o[0]) * (p[1] - o[1]) - (a[1] - o[1]) * (p[0] - o[0]) > 0.0) break;
      --length;
    }
    hull[length][0] = p[0];
    hull[length][1] = p[1];
    ++length;
  }
  return length;
}

/* support.convex_hull of the touching soles' bottom corners (estimator's _support_polygon:
 * each corner the box centre plus its rotated offset, summed in the order numpy 2.4's einsum
 * sums three products, (0 + 2) + 1: the test holds the two bit for bit), into
 * out[OUT_POLYGON]; returns the vertex count. */
static int support_polygon(const AtlasEstimator *e, double *out) {
  double points[8][2], lower[9][2], upper[9][2];
  int count = 0;
  for (int foot = 0; foot < 2; ++foot) {
    if (out[OUT_IN_CONTACT + foot] == 0.0) continue;
    const double *pos = out + OUT_SOLE_POSITIONS + 3 * foot;
    const double *mat = out + OUT_SOLE_ROTATIONS + 9 * foot;
    for (int c = 0; c < 4; ++c) {
      const double *offset = e->corner_offsets[foot][c];
      double point[2];
      for (int i = 0; i < 2; ++i)
        point[i] = pos[i] + ((offset[0] * mat[3 * i] + offset[2] * mat[3 * i + 2]) +
                             offset[1] * mat[3 * i + 1]);
      int at = count;  /* insertion sort; an equal point is dropped (Python's set) */
      int equal = 0;
      for (int k = 0; k < count; ++k)
        if (points[k][0] == point[0] && points[k][1] == point[1]) equal = 1;
      if (equal) continue;
      while (at > 0 && before(point, points[at - 1])) {
        points[at][0] = points[at - 1][0];
        points[at][1] = points[at - 1][1];
        --at;
      }
      points[at][0] = point[0];
      points[at][1] = point[1];
      ++count;
    }
  }
  double *polygon = out + OUT_POLYGON;
  if (count < 3) {
    memcpy(polygon, points, 2 * count * sizeof(double));
    return count;
  }
  int lows = chain((const double (*)[2])points, count, 1, lower);
  int ups = chain((const double (*)[2])points, count, -1, upper);
  int vertices = 0;
  for (int k = 0; k + 1 < lows; ++k, ++vertices)
    memcpy(polygon + 2 * vertices, lower[k], 2 * sizeof(double));
  for (int k = 0; k + 1 < ups; ++k, ++vertices)
    memcpy(polygon + 2 * vertices, upper[k], 2 * sizeof(double));
  return vertices;
}

/* Each sole's bearing summary into out[OUT_BEARING + 5 * foot]: 1.0 when the normals of its
 * bearing contacts (within pressed_m of their surface, normal z >= upright_cos) are apart
 * (some more than acos(one_surface_cos) from the first's), else 0.0; then the box of those
 * contacts in the sole's frame from its bottom-face centre: lowest and highest along, lowest
 * and highest across (+inf, -inf, +inf, -inf with none). walking/sole_support.py's _bearing,
 * _apart and _span_of, the same arithmetic in the same order, over every contact of the
 * list (the rows beyond contact_capacity too). Needs the sole centres and rotations out. */
static void bearings(const AtlasEstimator *e, double *out) {
  const mjData *d = e->data;
  for (int foot = 0; foot < 2; ++foot) {
    long sole = e->soles[foot];
    const double *c = out + OUT_SOLE_CENTRES + 3 * foot;
    const double *r = out + OUT_SOLE_ROTATIONS + 9 * foot;
    double *summary = out + OUT_BEARING + 5 * foot;
    double first[3] = {0.0, 0.0, 0.0};
    int bearing = 0, apart = 0;
    summary[1] = summary[3] = INFINITY;
    summary[2] = summary[4] = -INFINITY;
    for (int k = 0; k < d->ncon; ++k) {
      const mjContact *con = &d->contact[k];
      if (con->geom[0] != sole && con->geom[1] != sole) continue;
      double sign = con->geom[1] == sole ? 1.0 : -1.0;
      double normal[3] = {sign * con->frame[0], sign * con->frame[1], sign * con->frame[2]};
      if (!(con->dist <= e->pressed_m && normal[2] >= e->upright_cos)) continue;
      if (bearing++ == 0) {
        memcpy(first, normal, sizeof first);
      } else if (first[0] * normal[0] + first[1] * normal[1] + first[2] * normal[2] <
                 e->one_surface_cos) {
        apart = 1;
      }
      double dx = con->pos[0] - c[0], dy = con->pos[1] - c[1], dz = con->pos[2] - c[2];
      double along = dx * r[0] + dy * r[3] + dz * r[6];
      double across = dx * r[1] + dy * r[4] + dz * r[7];
      if (along < summary[1]) summary[1] = along;
      if (along > summary[2]) summary[2] = along;
      if (across < summary[3]) summary[3] = across;
      if (across > summary[4]) summary[4] = across;
    }
    summary[0] = apart ? 1.0 : 0.0;
  }
}

/* The estimate from the scratch data's passes (the state's kinematics, collision, centre of
 * mass and its velocity, subtree velocity) and the bias forces in e->bias, into out;
 * returns the sole contacts' row count. */
static long estimate_from_passes(const AtlasEstimator *e) {
  mjData *d = e->data;
  double *out = e->out;
  long n = e->n;
  soles(e, out);
  const double *com = d->subtree_com + 3 * e->pelvis;
  const double *com_velocity = d->subtree_linvel + 3 * e->pelvis;
  const double *rotation = d->xmat + 9 * e->pelvis;
  const double *rates = d->qvel + e->free_dof + 3;
  memcpy(out + OUT_COM, com, 3 * sizeof(double));
  memcpy(out + OUT_COM_VELOCITY, com_velocity, 3 * sizeof(double));
  memcpy(out + OUT_PELVIS_POSITION, d->xpos + 3 * e->pelvis, 3 * sizeof(double));
  memcpy(out + OUT_PELVIS_ROTATION, rotation, 9 * sizeof(double));
  for (int i = 0; i < 3; ++i)
    out[OUT_PELVIS_ANGULAR_VELOCITY + i] =
        rotation[3 * i] * rates[0] + rotation[3 * i + 1] * rates[1] +
        rotation[3 * i + 2] * rates[2];
  double over = com[2] - e->ground_m;
  double height = over > e->min_com_height_m ? over : e->min_com_height_m;
  double omega = sqrt(e->gravity_m_s2 / height);
  out[OUT_OMEGA] = omega;
  for (int i = 0; i < 2; ++i) out[OUT_CAPTURE_POINT + i] = com[i] + com_velocity[i] / omega;
  for (long j = 0; j < n; ++j) out[OUT_FIXED + j] = e->bias[e->dof_adr[j]];
  double *counts = out + OUT_FIXED + 13 * n;
  long total = atlas_estimator_contacts(e, counts, counts + 2, e->contact_capacity);
  out[OUT_IN_CONTACT] = counts[0] > 0 ? 1.0 : 0.0;
  out[OUT_IN_CONTACT + 1] = counts[1] > 0 ? 1.0 : 0.0;
  bearings(e, out);
  int kept = polygon_kept(e, out);
  out[OUT_POLYGON_KEPT] = kept ? 1.0 : 0.0;
  out[OUT_POLYGON_COUNT] = kept ? 0.0 : (double)support_polygon(e, out);
  return total;
}

/* The estimate at (qpos, qvel) (full MuJoCo vectors) into out; returns the sole contacts'
 * row count (rows beyond contact_capacity are not written: atlas_estimator_contacts then). */
long atlas_estimate(AtlasEstimator *e) {
  const mjModel *m = e->model;
  mjData *d = e->data;
  e->mass_current = 0;
  memcpy(d->qpos, e->qpos, m->nq * sizeof(double));
  memcpy(d->qvel, e->qvel, m->nv * sizeof(double));
  mj_kinematics(m, d);
  mj_collision(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
  mj_subtreeVel(m, d);
  mj_rne(m, d, 0, e->bias);
  return estimate_from_passes(e);
}

#define COPY(field, count) memcpy(d->field, s->field, (size_t)(count) * sizeof(mjtNum))

/* atlas_estimate at the state of `stepped`, the simulator's own MjData after mj_step1 (of a
 * model the same but for margins and collision flags, sizes checked by the caller): its
 * position and velocity stages (mj_kinematics, mj_comPos, mj_comVel, and mj_rne's bias
 * forces: the same functions on the same numbers) copied into the scratch data instead of
 * computed again; only the soles' collision within their wider margin and the subtree
 * velocity, which mj_step1 does not compute, run here. The step's mass matrix (mj_makeM's,
 * mj_crb's numbers on a robot without tendons) is copied too, for Walk's legs
 * (mass_current). `stepped` is read, never written. */
long atlas_estimate_stepped(AtlasEstimator *e, const mjData *s) {
  const mjModel *m = e->model;
  mjData *d = e->data;
  long nbody = m->nbody, nv = m->nv;
  COPY(qpos, m->nq);
  COPY(qvel, nv);
  COPY(xpos, 3 * nbody);
  COPY(xquat, 4 * nbody);
  COPY(xmat, 9 * nbody);
  COPY(xipos, 3 * nbody);
  COPY(ximat, 9 * nbody);
  COPY(xanchor, 3 * m->njnt);
  COPY(xaxis, 3 * m->njnt);
  COPY(geom_xpos, 3 * m->ngeom);
  COPY(geom_xmat, 9 * m->ngeom);
  COPY(site_xpos, 3 * m->nsite);
  COPY(site_xmat, 9 * m->nsite);
  COPY(subtree_com, 3 * nbody);
  COPY(cinert, 10 * nbody);
  COPY(cdof, 6 * nv);
  COPY(cvel, 6 * nbody);
  COPY(cdof_dot, 6 * nv);
  COPY(M, m->nC);
  e->mass_current = 1;
  memcpy(e->bias, s->qfrc_bias, (size_t)nv * sizeof(mjtNum));
  mj_collision(m, d);
  mj_subtreeVel(m, d);
  return estimate_from_passes(e);
}
