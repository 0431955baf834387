/* The world's glossy maps (closures/mp_world.h), prefiltered on the device
 * from the world map's mips whenever the world changes: about 1.6 million
 * lobe samples, which took the host a third of a second per world. */
#include "core/mp_compat.h"
#include "closures/mp_world.h"

/* One texel of the glossy levels a work-item, in their layout (levels one
 * after another, mp_world_glossy_offset). `mips` holds the map of
 * width x height texels and its halvings (mp_world_mip_count). */
__kernel void prefilter_world_glossy(__global const float4* mips, int width, int height, __global float4* out) {
  int i = (int)get_global_id(0);
  if (i >= mp_world_glossy_offset(MP_WORLD_GLOSSY_LEVELS)) return;
  int k = 0;
  while (k + 1 < MP_WORLD_GLOSSY_LEVELS && i >= mp_world_glossy_offset(k + 1)) ++k;
  int w = mp_world_glossy_width(k), j = i - mp_world_glossy_offset(k);
  float3 c = mp_world_glossy_texel(mips, width, height, k, j % w, j / w);
  out[i] = (float4)(c, 1.0f);
}
