/* Integer hashing for sample jitter, stochastic opacity and sample ids.
 * The same inputs give the same bits on every device, which keeps renders
 * bit-identical run to run. Mixer: the "lowbias32" finaliser (Wellons 2018). */
#ifndef MP_HASH_H
#define MP_HASH_H

#include "core/mp_compat.h"

MP_INLINE uint mp_hash32(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

MP_INLINE uint mp_hash_combine(uint seed, uint v) { return mp_hash32(seed ^ (v + 0x9e3779b9u + (seed << 6) + (seed >> 2))); }

/* Uniform float in [0, 1) from the top 24 bits. */
MP_INLINE float mp_hash_unit(uint h) { return (float)(h >> 8) * (1.0f / 16777216.0f); }

#endif
