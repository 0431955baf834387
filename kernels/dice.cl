/* Dice: evaluate each diceable sub-patch on a (nu+1) x (nv+1) grid of
 * vertices (mp_grid_uv: edge vertices shared with the neighbours, bilinear
 * inside), with smooth normals from the surface derivatives. Grids live in
 * fixed-size slots of (max_grid+1)^2 vertices. */
#include "mp_compat.h"
#include "mp_patch.h"
#include "mp_types.h"
#include "mp_patch_eval.h"
#include "mp_surface.h"

__kernel void dice_grids(__global const SubPatch* diceable, uint count,
                         __global const float4* points, __global const uint* patch_info,
                         __global const uint* edges, __global const float4* curves,
                         __global const DeviceMaterial* materials, FrameParams f, __global float4* grid_p,
                         __global float4* grid_n,
                         volatile __global uint* micropolygon_count) {
  uint gid = get_global_id(0), i, j;
  SubPatch sp;
  if (!mp_grid_vertex(gid, count, f.max_grid, diceable, &sp, &i, &j)) return;
  uint nu = MP_INFO_NU(sp.info), nv = MP_INFO_NV(sp.info);
  if (i == 0u && j == 0u) atomic_add(micropolygon_count, nu * nv);
  float2 uv = mp_grid_uv(&sp, nu, nv, i, j);
  float3 p, dpdu, dpdv;
  mp_surface_point(points, patch_info, edges, curves, sp.patch, uv.x, uv.y, &p, &dpdu, &dpdv);
  uint flags = patch_info[4 * (ulong)sp.patch + 2];
  /* Displaced materials move shared edge vertices along the edge's own normal
   * (watertight); others shade with the patch's normal, which keeps polygon
   * faces flat. */
  float3 n = materials[patch_info[4 * (ulong)sp.patch + 1]].program[1] > 0.0f
                 ? mp_surface_normal(points, patch_info, edges, curves, sp.patch, uv.x, uv.y, dpdu, dpdv)
                 : mp_patch_normal(points + (ulong)sp.patch * MP_PATCH_POINTS, patch_info[4 * (ulong)sp.patch], uv.x,
                                   uv.y, dpdu, dpdv);
  if (flags & MP_PATCH_FLIP_ORIENTATION) n = -n;
  grid_p[gid] = (float4)(p, 1.0f);
  grid_n[gid] = (float4)(n, 0.0f);
}

/* Normals of displaced grids, from the displaced vertices (central
 * differences inside the grid, one-sided on its border), oriented like the
 * surface normal they replace. Where the differences vanish (a collapsed
 * grid edge) the undisplaced normal stays. Runs after every material's
 * displacement (material_program.cl). */
__kernel void displaced_normals(__global const SubPatch* diceable, uint count, __global const uint* patch_info,
                                __global const DeviceMaterial* materials, FrameParams f,
                                __global const float4* grid_p, __global float4* grid_n) {
  uint gid = get_global_id(0), i, j;
  SubPatch sp;
  if (!mp_grid_vertex(gid, count, f.max_grid, diceable, &sp, &i, &j)) return;
  if (!(materials[patch_info[4 * (ulong)sp.patch + 1]].program[1] > 0.0f)) return;
  uint nu = MP_INFO_NU(sp.info), nv = MP_INFO_NV(sp.info), stride = (uint)f.max_grid + 1u;
  ulong row = gid - i - (ulong)j * stride; /* vertex (0, 0) of this grid */
  uint i0 = i > 0u ? i - 1u : 0u, i1 = i < nu ? i + 1u : nu;
  uint j0 = j > 0u ? j - 1u : 0u, j1 = j < nv ? j + 1u : nv;
  float3 du = grid_p[row + j * stride + i1].xyz - grid_p[row + j * stride + i0].xyz;
  float3 dv = grid_p[row + j1 * stride + i].xyz - grid_p[row + j0 * stride + i].xyz;
  float3 n = cross(du, dv);
  float len = length(n);
  float3 old = grid_n[gid].xyz;
  if (!(len > 1e-12f * dot(du, du) + 1e-30f)) return;
  n /= len;
  grid_n[gid] = (float4)(dot(n, old) < 0.0f ? -n : n, 0.0f);
}
