/*
 * A walking tick with a foot swinging, in one call: the compiled twin of what
 * WalkController.tick_torque does between its phase logic and its output
 * (src/tutorial_atlas_control/walking/walk.py, whose docstrings give the rules): the legs'
 * reference turned and lowered by its timed moves (LegTasks._moved_reference), the capture
 * point's reference from the step's plan (DcmPlan.reference), the swing foot's landing moved
 * by the capture point's predicted error (step_adjustment.foothold_shift, then
 * step_queue.clamp_pose, kept unless it moves by the tolerance: _adjust), the law's pressure
 * centre (lipm.dcm_feedback_cop), then the legs' single-support tick (atlas_legs_swing_tick)
 * at it. In Python these were some hundred operations on floats a tick; the Python glue
 * makes the new Footstep and SwingPath only when the landing moved (walking/compiled_walk_swing.py).
 * The same operations in the same order as the Python: the torques agree with it bit for bit
 * (test/unit/walking/test_compiled_walk_swing.py).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "atlas_legs.h"

/* Laid out once a step by walking/compiled_walk_swing.py, mirrored in native.py (same
 * fields, same order; tac_sizeof_AtlasWalkSwing lets the loader check). */
typedef struct {
  AtlasLegs *legs;        /* its whole body loaded for this tick (row set), its path set;
                           * with rule_in_call its near_m and bearing set here */
  double *out;            /* WALK_OUT_*: the capture point's reference, moved?, the landing */
  double plan[5];         /* the step's plan: pressure centre x, y; end x, y; duration (s) */
  double plan_omega;      /* the omega the plan was made with (1/s) */
  double next_duration_s; /* the step after this one (s), when has_next */
  long has_next;          /* 0: the walk catches itself after this step */
  double step_duration_s; /* the step's duration (s) */
  double dcm_gain;        /* k of p = p_ref + (1 + k)(xi - xi_ref) */
  double tolerance_m;     /* the least change that moves the landing (m) */
  double planned[3];      /* the step as planned: x, y, z (m) */
  double stance[3];       /* the stance foot as the queue holds it: x, y (m), yaw (rad) */
  double limits[4];       /* the step limits: forward, back, least and most width (m) */
  double side;            /* the swing foot's side: +1 left, -1 right */
  double step_xy[2];      /* the landing as adjusted so far (m) */
  long adjust;            /* 0: the landing is not adjusted */
  double elapsed_s;       /* the time into the step (s) */
  double time_s;          /* the tick's time (s) */
  double height[4];       /* the CoM height's move: began (s), duration (s), from, change (m) */
  double facing[4];       /* the heading's move: began (s), duration (s), from, turn (rad) */
  long rule_in_call;      /* 1: the stance sole's rule read here from the estimate's row
                           * (sole_support.stance_rule); 0: the caller set it in legs */
  double near_cop_m;      /* the rule's distance across facets (m) */
  long bearing_at;        /* where the row holds each sole's bearing summary (5 doubles) */
} AtlasWalkSwing;

enum { WALK_OUT_XI_REF = 0, WALK_OUT_MOVED = 2, WALK_OUT_STEP = 3, WALK_OUT_SIZE = 5 };

size_t tac_sizeof_AtlasWalkSwing(void) { return sizeof(AtlasWalkSwing); }

/* Python's min(max(v, low), high). */
static double clamp(double v, double low, double high) {
  double raised = low > v ? low : v;
  return high < raised ? high : raised;
}

/* step_adjustment.predicted_error. */
static double predicted_error(double error, double reach_m, double gain, double omega,
                              double remaining_s) {
  if (remaining_s <= 0.0) return error;
  double reach = 0.0 > reach_m ? 0.0 : reach_m;
  double magnitude = fabs(error), sign = copysign(1.0, error);
  double linear = reach / (1.0 + gain);
  if (magnitude <= linear) return error * exp(-gain * omega * remaining_s);
  if (magnitude < reach) {
    double back_s = log((reach - linear) / (reach - magnitude)) / omega;
    if (back_s < remaining_s) return sign * linear * exp(-gain * omega * (remaining_s - back_s));
  }
  return sign * (reach + (magnitude - reach) * exp(omega * remaining_s));
}

/* _adjust: the landing for the capture point's error, clamped to the step limits from the
 * stance foot; moved (out) when it is the tolerance or more from the landing so far. */
static void adjust(AtlasWalkSwing *w, const double *row, const long *at, const double xi_ref[2],
                   const double cop_ref[2]) {
  long stance = (long)w->legs->stance;
  const double *capture = row + at[WB_ROW_CAPTURE];
  const double *centre = row + at[WB_ROW_SOLE_CENTRES] + 3 * stance;
  const double *r = row + at[WB_ROW_SOLE_ROTATIONS] + 9 * stance;
  double omega = row[at[WB_ROW_OMEGA]], gain = w->dcm_gain;
  double c = r[0], s = r[3];
  double error_x = capture[0] - xi_ref[0], error_y = capture[1] - xi_ref[1];
  double offset_x = cop_ref[0] - centre[0], offset_y = cop_ref[1] - centre[1];
  double remaining_s = w->step_duration_s - w->elapsed_s;
  double errors[2] = {c * error_x + s * error_y, c * error_y - s * error_x};
  double offsets[2] = {c * offset_x + s * offset_y, c * offset_y - s * offset_x};
  double predicted[2];
  for (int axis = 0; axis < 2; ++axis) {
    double room = w->legs->reach[axis] - (errors[axis] >= 0.0 ? offsets[axis] : -offsets[axis]);
    predicted[axis] = predicted_error(errors[axis], room, gain, omega, remaining_s);
  }
  double carried = w->has_next ? 1.0 / (1.0 - exp(-omega * w->next_duration_s)) : 1.0;
  double shift_x = carried * (c * predicted[0] - s * predicted[1]);
  double shift_y = carried * (s * predicted[0] + c * predicted[1]);
  /* step_queue.clamp_pose */
  double cs = cos(w->stance[2]), ss = sin(w->stance[2]);
  double dx = (w->planned[0] + shift_x) - w->stance[0];
  double dy = (w->planned[1] + shift_y) - w->stance[1];
  double ahead = cs * dx + ss * dy, across = -ss * dx + cs * dy;
  ahead = clamp(ahead, -w->limits[1], w->limits[0]);
  across = w->side * clamp(w->side * across, w->limits[2], w->limits[3]);
  double x = (w->stance[0] + cs * ahead) - ss * across;
  double y = (w->stance[1] + ss * ahead) + cs * across;
  double *out = w->out;
  out[WALK_OUT_MOVED] = 0.0;
  if (hypot(x - w->step_xy[0], y - w->step_xy[1]) < w->tolerance_m) return;
  w->step_xy[0] = out[WALK_OUT_STEP] = x;
  w->step_xy[1] = out[WALK_OUT_STEP + 1] = y;
  out[WALK_OUT_MOVED] = 1.0;
  double *end = w->legs->swing->in + IN_END; /* the path's end: the landing as moved */
  end[0] = x;
  end[1] = y;
  end[2] = w->planned[2];
}

/* balance.blend.smoothstep (min(max(f, 0), 1) as Python's, then the same products). */
static double smoothstep(double fraction) {
  double s = clamp(fraction, 0.0, 1.0);
  return s * s * (3.0 - 2.0 * s);
}

/* LegTasks._moved_reference then CompiledWholeBody._move_reference: the legs' heading, CoM
 * height and its rate at time_s written over the whole body's reference (upright pelvis
 * frame turned by the heading), as the Python writes them. */
static void move_reference(const AtlasWalkSwing *w, double *reference) {
  const double *h = w->height, *f = w->facing;
  double fraction = (w->time_s - h[0]) / h[1];
  double rate = (0.0 < fraction && fraction < 1.0) ? 6.0 * fraction * (1.0 - fraction) / h[1]
                                                   : 0.0;
  double yaw = f[2] + smoothstep((w->time_s - f[0]) / f[1]) * f[3];
  double c = cos(yaw), s = sin(yaw);
  double values[11] = {h[2] + smoothstep(fraction) * h[3], rate * h[3], c, -s, 0.0, s, c,
                       0.0, 0.0, 0.0, 1.0};
  memcpy(reference + WB_REF_HEIGHT, values, sizeof values);
}

/* The tick: the legs' moved reference, reference, adjustment, the law's pressure centre, the legs' swing tick. */
/* sole_support.stance_rule from the row's summary of the stance sole's contacts: across
 * facets (its first number not 0.0, NaN too, as Python's truth), near_cop_m and the box of
 * its bearing points; else 0.0 and no box (NO_SPAN: inf, -inf, inf, -inf). */
static void stance_rule(const AtlasWalkSwing *w, const double *row) {
  AtlasLegs *legs = w->legs;
  const double *summary = row + w->bearing_at + 5 * legs->stance;
  if (summary[0] != 0.0) {
    legs->near_m = w->near_cop_m;
    memcpy(legs->bearing, summary + 1, 4 * sizeof(double));
  } else {
    legs->near_m = 0.0;
    legs->bearing[0] = INFINITY, legs->bearing[1] = -INFINITY;
    legs->bearing[2] = INFINITY, legs->bearing[3] = -INFINITY;
  }
}

void atlas_walk_swing_tick(AtlasWalkSwing *w) {
  const AtlasWholeBody *body = w->legs->whole_body;
  const double *row = body->row;
  const long *at = body->row_at;
  if (w->rule_in_call) stance_rule(w, row);
  move_reference(w, (double *)body->reference);
  /* DcmPlan.reference(0, elapsed) */
  const double *plan = w->plan;
  double t = clamp(w->elapsed_s, 0.0, plan[4]);
  double growth = exp(w->plan_omega * (t - plan[4]));
  double *xi_ref = w->out + WALK_OUT_XI_REF;
  xi_ref[0] = plan[0] + (plan[2] - plan[0]) * growth;
  xi_ref[1] = plan[1] + (plan[3] - plan[1]) * growth;
  if (w->adjust) adjust(w, row, at, xi_ref, plan);
  else w->out[WALK_OUT_MOVED] = 0.0;
  /* lipm.dcm_feedback_cop, into the whole body's input (the legs clamp it to the sole) */
  const double *capture = row + at[WB_ROW_CAPTURE];
  double factor = 1.0 + w->dcm_gain;
  double *cop = (double *)body->in + WB_IN_COP;
  cop[0] = plan[0] + factor * (capture[0] - xi_ref[0]);
  cop[1] = plan[1] + factor * (capture[1] - xi_ref[1]);
  atlas_legs_swing_tick(w->legs);
}
