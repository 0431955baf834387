/* The light program: lights the surfaces a material program recorded
 * (mp_surface_record.h) with every lamp, the shadow pages, the world and the
 * refraction proxy. Built apart from the stages' program, once per set of
 * the switches lighting reads (MP_NODE_USES_THIN_FILM, defined ahead of this
 * file by the host), and shared by every node tree that has those switches. */
#define MP_MATERIAL_PROGRAM 1
#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "closures/mp_shading.h"
#include "closures/mp_shade_closures.h"
#include "core/mp_scene_data.h"
#include "materials/mp_surface_record.h"

/* Lights the surfaces a material program recorded in the pool's first
 * records (one work-item each; shade_program_grids in material_program.cl),
 * into their grid vertices' colour, alpha and held-out share. */
__kernel void light_program_surfaces(MP_SCENE_PARAMS FrameParams f, __global const float4* grid_p,
                                     __global float4* grid_n, __global float4* grid_c, MP_SHADOW_INPUT_PARAMS,
                                     __global const float4* records, uint stride, uint count) {
  const uint k = get_global_id(0);
  if (k >= count) return;
  MpSurface s;
  int4 head;
  float alpha, spread2;
  if (!mp_record_load(records, stride, k, &s, &head, &alpha, &spread2)) return;
  const uint index = (uint)head.y, object = (uint)head.z;
  const int faced = head.w & 1, ribbon = (head.w >> 1) & 1;
  float3 p = grid_p[index].xyz, n = grid_n[index].xyz;
  /* Shadows compare with the surface's tangent plane (for smooth-shaded
   * polygons, which shade.cl gave their interpolated normal, that normal's). */
  MpShadowMaps maps = MP_SHADOW_INPUTS;
  MpShadowQuery shadow = {&maps, n, mp_pixel_footprint(-p.z, f), ribbon};
  /* Sharp lobes widened by the normal's spread across the micropolygon. */
  mp_surface_prepare(&s, spread2, p, f.ortho);
  MpRefractScene refract = {refract_nodes, refract_tris, refract_roots[object]};
  float3 c = mp_shade_closures(p, n, faced, f.ortho, &s, lights, light_count, world_glossy,
                               use_shadows ? &shadow : 0, refract.root != MP_REFRACT_NONE ? &refract : 0);
  /* Stochastic coverage multiplies by alpha, and by 1 - the held-out share
   * of it: what the closures give is the kept samples' colour. */
  float held = mp_surface_holdout_share(&s, alpha), kept = alpha * (1.0f - held);
  c = kept > 1e-6f ? c / kept : (float3)(0.0f);
  grid_c[index] = (float4)(c, alpha);
  /* The faced flag (read by the material program) has served: w now
   * carries the held-out share to the sampler (mp_raster.h). */
  grid_n[index].w = held;
}
