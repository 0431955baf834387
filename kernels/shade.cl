/* Shade every diced grid vertex (Reyes shades before sampling, so the
 * rasteriser only interpolates colors). */
#include "mp_compat.h"
#include "mp_patch.h"
#include "mp_types.h"
#include "mp_shading.h"
#include "mp_grid.h"

__kernel void shade_grids(__global const SubPatch* diceable, uint count, __global const uint* patch_info,
                          FrameParams f, __global const float4* grid_p, __global const float4* grid_n,
                          __global const DeviceMaterial* materials, __global const DeviceLight* lights,
                          uint light_count, __global float4* grid_c, __global const uint* vertex_offsets) {
  uint gid = get_global_id(0), i, j;
  SubPatch sp;
  float2 uv;
  ulong index;
  if (!mp_grid_vertex(gid, count, vertex_offsets, f.max_grid, diceable, &sp, &i, &j, &uv, &index)) return;
  DeviceMaterial m = materials[patch_info[4 * (ulong)sp.patch + 1]];
  if (m.program[2] > 0.0f) return; /* shaded by its node program (material_program.cl) */
  float3 c = mp_shade(grid_p[index].xyz, grid_n[index].xyz, f.ortho, &m, lights, light_count);
  grid_c[index] = (float4)(c, m.opacity[3]);
}
