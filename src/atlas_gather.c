/*
 * Indexed copies of doubles, many per call: how the simulator's messages take their numbers
 * from MjData (sim_messages.py). Through numpy each copy is a call of its own (plus a new view
 * of the MjData array); here one ctypes call does all of a message's copies.
 * Copies only: the values are bit for bit numpy's `dst[to] = src[from]`.
 */
#include <stddef.h>
#include <string.h>

/* dst[dst_index[i]] = src[src_index[i]] for i < count; laid out by sim/copy_plan.py, mirrored
 * in native.py (same fields, same order; tac_sizeof_AtlasCopy lets the loader check).
 * dst is a message's float block inside its serialized bytes, not necessarily 8-byte
 * aligned: it is written with memcpy. */
typedef struct {
  unsigned char *dst;
  const ptrdiff_t *dst_index;
  const double *src;
  const ptrdiff_t *src_index;
  long count;
} AtlasCopy;

/* sizeof(AtlasCopy), for native.py's check of its ctypes mirror. */
size_t tac_sizeof_AtlasCopy(void) { return sizeof(AtlasCopy); }

void atlas_copy_all(const AtlasCopy *copies, long n_copies) {
  for (long k = 0; k < n_copies; ++k) {
    const AtlasCopy *c = &copies[k];
    for (long i = 0; i < c->count; ++i)
      memcpy(c->dst + sizeof(double) * c->dst_index[i], &c->src[c->src_index[i]], sizeof(double));
  }
}
