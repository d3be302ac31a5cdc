/*
 * DRCSim 2.5.2's joint controller law for all joints in one call: the compiled twin of
 * compute_torque() in src/tutorial_atlas_control/sim/controller.py (whose docstring gives the
 * law). Called once per step through ctypes (sim/law_kernel.py) instead of many numpy calls.
 *
 * It must give the numpy law's results bit for bit (offline replay depends on it), so:
 * every operation is the numpy code's, in the same order, in double precision; the build
 * forbids contracting a*b+c into an FMA (-ffp-contract=off, see CMakeLists.txt) and uses
 * no -ffast-math; min/max are numpy's (see np_minimum).
 */
#include <math.h>
#include <stddef.h>

/* Gazebo's math::equal tolerance (controller.TIE_BACK_EPSILON). */
#define TIE_BACK_EPSILON 1e-6

/* The fields of osrf_msgs/JointCommands, in message order, then AtlasCommand's k_effort as
 * a fraction (command/arrays.py's LAW_FIELDS). */
enum {
  POSITION, VELOCITY, EFFORT, KP_POSITION, KI_POSITION, KD_POSITION, KP_VELOCITY,
  I_EFFORT_MIN, I_EFFORT_MAX, K_EFFORT, NUM_FIELDS
};

/* Everything one step reads and writes; laid out once by law_kernel.py, mirrored in native.py
 * (same fields, same order; tac_sizeof_AtlasLawStep lets the loader check). */
typedef struct {
  const double *command[NUM_FIELDS]; /* (n,) each, joint order */
  const double *qpos;                /* MjData.qpos */
  const ptrdiff_t *qpos_adr;         /* (n,) qpos index of each joint */
  const double *qvel;                /* MjData.qvel */
  const ptrdiff_t *dof_adr;          /* (n,) qvel index of each joint */
  const double *lower;               /* (n,) position limits (rad) */
  const double *upper;
  const double *effort_limit;        /* (n,) |torque| bound (N m) */
  double *integral;                  /* (n,) PidState.integral (N m), updated */
  double *previous_error;            /* (n,) PidState.previous_error (rad), updated */
  double *torque;                    /* (n,) result (N m) */
  double *ctrl;                      /* (n,) MjData.ctrl, also set to the result; or NULL */
  const double *f_out;               /* (n,) torque blended in by 1 - k_effort; NULL: 0 */
  double dt_s;
  long n;
  long initialized;                  /* PidState.initialized; set to 1 */
  long nq, nv;                       /* lengths of qpos and qvel (atlas_state_is_finite) */
  const int *warnings;               /* MjData.warning's number fields, every warning_stride-th
                                      * int (atlas_step_unsound; NULL: not set) */
  long warning_stride;
  long warning_count;                /* how many of warning_which it tests, in order */
  long warning_which[4];
} AtlasLawStep;

/* numpy.minimum / numpy.maximum for one pair: a NaN wins, and of two equal values (0.0 and
 * -0.0) the second is returned, like the SIMD minpd/maxpd numpy's loops use. */
static inline double np_minimum(double a, double b) { return (isnan(a) || a < b) ? a : b; }
static inline double np_maximum(double a, double b) { return (isnan(a) || a > b) ? a : b; }

/* Gazebo's math::clamp as controller._clamp computes it: max(min(value, high), low). */
static inline double clamp(double value, double low, double high) {
  return np_maximum(np_minimum(value, high), low);
}

void atlas_law_step(AtlasLawStep *s) {
  const double *const *c = s->command;
  const double dt_s = s->dt_s;
  const int initialized = s->initialized != 0;
  for (long j = 0; j < s->n; ++j) {
    const double error = clamp(c[POSITION][j], s->lower[j], s->upper[j]) - s->qpos[s->qpos_adr[j]];
    const double previous = initialized ? s->previous_error[j] : error;
    const double ki = c[KI_POSITION][j];

    double integral = s->integral[j] + (ki * dt_s) * error;
    integral = clamp(integral, c[I_EFFORT_MIN][j], c[I_EFFORT_MAX][j]);

    double u = c[KP_POSITION][j] * error;
    u += integral;
    u += ((error - previous) / dt_s) * c[KD_POSITION][j];
    u += c[VELOCITY][j] * c[KP_VELOCITY][j]; /* its damping is the joint's (2.7) */
    u += c[EFFORT][j];
    s->previous_error[j] = error;

    /* AtlasCommand's k_effort: 2.5.2's k * u + (1 - k) * f_out, skipped at k = 1 */
    const double k_effort = c[K_EFFORT][j];
    if (k_effort != 1.0) {
      const double f_out = s->f_out != NULL ? s->f_out[j] : 0.0;
      u = k_effort * u + (1.0 - k_effort) * f_out;
    }

    const double limit = s->effort_limit[j];
    const double torque = clamp(u, -limit, limit);

    /* tie-back: while saturated, pull the integral back by the torque that was cut off */
    if (fabs(torque - u) > TIE_BACK_EPSILON && fabs(ki) > TIE_BACK_EPSILON) {
      integral = clamp((torque - u) + integral, c[I_EFFORT_MIN][j], c[I_EFFORT_MAX][j]);
    }
    s->integral[j] = integral;
    s->torque[j] = torque;
    if (s->ctrl != NULL) s->ctrl[j] = torque;
  }
  s->initialized = 1;
}

/* sizeof(AtlasLawStep), for native.py's check of its ctypes mirror. */
size_t tac_sizeof_AtlasLawStep(void) { return sizeof(AtlasLawStep); }

/* 1 if every qpos and qvel is finite, else 0: the simulator's divergence check after each
 * step, in one call instead of four numpy ones. */
int atlas_state_is_finite(const AtlasLawStep *s) {
  for (long i = 0; i < s->nq; ++i) {
    if (!isfinite(s->qpos[i])) return 0;
  }
  for (long i = 0; i < s->nv; ++i) {
    if (!isfinite(s->qvel[i])) return 0;
  }
  return 1;
}

/* The simulator's divergence check after each step in one call (sim/divergence.py's, in its
 * order): MuJoCo's warning counters at each of warning_which, then every qpos and qvel finite.
 * 0: sound; 1 + the index in warning_which of the first counter above 0; warning_count + 1:
 * a value not finite. */
long atlas_step_unsound(const AtlasLawStep *s) {
  for (long k = 0; k < s->warning_count; ++k) {
    if (s->warnings[s->warning_stride * s->warning_which[k]] > 0) return k + 1;
  }
  return atlas_state_is_finite(s) ? 0 : s->warning_count + 1;
}

/* A behaviour's torque within the effort limits (JointLaw.apply_behaviour with no command
 * blended): f_out, the behaviour's torque copied in, clamped in place as numpy's maximum
 * with -limit then minimum with limit, and written to torque and ctrl. One call for the
 * two ufuncs and two copies a step. */
void atlas_behaviour_torque(const AtlasLawStep *s) {
  double *f_out = (double *)s->f_out;
  for (long j = 0; j < s->n; ++j) {
    const double limit = s->effort_limit[j];
    const double torque = np_minimum(np_maximum(f_out[j], -limit), limit);
    f_out[j] = torque;
    s->torque[j] = torque;
    if (s->ctrl != NULL) s->ctrl[j] = torque;
  }
}
