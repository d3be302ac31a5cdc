/*
 * The inverse statics' call (src/atlas_statics.c), shared with the whole-body tick
 * (src/atlas_whole_body.c), which fills the same input and calls it.
 */
#ifndef TAC_ATLAS_STATICS_H
#define TAC_ATLAS_STATICS_H

/* Laid out once by balance/compiled_statics.py, mirrored in native.py (same fields, same
 * order; tac_sizeof_AtlasStatics lets the loader check). */
typedef struct {
  const double *in;    /* force (3), moment (3) about the CoM, com (3), sole centres (2, 3),
                        * sole rotations (2, 3, 3), bias (n), sole jacobians (2, 6, n) */
  const double *feet;  /* (2, FOOT): carries (0/1), half length, half width (m), torsion (m;
                        * NaN: none), friction (NaN: none), the region's centre along and
                        * across the sole (m, sole frame; 0, 0: the sole's own) */
  double *wrenches;    /* (2, 6) out: [f, m] per sole, feasible */
  double *torque;      /* (n,) out: bias - J^T w (N m) */
  double min_load_share;
  long n;
} AtlasStatics;

enum { IN_FORCE = 0, IN_MOMENT = 3, IN_COM = 6, IN_CENTRES = 9, IN_ROTATIONS = 15, IN_BIAS = 33 };
enum { CARRIES = 0, HALF_LENGTH, HALF_WIDTH, TORSION, FRICTION, CENTRE_ALONG, CENTRE_ACROSS, FOOT };

void atlas_inverse_statics(const AtlasStatics *s);

#endif
