/* Shade every diced grid vertex (Reyes shades before sampling, so the
 * rasteriser only interpolates colors). */
#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "closures/mp_shading.h"
#include "closures/mp_shade_closures.h"
#include "geometry/mp_grid.h"
#include "core/mp_scene_data.h"

__kernel void shade_grids(MP_SCENE_PARAMS __global const SubPatch* diceable, uint count, FrameParams f,
                          __global const float4* grid_p, __global float4* grid_n, __global float4* grid_c,
                          __global const uint* vertex_offsets, MP_SHADOW_INPUT_PARAMS,
                          __global const uchar* visible) {
  uint gid = get_global_id(0), i, j;
  SubPatch sp;
  float2 uv;
  ulong index;
  if (!mp_grid_vertex(gid, count, vertex_offsets, f.max_grid, diceable, &sp, &i, &j, &uv, &index)) return;
  if (mp_grid_unseen(visible, index, f.max_grid, materials, patch_info, sp.patch)) return;
  DeviceMaterial m = materials[patch_info[4 * (ulong)sp.patch + 1]];
  float3 p = grid_p[index].xyz, n = grid_n[index].xyz;
  /* Shadows compare with the surface's own tangent plane (mp_shadow.h). */
  MpShadowMaps maps = MP_SHADOW_INPUTS;
  MpShadowQuery shadow = {&maps, n, mp_pixel_footprint(-p.z, f),
                          patch_info[4 * (ulong)sp.patch] == MP_PATCH_CURVE};
  /* Smooth-shaded polygons: their interpolated normal replaces the surface's
   * for shading, node programs and the Normal pass (w = 1: already faced).
   * Displaced surfaces keep the normal of their displaced grid. */
  /* Ribbons' normals face their view already (dice.cl, w = 1). */
  int faced = grid_n[index].w > 0.5f;
  /* The surface itself faces away from the viewer. */
  int away = dot(n, f.ortho ? (float3)(0.0f, 0.0f, 1.0f) : -p) < 0.0f;
  int smooth = (patch_info[4 * (ulong)sp.patch + 2] & MP_PATCH_SMOOTH_NORMALS) && !(m.program[1] > 0.0f);
  MpPlacement place = mp_instance_placement(instances, sp.instance);
  if (smooth) {
    float3 ns = mp_face_shading_normal(patch_normals, sp.patch, uv.x, uv.y, n, p, f.ortho, &place);
    if (dot(ns, ns) > 0.0f) {
      /* w, for node programs: 1 faced, 2 faced and the surface itself faces
       * away (Backfacing). They replace it by the held-out share the sampler
       * reads (material_program.cl); for other materials it stays 0. */
      float flag = away ? 2.0f : 1.0f;
      grid_n[index] = (float4)(ns, m.program[2] > 0.0f ? flag : 0.0f);
      n = ns, faced = 1;
    }
  }
  if (m.program[2] > 0.0f) return; /* shaded by its node program (material_program.cl) */
  /* w goes on to the sampler as the held-out share (mp_raster.h): none. */
  if (faced && !smooth) grid_n[index].w = 0.0f;
  /* The normal one step along u and v (mp_normal_spread2). Smooth-shaded
   * polygons take their neighbours' interpolated normals from the patch
   * (their grid normals are being replaced by this kernel), the rest the
   * grid's, which this kernel leaves alone. */
  MpGridShape shape = mp_grid_shape(&sp, (uint)f.max_grid);
  uint here = mp_slot(&shape, i, j), sx, sy;
  mp_grid_steps(&shape, i, j, &sx, &sy);
  ulong gx = index - here + sx, gy = index - here + sy;
  /* Past the contour by less than a micropolygon: the side in front (not
   * for smooth-shaded polygons, whose neighbours' normals this kernel is
   * replacing). */
  if (!smooth && away && mp_grid_beside_contour(grid_p, grid_n, index - here, &shape, i, j, f.ortho))
    faced = 1;
  float3 nx, ny;
  if (!smooth) {
    nx = grid_n[gx].xyz, ny = grid_n[gy].xyz;
  } else {
    uint stride = (uint)f.max_grid + 1u;
    float2 uvx = uv, uvy = uv;
    mp_slot_uv(&sp, &shape, sx % stride, sx / stride, &uvx);
    mp_slot_uv(&sp, &shape, sy % stride, sy / stride, &uvy);
    nx = mp_face_shading_normal(patch_normals, sp.patch, uvx.x, uvx.y, shadow.normal, grid_p[gx].xyz, f.ortho, &place);
    ny = mp_face_shading_normal(patch_normals, sp.patch, uvy.x, uvy.y, shadow.normal, grid_p[gy].xyz, f.ortho, &place);
    if (!(dot(nx, nx) > 0.0f)) nx = n; /* a patch without smooth normals there */
    if (!(dot(ny, ny) > 0.0f)) ny = n;
  }
  float spread2 = mp_normal_spread2(n, nx, ny);
  MpRefractScene refract = {refract_nodes, refract_tris,
                            refract_roots[MP_PATCH_OBJECT(mp_placed_flags(patch_info, instances, sp.patch, sp.instance))]};
  float3 c = mp_shade_material(p, n, faced, f.ortho, &m, lights, light_count, world_glossy, use_shadows ? &shadow : 0,
                               spread2, refract.root != MP_REFRACT_NONE ? &refract : 0);
  grid_c[index] = (float4)(c, m.opacity[3]);
}
