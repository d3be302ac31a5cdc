/*
 * Where the head laser's rays first meet a heightfield: sensors/heightfield_march.py's
 * Heightfield.distances as one call, bit for bit its numpy (the same operations in the same
 * order, compiled with -ffp-contract=off): the rays marched in steps of `step_m` over the
 * heights, bilinear between the vertices; a segment of `segment_steps` steps whose lower end
 * is above the highest vertex of the tiles around its start skipped, as there; the first step
 * under the surface bisected, every ray together until the widest bracket is within `tol_m`.
 */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>

/* Mirrored in native.py (same fields, same order; tac_sizeof_AtlasHeightfield). */
typedef struct {
  const double *heights;      /* rows x cols, row 0 at -y, column 0 at -x (world z) */
  const double *tile_highest; /* tile_rows x tile_cols: highest vertex around each tile */
  long rows, cols, tile_rows, tile_cols, tile_cells, segment_steps;
  double centre_x, centre_y, half_x, half_y, lowest, highest, step_m, tol_m;
} AtlasHeightfield;

size_t tac_sizeof_AtlasHeightfield(void) { return sizeof(AtlasHeightfield); }

static double grid_col(const AtlasHeightfield *f, double x) {
  return (x - f->centre_x + f->half_x) / (2.0 * f->half_x) * (double)(f->cols - 1);
}

static double grid_row(const AtlasHeightfield *f, double y) {
  return (y - f->centre_y + f->half_y) / (2.0 * f->half_y) * (double)(f->rows - 1);
}

/* Heightfield.height_m: bilinear; -inf outside. */
static double surface_m(const AtlasHeightfield *f, double x, double y) {
  double col = grid_col(f, x), row = grid_row(f, y);
  if (!(col >= 0.0 && col <= (double)(f->cols - 1) && row >= 0.0 && row <= (double)(f->rows - 1)))
    return -INFINITY;
  long c0 = (long)col, r0 = (long)row;
  if (c0 > f->cols - 2) c0 = f->cols - 2;
  if (r0 > f->rows - 2) r0 = f->rows - 2;
  double fc = col - (double)c0, fr = row - (double)r0;
  const double *h0 = f->heights + r0 * f->cols + c0, *h1 = h0 + f->cols;
  return (h0[0] * (1.0 - fc) + h0[1] * fc) * (1.0 - fr) + (h1[0] * (1.0 - fc) + h1[1] * fc) * fr;
}

static long tile_index(double grid, long tile_cells, long tiles) {
  double tile = floor(grid / (double)tile_cells);
  if (tile < 0.0) tile = 0.0;
  if (tile > (double)(tiles - 1)) tile = (double)(tiles - 1);
  return (long)tile;
}

/* Heightfield.tile_highest_m. */
static double tile_highest_m(const AtlasHeightfield *f, double x, double y) {
  long col = tile_index(grid_col(f, x), f->tile_cells, f->tile_cols);
  long row = tile_index(grid_row(f, y), f->tile_cells, f->tile_rows);
  return f->tile_highest[row * f->tile_cols + col];
}

/* numpy's arange(start, stop, step): start, start + step, then start + i * ((start + step) -
 * start) (numpy's fill). */
static double step_at(double start, double step, long i) {
  if (i < 2) return i == 0 ? start : start + step;
  return start + (double)i * ((start + step) - start);
}

/* Heightfield._first_steps_under for one ray: its first step at or under the surface within
 * reach (plus a step), -1 where none is. */
static long first_step_under(const AtlasHeightfield *f, const double *o, const double *r,
                             double reach, const double *steps, long n) {
  long per = f->segment_steps, segments = (n + per - 1) / per;
  double limit = reach + f->step_m;
  for (long s = 0; s < segments; ++s) {
    double start = s == 0 ? 0.0 : steps[s * per - 1];
    long end = s * per + per - 1 < n - 1 ? s * per + per - 1 : n - 1;
    double sx = o[0] + start * r[0], sy = o[1] + start * r[1], sz = o[2] + start * r[2];
    double end_z = o[2] + steps[end] * r[2];
    double lowest = sz < end_z ? sz : end_z;
    if (!(lowest <= tile_highest_m(f, sx, sy) && start <= limit)) continue;
    for (long i = s * per; i < s * per + per && i < n; ++i) {
      double at = steps[i];
      double px = o[0] + at * r[0], py = o[1] + at * r[1], pz = o[2] + at * r[2];
      if (pz <= surface_m(f, px, py) && at <= limit) return i;
    }
  }
  return -1;
}

/* Heightfield.crossing_m over the rays `met` (count), brackets near/far, in place. */
static void bisect(const AtlasHeightfield *f, const double *o, const double *rays,
                   const long *met, long count, double *near, double *far) {
  for (;;) {
    double widest = -INFINITY;
    for (long k = 0; k < count; ++k)
      if (far[k] - near[k] > widest) widest = far[k] - near[k];
    if (count == 0 || !(widest > f->tol_m)) return;
    for (long k = 0; k < count; ++k) {
      const double *r = rays + 3 * met[k];
      double middle = 0.5 * (near[k] + far[k]);
      double ax = o[0] + middle * r[0], ay = o[1] + middle * r[1], az = o[2] + middle * r[2];
      if (az <= surface_m(f, ax, ay))
        far[k] = middle;
      else
        near[k] = middle;
    }
  }
}

/* Heightfield.distances: each ray's distance (m) to where it first goes below the surface
 * within range_m into out (n), -1 where it does not (0 for every ray from under the
 * surface). Returns 0, or -1 when memory ran out (out then untouched). */
long atlas_heightfield_distances(const AtlasHeightfield *f, const double *o, const double *rays,
                                 long n, double range_m, double *out) {
  if (surface_m(f, o[0], o[1]) >= o[2]) {
    for (long k = 0; k < n; ++k) out[k] = 0.0;
    return 0;
  }
  double *reach = malloc(sizeof(double) * (size_t)(3 * n + 1));
  long *met = malloc(sizeof(long) * (size_t)(n + 1));
  if (reach == NULL || met == NULL) {
    free(reach);
    free(met);
    return -1;
  }
  double *near = reach + n, *far = near + n, farthest = -INFINITY;
  long live = 0;
  for (long k = 0; k < n; ++k) {
    out[k] = -1.0;
    double rz = rays[3 * k + 2], limit = range_m;
    if (rz < 0.0) {
      double down = (o[2] - f->lowest) / -rz;
      limit = limit < down ? limit : down;
    } else if (o[2] > f->highest) {
      limit = 0.0;
    }
    reach[k] = limit;
    if (limit > 0.0) {
      ++live;
      if (limit > farthest) farthest = limit;
    }
  }
  if (live == 0) {
    free(reach);
    free(met);
    return 0;
  }
  double start = f->step_m;
  long count = (long)ceil((farthest + f->step_m - start) / f->step_m);
  double *steps = malloc(sizeof(double) * (size_t)(count > 0 ? count : 1));
  if (steps == NULL) {
    free(reach);
    free(met);
    return -1;
  }
  for (long i = 0; i < count; ++i) steps[i] = step_at(start, f->step_m, i);
  long hits = 0;
  for (long k = 0; k < n; ++k) {
    if (!(reach[k] > 0.0)) continue;
    long first = first_step_under(f, o, rays + 3 * k, reach[k], steps, count);
    if (first < 0) continue;
    met[hits] = k;
    near[hits] = first > 0 ? steps[first - 1] : 0.0;
    far[hits] = steps[first];
    ++hits;
  }
  bisect(f, o, rays, met, hits, near, far);
  for (long k = 0; k < hits; ++k) {
    double distance = 0.5 * (near[k] + far[k]);
    if (distance <= range_m) out[met[k]] = distance;
  }
  free(steps);
  free(reach);
  free(met);
  return 0;
}
