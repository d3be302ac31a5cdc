/*
 * Walk's single-support tick of the legs (src/atlas_legs.c), shared with the walk's swing
 * tick (src/atlas_walk_swing.c), which sets its pressure centre first.
 */
#ifndef TAC_ATLAS_LEGS_H
#define TAC_ATLAS_LEGS_H

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
  const double *row;                /* atlas_legs_support_clamp's state: the estimate's row */
  double half_size[2];              /* a sole's half length and half width (m) */
  double margin_m;                  /* the support region's margin (m) */
  long carrying[2];                 /* which soles carry (1) */
  double near_m;                    /* > 0: the stance sole is across facets, its wrench's
                                     * pressure centre within this of the kept one or of
                                     * `bearing` (m; walking/sole_support.py); else the
                                     * whole sole */
  double bearing[4];                /* the box the stance sole bears on (sole frame, m):
                                     * along lowest, highest, across lowest, highest */
  const long *mass_current;         /* the estimator's flag: not 0 when the data's mass
                                     * matrix is its state's already (NULL: never) */
} AtlasLegs;

/* A foot's pose for a tick with both feet meant down (LegTasks.finish): the put-down servo's
 * target (x, y, its step's height less the press, yaw, the surface's tilt x, y), then what
 * the flat test reads (the surface's height, its normal). */
enum { FOOT_X = 0, FOOT_Y, FOOT_Z_PRESSED, FOOT_YAW, FOOT_TILT_X, FOOT_TILT_Y, FOOT_Z,
       FOOT_NORMAL, FOOT_SIZE = FOOT_NORMAL + 3 };

/* Laid out once by walking/compiled_legs.py, mirrored in native.py (same fields, same
 * order; tac_sizeof_AtlasLegsSupport lets the loader check). */
typedef struct {
  AtlasLegs *legs;           /* loaded for this tick: its whole body, row, carrying soles and
                              * the law's pressure centre (out); its leg set here per foot */
  long leg_starts[2];        /* each leg's first joint (tutorial order) */
  long leg_dofs[2][LEG];     /* each leg's dof addresses in qvel */
  double feet[2][FOOT_SIZE]; /* each foot's pose: FOOT_* */
  double flat_height_m;      /* a sole is flat within this height over its surface (m) */
  double flat_cos;           /* and its normal within acos(flat_cos) of the surface's */
} AtlasLegsSupport;

void atlas_legs_swing_tick(const AtlasLegs *legs);
void atlas_legs_support_clamp(const AtlasLegs *legs);

#endif
