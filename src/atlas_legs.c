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
 * (test/unit/walking/test_compiled_legs.py holds them to 1e-9).
 */
#include <stddef.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "atlas_swing.h"
#include "atlas_whole_body.h"

/* Laid out once by walking/compiled_legs.py, mirrored in native.py (same fields, same
 * order; tac_sizeof_AtlasLegs lets the loader check). */
typedef struct {
  const AtlasWholeBody *whole_body; /* loaded for this tick, its row set: the stance sole's
                                     * contacts, the legs' reference and joint gains, the
                                     * joints; its pressure centre is the law's, unclamped */
  const AtlasSwing *swing;          /* its path's numbers in its input; the rest filled here */
  const mjModel *model;             /* the estimator's model and the scratch data the */
  mjData *data;                     /* estimate ran in: the mass matrix of its state */
  double *mass_matrix;              /* (nv, nv) scratch */
  double *out;                      /* LEGS_OUT_*: the torques (n), the pressure centre */
  double reach[2];                  /* the stance sole's reach along and across it (m) */
  long stance;                      /* the stance foot: 0 left, 1 right */
  long leg_start;                   /* the swing leg's first joint (tutorial order) */
  long leg_dofs[LEG];               /* the swing leg's dof addresses in qvel */
  long sole_velocities_at;          /* where the row holds the soles' velocities (2, 6) */
} AtlasLegs;

size_t tac_sizeof_AtlasLegs(void) { return sizeof(AtlasLegs); }

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

/* CompiledSwing._load from the row: the swing sole's jacobian (its leg's columns), pose and
 * velocity, the leg's joint rates, and its inertia block (mj_crb, mj_fullM). */
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
  mj_crb(legs->model, legs->data);
  mj_fullM(legs->model, legs->data, legs->mass_matrix);
  long nv = legs->model->nv;
  for (int i = 0; i < LEG; ++i)
    for (int j = 0; j < LEG; ++j)
      in[IN_INERTIA + LEG * i + j] = legs->mass_matrix[nv * legs->leg_dofs[i] + legs->leg_dofs[j]];
}

/* LegTasks.torque then LegTasks.finish, one foot swinging. */
void atlas_legs_swing_tick(const AtlasLegs *legs) {
  const AtlasWholeBody *w = legs->whole_body;
  const double *row = w->row;
  long n = w->statics->n, stance = legs->stance;
  double *cop = (double *)w->in + WB_IN_COP;
  clamp_to_sole(legs, row + w->row_at[WB_ROW_SOLE_CENTRES] + 3 * stance,
                row + w->row_at[WB_ROW_SOLE_ROTATIONS] + 9 * stance, cop);
  atlas_whole_body(w);
  load_swing(legs);
  atlas_swing_torque(legs->swing);
  double *torque = legs->out;
  memcpy(torque, w->statics->torque, (size_t)n * sizeof(double));
  for (long j = 0; j < LEG; ++j)
    torque[legs->leg_start + j] = torque[legs->leg_start + j] + legs->swing->torque[j];
  const double *limit = w->effort_limit;
  for (long j = 0; j < n; ++j) { /* WholeBodyLayer.limit: np.maximum then np.minimum */
    double low = -limit[j], raised = low > torque[j] ? low : torque[j];
    torque[j] = limit[j] < raised ? limit[j] : raised;
  }
  torque[n] = cop[0];
  torque[n + 1] = cop[1];
}
