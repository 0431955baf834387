/* Dice: evaluate each diceable sub-patch at the vertices of its stitched
 * grid (mp_grid.h: edge vertices shared with the neighbours, a regular grid
 * inside), with smooth normals from the surface derivatives. Grids live in
 * fixed-size slots of (max_grid+1)^2 vertices. */
#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "geometry/mp_patch_eval.h"
#include "geometry/mp_surface.h"
#include "geometry/mp_grid.h"
#include "core/mp_scene_data.h"

__kernel void dice_grids(MP_SCENE_PARAMS __global const SubPatch* diceable, uint count, FrameParams f,
                         __global const FrameParams* views, uint view_count, __global float4* grid_p,
                         __global float4* grid_n, __global const uint* vertex_offsets) {
  uint gid = get_global_id(0), i, j;
  SubPatch sp;
  float2 uv;
  ulong index;
  if (!mp_grid_vertex(gid, count, vertex_offsets, f.max_grid, diceable, &sp, &i, &j, &uv, &index)) return;
  float3 p, dpdu, dpdv;
  MpPlacement place = mp_instance_placement(instances, sp.instance);
  mp_place_facing(&place, mp_subpatch_view(&sp, f, views, view_count)); /* ribbons face it (mp_ribbon.h) */
  uint flags = mp_placed_flags(patch_info, instances, sp.patch, sp.instance);
  if (patch_info[4 * (ulong)sp.patch] == MP_PATCH_CURVE) {
    /* A ribbon shades with the round normal of the strand it stands for,
     * which faces its view: w = 1 says so (shade.cl), as for smooth normals
     * (at the ribbon's very edges the normal is square to the view, and
     * the strip's edge seen from the eye lies a radius off that tangent).
     * A grid across the whole width shades its vertices inward by its
     * rate across (mp_ribbon_shading_scale). */
    float scale = 1.0f, u0, v0, u1, v1;
    mp_subpatch_range(&sp, &u0, &v0, &u1, &v1);
    if (u0 == 0.0f && u1 == 1.0f) {
      MpGridShape g = mp_grid_shape(&sp, (uint)f.max_grid);
      int e = mp_edge_runs_along_u(&sp, 0) ? 0 : 1; /* the edges across the strand: e and e + 2 */
      uint across = max(max(g.n[e], g.n[e + 2]), e == 0 ? g.nu : g.nv);
      scale = mp_ribbon_shading_scale(across);
    }
    float3 n;
    mp_eval_ribbon_shaded(points + (ulong)sp.patch * MP_PATCH_POINTS, uv.x, uv.y, &place, scale, &p, &dpdu, &dpdv, &n);
    grid_p[index] = (float4)(p, 1.0f);
    grid_n[index] = (float4)(n, 1.0f);
    return;
  }
  mp_surface_point(points, patch_info, patch_edges, edge_curves, sp.patch, uv.x, uv.y, &place, &p, &dpdu, &dpdv);
  /* Displaced materials move shared edge vertices along the edge's own normal
   * (watertight); others shade with the patch's normal, which keeps polygon
   * faces flat. */
  float3 n = materials[patch_info[4 * (ulong)sp.patch + 1]].program[1] > 0.0f
                 ? mp_surface_normal(points, patch_info, patch_edges, edge_curves, sp.patch, uv.x, uv.y, dpdu, dpdv,
                                     &place)
                 : mp_patch_normal(points + (ulong)sp.patch * MP_PATCH_POINTS, patch_info[4 * (ulong)sp.patch], uv.x,
                                   uv.y, dpdu, dpdv, &place);
  if (flags & MP_PATCH_FLIP_ORIENTATION) n = -n;
  grid_p[index] = (float4)(p, 1.0f);
  grid_n[index] = (float4)(n, 0.0f);
}

/* Vertices and micropolygons of each diceable sub-patch's grid (interleaved
 * in `counts`), which the host sums into the offsets that size the dice,
 * shade and sample launches. */
__kernel void grid_counts(__global const SubPatch* diceable, uint count, FrameParams f, __global uint* counts) {
  uint k = get_global_id(0);
  if (k >= count) return;
  SubPatch sp = diceable[k];
  MpGridShape g = mp_grid_shape(&sp, (uint)f.max_grid);
  counts[2 * (ulong)k] = mp_grid_vertices(&g);
  counts[2 * (ulong)k + 1] = mp_grid_micropolygons(&g);
}

/* Normals of displaced grids, from the displaced vertices (differences
 * between each vertex's neighbours along u and v, mp_grid_neighbours;
 * one-sided on the grid's border), oriented like the
 * surface normal they replace. Where the differences vanish (a collapsed
 * grid edge) the undisplaced normal stays. Runs after every material's
 * displacement (material_program.cl). */
__kernel void displaced_normals(MP_SCENE_PARAMS __global const SubPatch* diceable, uint count, FrameParams f,
                                __global const float4* grid_p, __global float4* grid_n,
                                __global const uint* vertex_offsets) {
  uint gid = get_global_id(0), i, j;
  SubPatch sp;
  float2 uv;
  ulong index;
  if (!mp_grid_vertex(gid, count, vertex_offsets, f.max_grid, diceable, &sp, &i, &j, &uv, &index)) return;
  if (!(materials[patch_info[4 * (ulong)sp.patch + 1]].program[1] > 0.0f)) return;
  MpGridShape g = mp_grid_shape(&sp, (uint)f.max_grid);
  ulong base = index - mp_slot(&g, i, j); /* slot (0, 0) of this grid */
  uint xm, xp, ym, yp;
  mp_grid_neighbours(&g, i, j, &xm, &xp, &ym, &yp);
  float3 du = grid_p[base + xp].xyz - grid_p[base + xm].xyz;
  float3 dv = grid_p[base + yp].xyz - grid_p[base + ym].xyz;
  float3 n = cross(du, dv);
  float len = length(n);
  float3 old = grid_n[index].xyz;
  if (!(len > 1e-12f * dot(du, du) + 1e-30f)) return;
  n /= len;
  grid_n[index] = (float4)(dot(n, old) < 0.0f ? -n : n, 0.0f);
}

/* Motion blur: the positions of the same grid vertices at one motion step,
 * from that step's control points and edge curves (the same patches, moved,
 * in motion_points and motion_curves), or an instance's prototype through
 * its transform at that step, into grid_p + out_offset.
 * The same (u, v) and the same edge rates as the shutter centre's grid, so
 * shared edges stay shared at every step. */
__kernel void dice_motion_positions(MP_SCENE_PARAMS __global const SubPatch* diceable, uint count, uint step,
                                    FrameParams f, __global float4* grid_p, ulong out_offset,
                                    __global const uint* vertex_offsets) {
  uint gid = get_global_id(0), i, j;
  SubPatch sp;
  float2 uv;
  ulong index;
  if (!mp_grid_vertex(gid, count, vertex_offsets, f.max_grid, diceable, &sp, &i, &j, &uv, &index)) return;
  float3 p, dpdu, dpdv;
  /* An instance's prototype does not move: its step is the instance's transform at that step.
   * Only the camera's view moves (FrameParams.motion_steps), so ribbons face its eye. */
  MpPlacement place = mp_instance_placement_at_step(instances, instance_motion, instance_count, sp.instance, step);
  mp_place_facing(&place, f);
  if (sp.instance == MP_NO_INSTANCE)
    mp_surface_point(motion_points + (ulong)step * point_count, patch_info, patch_edges,
                     motion_curves + (ulong)step * curve_count, sp.patch, uv.x, uv.y, &place, &p, &dpdu, &dpdv);
  else
    mp_surface_point(points, patch_info, patch_edges, edge_curves, sp.patch, uv.x, uv.y, &place, &p, &dpdu, &dpdv);
  grid_p[out_offset + index] = (float4)(p, 1.0f);
}

/* Motion blur of displaced grids: the displacement the shutter centre's
 * grid received (grid_p - rest) moves each step's vertex alike (a
 * translation: the surface's turn during the shutter does not turn it). */
__kernel void motion_displacement(__global const SubPatch* diceable, uint count, FrameParams f,
                                  __global const float4* grid_p, __global const float4* rest, __global float4* steps,
                                  ulong stride, int step_count, __global const uint* vertex_offsets) {
  uint gid = get_global_id(0), i, j;
  SubPatch sp;
  float2 uv;
  ulong index;
  if (!mp_grid_vertex(gid, count, vertex_offsets, f.max_grid, diceable, &sp, &i, &j, &uv, &index)) return;
  float4 d = grid_p[index] - rest[index];
  if (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f) return;
  for (int k = 0; k < step_count; ++k) steps[(ulong)k * stride + index] += (float4)(d.xyz, 0.0f);
}
