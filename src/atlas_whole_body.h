/*
 * The whole-body layer's call (src/atlas_whole_body.c), shared with Walk's single-support
 * tick (src/atlas_legs.c), which has it solve at the stance sole's pressure centre.
 */
#ifndef TAC_ATLAS_WHOLE_BODY_H
#define TAC_ATLAS_WHOLE_BODY_H

#include "atlas_statics.h"

/* Where the compiled estimate's row holds the state's fields the tick reads (the row's layout
 * is balance/compiled_estimator.py's, whose offsets compiled_whole_body.py writes here). */
enum { WB_ROW_COM = 0, WB_ROW_COM_VELOCITY, WB_ROW_PELVIS_ROTATION, WB_ROW_PELVIS_ANGULAR,
       WB_ROW_SOLE_CENTRES, WB_ROW_SOLE_ROTATIONS, WB_ROW_OMEGA, WB_ROW_CAPTURE, WB_ROW_BIAS,
       WB_ROW_JACOBIANS, WB_ROW_FIELDS };

/* Laid out once by balance/compiled_whole_body.py, mirrored in native.py (same fields, same
 * order; tac_sizeof_AtlasWholeBody lets the loader check). */
typedef struct {
  AtlasStatics *statics;      /* its input holds com, sole centres and rotations, bias and
                               * jacobians; the force and moment are written here */
  const double *in;           /* per tick: WB_IN_* then joint positions (n), velocities (n) */
  const double *reference;    /* WB_REF_* then posture (n) and its rate (n) */
  const double *gains;        /* WB_GAIN_* */
  const double *joint_gains;  /* kp (n), kd (n) */
  const double *effort_limit; /* (n,) N m */
  const double *region;       /* (region_count, 5): vertex x, y; then the inward normal x, y and
                               * offset of its edge to the next vertex */
  double *out;                /* WB_OUT_*: the pressure centre, the tasks' force and moment */
  long region_count;          /* 0: no region (the law's pressure centre kept); 1: a point */
  const double *row;          /* NULL: the state's fields were copied into `in` and the
                               * statics' input; else the estimate's row, read at row_at */
  long row_at[WB_ROW_FIELDS]; /* each field's offset in the row (doubles) */
  const double *joint_qpos;   /* NULL: the joints copied into `in` by the caller; else, with a */
  const double *joint_qvel;   /* row, the estimate's scratch qpos and qvel (the row's state), */
  const long *qpos_adr;       /* its joints read at these qpos and dof addresses (tutorial */
  const long *dof_adr;        /* order) into `in` by the call itself */
} AtlasWholeBody;

enum { WB_IN_COP = 0, WB_IN_CAPTURE = 2, WB_IN_OMEGA = 4, WB_IN_COM_VELOCITY = 5,
       WB_IN_PELVIS_ROTATION = 8, WB_IN_PELVIS_ANGULAR = 17, WB_IN_JOINTS = 20 };
enum { WB_REF_CAPTURE = 0, WB_REF_HEIGHT = 2, WB_REF_HEIGHT_RATE = 3, WB_REF_ROTATION = 4,
       WB_REF_ANGULAR = 13, WB_REF_POSTURE = 16 };
enum { WB_GAIN_MASS = 0, WB_GAIN_CAPTURE, WB_GAIN_HEIGHT_KP, WB_GAIN_HEIGHT_KD,
       WB_GAIN_ORIENTATION_KP, WB_GAIN_ORIENTATION_KD, WB_GAIN_GRAVITY };
enum { WB_OUT_COP = 0, WB_OUT_FORCE = 2, WB_OUT_MOMENT = 5 };

/* support.Region.clamp over `count` region rows (vertex x, y, then the inward normal x, y
 * and offset of its edge to the next vertex; 0 rows: `p` kept, 1 or 2: the first vertex):
 * `p` if inside, else the region's nearest point. */
void atlas_clamp_into_rows(const double *region, long count, double p[2]);
void atlas_whole_body(const AtlasWholeBody *w);
void atlas_stand_tick(const AtlasWholeBody *w);

#endif
