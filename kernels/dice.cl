/* Dice: evaluate each diceable sub-patch on a (nu+1) x (nv+1) grid of
 * vertices (mp_grid_uv: edge vertices shared with the neighbours, bilinear
 * inside), with smooth normals from the surface derivatives. Grids live in
 * fixed-size slots of (max_grid+1)^2 vertices. */
#include "mp_compat.h"
#include "mp_patch.h"
#include "mp_types.h"
#include "mp_patch_eval.h"
#include "mp_surface.h"

/* Unit normal of the patch at (u, v). Where the derivatives are parallel or
 * vanish (collapsed corners, poles) the normal is taken a little way towards
 * the patch centre, which is its limit along that direction. */
inline float3 mp_patch_normal(__global const float4* cp, uint type, float u, float v, float3 dpdu, float3 dpdv) {
  float3 n = cross(dpdu, dpdv);
  float scale = length(dpdu) * length(dpdv);
  for (int k = 0; k < 3 && !(length(n) > 1e-7f * scale && length(n) > 0.0f); ++k) {
    float t = k == 0 ? 1e-4f : k == 1 ? 1e-3f : 1e-2f;
    float3 p;
    mp_eval_patch(cp, type, u + (0.5f - u) * t, v + (0.5f - v) * t, &p, &dpdu, &dpdv);
    n = cross(dpdu, dpdv);
    scale = length(dpdu) * length(dpdv);
  }
  float len = length(n);
  return len > 0.0f ? n / len : (float3)(0.0f, 0.0f, 1.0f);
}

__kernel void dice_grids(__global const SubPatch* diceable, uint count,
                         __global const float4* points, __global const uint* patch_info,
                         __global const uint* edges, __global const float4* curves,
                         FrameParams f, __global float4* grid_p, __global float4* grid_n,
                         volatile __global uint* micropolygon_count) {
  uint gid = get_global_id(0), i, j;
  SubPatch sp;
  if (!mp_grid_vertex(gid, count, f.max_grid, diceable, &sp, &i, &j)) return;
  uint nu = MP_INFO_NU(sp.info), nv = MP_INFO_NV(sp.info);
  if (i == 0u && j == 0u) atomic_add(micropolygon_count, nu * nv);
  float2 uv = mp_grid_uv(&sp, nu, nv, i, j);
  float3 p, dpdu, dpdv;
  mp_surface_point(points, patch_info, edges, curves, sp.patch, uv.x, uv.y, &p, &dpdu, &dpdv);
  __global const float4* cp = points + (ulong)sp.patch * MP_PATCH_POINTS;
  uint type = patch_info[4 * (ulong)sp.patch];
  uint flags = patch_info[4 * (ulong)sp.patch + 2];
  float3 n = mp_patch_normal(cp, type, uv.x, uv.y, dpdu, dpdv);
  if (flags & MP_PATCH_FLIP_ORIENTATION) n = -n;
  grid_p[gid] = (float4)(p, 1.0f);
  grid_n[gid] = (float4)(n, 0.0f);
}
