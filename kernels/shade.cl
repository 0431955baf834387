/* Shade every diced grid vertex (Reyes shades before sampling, so the
 * rasteriser only interpolates colors). */
#include "mp_compat.h"
#include "mp_patch.h"
#include "mp_types.h"
#include "mp_shading.h"

__kernel void shade_grids(__global const SubPatch* diceable, uint count, __global const uint* patch_info,
                          FrameParams f, __global const float4* grid_p, __global const float4* grid_n,
                          __global const DeviceMaterial* materials, __global const DeviceLight* lights,
                          uint light_count, __global float4* grid_c) {
  uint stride = (uint)f.max_grid + 1u;
  uint slot_size = stride * stride;
  uint gid = get_global_id(0);
  uint slot = gid / slot_size;
  if (slot >= count) return;
  uint local_index = gid - slot * slot_size;
  SubPatch sp = diceable[slot];
  if (local_index % stride > MP_INFO_NU(sp.info) || local_index / stride > MP_INFO_NV(sp.info)) return;
  __global const DeviceMaterial* m = materials + patch_info[4 * (ulong)sp.patch + 1];
  float3 c = mp_shade(grid_p[gid].xyz, grid_n[gid].xyz, f.ortho, m, lights, light_count);
  grid_c[gid] = (float4)(c, m->opacity[3]);
}
