/* The occlusion pyramid (mp_occlusion.h), rebuilt from the sample buffer
 * after a batch of sub-patches has been sampled, before bound & split goes
 * on: level 0 from the samples, then each level from the one below. */
#include "core/mp_compat.h"
#include "core/mp_types.h"
#include "stages/mp_occlusion.h"

#define MP_EMPTY_KEY ((ulong)0xffffffffffffffffUL)

/* One work-item per level-0 cell: the farthest depth of its samples, and
 * (into covered[0]) how many of its pixels have a sample with a surface.
 * Only pixels in count_region ([x, z) x [y, w)) are counted. Unless `all` is set, only cells the sample stage marked in `dirty` since
 * the last build are read (the others have not changed). */
__kernel void occlusion_base(__global const ulong* keys, FrameParams f, OcclusionParams o, __global uint* pyramid,
                             __global uchar* dirty, int all, volatile __global uint* covered, int4 count_region) {
  int cx = get_global_id(0), cy = get_global_id(1);
  if (cx >= o.base_w || cy >= o.base_h) return;
  if (!all) {
    if (!dirty[cy * o.base_w + cx]) return;
    dirty[cy * o.base_w + cx] = (uchar)0;
  }
  int spp = f.spp_x * f.spp_y, n = 1 << o.cell_shift;
  uint far_bits = 0u, count = 0u;
  for (int py = cy * n; py < min(cy * n + n, f.height); ++py)
    for (int px = cx * n; px < min(cx * n + n, f.width); ++px) {
      __global const ulong* k = keys + ((ulong)py * (ulong)f.width + (ulong)px) * (ulong)spp;
      uint any = 0u;
      for (int s = 0; s < spp; ++s) {
        ulong key = k[s];
        far_bits = max(far_bits, key == MP_EMPTY_KEY ? 0xffffffffu : (uint)(key >> 32));
        any |= key != MP_EMPTY_KEY;
      }
      count += any && px >= count_region.x && px < count_region.z && py >= count_region.y && py < count_region.w;
    }
  pyramid[cy * o.base_w + cx] = far_bits;
  if (count) atomic_add(covered, count);
}

/* Level `level` from level - 1: the farthest of each 2 x 2 block. */
__kernel void occlusion_reduce(__global uint* pyramid, OcclusionParams o, int level) {
  int x = get_global_id(0), y = get_global_id(1);
  int w = mp_occlusion_side(o.base_w, level), h = mp_occlusion_side(o.base_h, level);
  if (x >= w || y >= h) return;
  int pw = mp_occlusion_side(o.base_w, level - 1), ph = mp_occlusion_side(o.base_h, level - 1);
  __global const uint* src = pyramid + mp_occlusion_offset(o, level - 1);
  uint m = 0u;
  for (int dy = 0; dy < 2; ++dy)
    for (int dx = 0; dx < 2; ++dx) {
      int sx = min(2 * x + dx, pw - 1), sy = min(2 * y + dy, ph - 1);
      m = max(m, src[sy * pw + sx]);
    }
  pyramid[mp_occlusion_offset(o, level) + (uint)(y * w + x)] = m;
}
